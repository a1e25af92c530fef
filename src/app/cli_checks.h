// Checks every command shares before it reads or writes anything: numbers from the command line
// are finite and in range (the output guard itself lives in the library: softsight/io/output_guard.h).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "softsight/io/output_guard.h"  // PathRole, CheckOutputsAreNotInputs: every command's guard.

namespace softsight {

// A number in [min, max]; NaN and infinities are refused (CLI::Range lets NaN through, and
// CLI11 reads "inf" and "nan" as doubles). Use min == max == 0 for "any finite number".
CLI::Validator NumberIn(double min, double max);

// Adds the finiteness check to every numeric option of `app` and its subcommands, so no command
// can forget it: `--fps inf`, `--noise nan` are refused with one line naming the option. main()
// applies it to every command but control and rig, whose options' Check() does the same.
void RequireFiniteNumbers(CLI::App& app);

}  // namespace softsight
