// --help wrapped to the terminal: CLI11 prints each option's description on one line, and the
// longest ran to 388 characters. Used by the launcher (main.cc: `softsight --help`) and by every
// plugin (command_line.cc: `softsight <command> --help`).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

namespace softsight {

// The width help is wrapped to: $COLUMNS when it is a number, else the terminal's on standard
// output (ioctl TIOCGWINSZ), else 80 (output to a pipe or a file); never below 40.
size_t HelpWidth();

// The number of columns `text` takes on a terminal: its characters, not its bytes ("±" is one).
size_t TextColumns(std::string_view text);

// `text` broken at spaces into lines of at most `width` columns, each starting at column
// `indent` (the first line's `indent` columns are the caller's: the text goes on from there). A
// newline in the text starts a new line, a line's leading spaces stay (an example command), and
// its continuations go 4 columns further in. A word longer than a line stays whole.
std::string WrapText(std::string_view text, size_t width, size_t indent);

// Descriptions are written as lines of ~90 columns: their newlines are read as spaces, so the
// text reflows, except where the text breaks on purpose: after a line ending in '.' or ':', at a
// blank line, and before or after an indented line (an example) or one starting "Example".
std::string JoinSoftLineBreaks(std::string_view text);

// CLI11's formatter with every description wrapped to `width`: an option's or a command's in a
// column beside its name (below the name when the name is wider than that column), the
// command's own above the usage line.
class WrappingFormatter : public CLI::Formatter {
 public:
  explicit WrappingFormatter(size_t width);

  std::string make_option(const CLI::Option* option, bool is_positional) const override;
  std::string make_subcommand(const CLI::App* sub) const override;
  std::string make_description(const CLI::App* app) const override;
  std::string make_footer(const CLI::App* app) const override;

 private:
  // One entry: "  name" then the description from the column on, wrapped.
  std::string entry(const std::string& name, const std::string& description) const;

  size_t width_;
};

// The formatter every `softsight` command line uses: HelpWidth() wide.
std::shared_ptr<WrappingFormatter> TerminalHelpFormatter();

}  // namespace softsight
