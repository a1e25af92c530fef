// A mistyped command or option, named with the nearest one the program knows: CLI11 alone said
// "A subcommand is required" for `softsight trak` and "--config is required" for
// `softsight track --confg x`, without the word that was wrong. Used by the launcher (main.cc,
// for the commands) and by every plugin (command_line.cc, for each command's options).
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

namespace softsight {

// The optimal string alignment distance (Levenshtein's insertions, deletions and substitutions,
// plus a swap of two neighbouring characters as one edit: "trakc" is 1 from "track").
size_t EditDistance(std::string_view a, std::string_view b);

// The candidate `word` was most likely meant to be: the nearest by EditDistance (ignoring case
// and leading dashes) when it is close enough for its length (1 edit up to 4 characters, 2 up to
// 8, else 3), or the only candidate `word` begins (3 characters or more); nullopt otherwise.
// Ties go to the earlier candidate.
std::optional<std::string> NearestWord(std::string_view word,
                                       const std::vector<std::string>& candidates);

// After a failed parse of `app` (the program's, with its commands): the first word of the command
// line that no command or option took, as one error line's command and message, e.g.
// {"softsight", "unknown command \"trak\"; did you mean \"track\"?"} or
// {"softsight track", "unknown option \"--inptu\"; did you mean \"--input\"?"}.
// nullopt when every word was taken (the error is then about a value or a missing option).
struct UnknownWord {
  std::string command;  // "softsight" or "softsight <command>": the line's prefix.
  std::string message;
};
std::optional<UnknownWord> FindUnknownWord(const CLI::App& app);

// A failed parse of `app` that is --help or --version (CLI11 prints them), or a mistyped word (one
// error line on `err`, from FindUnknownWord): the exit code. nullopt for any other error, which
// the caller words itself. The mistyped word comes first: CLI11 reports a required option the
// typo left out before the word it did not know ("--config is required" for --confg).
std::optional<int> AnswerHelpOrUnknownWord(CLI::App& app, const CLI::ParseError& error,
                                           std::ostream& err);

}  // namespace softsight
