#include "app/help_format.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>

namespace softsight {
namespace {

constexpr size_t kDefaultWidth = 80;  // Not a terminal: what a pager or an editor shows well.
constexpr size_t kMinWidth = 40;
constexpr size_t kNameColumn = 30;    // CLI11's own, where wide terminals have room for it.

}  // namespace

size_t HelpWidth() {
  size_t width = 0;
  if (const char* columns = std::getenv("COLUMNS")) {
    char* end = nullptr;
    const long value = std::strtol(columns, &end, 10);
    if (end != columns && *end == '\0' && value > 0) width = static_cast<size_t>(value);
  }
  winsize size{};
  if (width == 0 && ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) {
    width = size.ws_col;
  }
  if (width == 0) width = kDefaultWidth;
  return std::max(width, kMinWidth);
}

size_t TextColumns(std::string_view text) {
  // UTF-8 continuation bytes (10xxxxxx) belong to the character before them.
  return static_cast<size_t>(std::count_if(text.begin(), text.end(), [](char c) {
    return (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  }));
}

std::string WrapText(std::string_view text, size_t width, size_t indent) {
  std::string out;
  bool first_line = true;
  for (size_t start = 0; start <= text.size();) {
    const size_t newline = text.find('\n', start);
    const std::string_view line = text.substr(
        start, newline == std::string_view::npos ? std::string_view::npos : newline - start);
    // A line's own leading spaces (an example command) stay; its continuations go 4 further.
    const size_t lead = std::min(line.find_first_not_of(' '), line.size());
    size_t row_indent = indent + lead;
    if (!first_line) out += '\n';
    // The very first row's indent is on the caller's line already.
    bool indent_written = first_line && lead == 0;
    size_t column = indent_written ? indent : 0;
    bool row_has_words = false;
    for (size_t word_start = lead; word_start < line.size();) {
      if (line[word_start] == ' ') {
        ++word_start;
        continue;
      }
      const size_t word_end = std::min(line.find(' ', word_start), line.size());
      const std::string_view word = line.substr(word_start, word_end - word_start);
      const size_t columns = TextColumns(word);
      if (row_has_words && column + 1 + columns > width) {
        out += '\n';
        row_indent = indent + lead + (lead > 0 ? 4 : 0);
        indent_written = false;
        column = 0;
        row_has_words = false;
      }
      if (!indent_written) {
        // Written with the row's first word, so that no line ends in spaces.
        const size_t pad = out.empty() ? lead : row_indent;  // The caller wrote `indent`.
        out.append(pad, ' ');
        column = row_indent;
        indent_written = true;
      }
      if (row_has_words) {
        out += ' ';
        ++column;
      }
      out += word;
      column += columns;
      row_has_words = true;
      word_start = word_end;
    }
    first_line = false;
    if (newline == std::string_view::npos) break;
    start = newline + 1;
  }
  return out;
}

std::string JoinSoftLineBreaks(std::string_view text) {
  std::string out(text);
  for (size_t at = out.find('\n'); at != std::string::npos; at = out.find('\n', at + 1)) {
    const size_t line_start = at == 0 ? 0 : out.rfind('\n', at - 1) + 1;  // npos + 1 == 0
    const std::string_view line(out.data() + line_start, at - line_start);
    const std::string_view next(out.data() + at + 1, out.size() - at - 1);
    const bool kept = line.empty() || line.front() == ' ' || line.back() == ':' ||
                      line.back() == '.' || next.empty() || next.front() == ' ' ||
                      next.front() == '\n' || next.compare(0, 7, "Example") == 0;
    if (!kept) out[at] = ' ';
  }
  return out;
}

WrappingFormatter::WrappingFormatter(size_t width) : width_(width) {
  // A narrow terminal keeps two thirds of its width for the descriptions.
  column_width(std::min(kNameColumn, width / 3));
}

std::string WrappingFormatter::entry(const std::string& name,
                                     const std::string& description) const {
  std::string out = "  " + name;
  if (!description.empty()) {
    const size_t name_columns = TextColumns(out);
    if (name_columns + 1 > column_width_) {
      out += '\n';
      out.append(column_width_, ' ');
    } else {
      out.append(column_width_ - name_columns, ' ');
    }
    out += WrapText(description, width_, column_width_);
  }
  return out + "\n";
}

std::string WrappingFormatter::make_option(const CLI::Option* option, bool is_positional) const {
  return entry(make_option_name(option, is_positional) + make_option_opts(option),
               make_option_desc(option));
}

std::string WrappingFormatter::make_subcommand(const CLI::App* sub) const {
  return entry(sub->get_display_name(true), sub->get_description());
}

std::string WrappingFormatter::make_description(const CLI::App* app) const {
  const std::string description = CLI::Formatter::make_description(app);
  return description.empty() ? description
                             : WrapText(JoinSoftLineBreaks(description), width_, 0);
}

std::string WrappingFormatter::make_footer(const CLI::App* app) const {
  const std::string footer = CLI::Formatter::make_footer(app);
  return footer.empty() ? footer : WrapText(JoinSoftLineBreaks(footer), width_, 0);
}

std::shared_ptr<WrappingFormatter> TerminalHelpFormatter() {
  return std::make_shared<WrappingFormatter>(HelpWidth());
}

}  // namespace softsight
