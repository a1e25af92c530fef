// Checks every command shares before it reads or writes anything: numbers from the command line
// are finite and in range, and no output path is one of the run's inputs.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace softsight {

// A number in [min, max]; NaN and infinities are refused (CLI::Range lets NaN through, and
// CLI11 reads "inf" and "nan" as doubles). Use min == max == 0 for "any finite number".
CLI::Validator NumberIn(double min, double max);

// Adds the finiteness check to every numeric option of `app` and its subcommands, so no command
// can forget it: `--fps inf`, `--noise nan` are refused with one line naming the option. main()
// applies it to every command but control and rig, whose options' Check() does the same.
void RequireFiniteNumbers(CLI::App& app);

struct PathRole {
  std::string role;  // How the user named it: "--csv", "--input", "the config's camera file".
  std::string path;
};

// Throws InputError when an output is the same file (device and inode, so links and "./x" count)
// as an input or as another output, or is an image pattern (frames/%04d.png) that would write
// one of the inputs' names in their folder. Outputs that do not exist yet cannot be either.
void CheckOutputsAreNotInputs(const std::vector<PathRole>& outputs,
                              const std::vector<PathRole>& inputs);

}  // namespace softsight
