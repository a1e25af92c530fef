#include "app/unknown_word.h"

#include <algorithm>
#include <cctype>

#include "softsight/core/error.h"

namespace softsight {
namespace {

std::string Lowercase(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view WithoutDashes(std::string_view word) {
  const size_t start = word.find_first_not_of('-');
  return start == std::string_view::npos ? std::string_view() : word.substr(start);
}

// How far a word may be from what was meant: a typo or two, more for longer words, so that
// "--fps" is not offered for "--xyz".
size_t EditsAllowed(size_t length) { return length <= 4 ? 1 : length <= 8 ? 2 : 3; }

// The names `app`'s options answer to, "--long" and "-s", in the order --help lists them.
std::vector<std::string> OptionNames(const CLI::App& app, bool long_names) {
  std::vector<std::string> names;
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& name : long_names ? option->get_lnames() : option->get_snames()) {
      names.push_back((long_names ? "--" : "-") + name);
    }
  }
  return names;
}

// `command` is "softsight" or "softsight <name>": where --help says more.
std::string Suggestion(const std::optional<std::string>& nearest, const std::string& command) {
  return nearest ? "; did you mean \"" + *nearest + "\"?" : " (see " + command + " --help)";
}

// The first word of `app`'s own that nothing took, said with what it may have been meant as.
std::optional<UnknownWord> UnknownWordOf(const CLI::App& app, const std::string& command) {
  const std::vector<std::string> words = app.remaining();
  if (words.empty()) return std::nullopt;
  const std::string& word = words.front();
  const bool is_root = app.get_parent() == nullptr;
  if (word.size() > 2 && word.compare(0, 2, "--") == 0) {
    const std::string name = word.substr(0, word.find('='));  // --name=value
    return UnknownWord{command, "unknown option \"" + name + "\"" +
                                    Suggestion(NearestWord(name, OptionNames(app, true)), command)};
  }
  if (word.size() > 1 && word[0] == '-') {
    // A short option is one letter: any other letter is one edit away, so only a different case
    // ("-O" for "-o") is offered.
    const std::string name = word.substr(0, 2);  // -xVALUE, or -abc for three flags
    std::optional<std::string> nearest;
    for (const std::string& known : OptionNames(app, false)) {
      if (Lowercase(known) == Lowercase(name)) nearest = known;
    }
    return UnknownWord{command, "unknown option \"" + name + "\"" + Suggestion(nearest, command)};
  }
  if (is_root) {
    std::vector<std::string> commands;
    for (const CLI::App* sub : app.get_subcommands({})) commands.push_back(sub->get_name());
    return UnknownWord{command, "unknown command \"" + word + "\"" +
                                    Suggestion(NearestWord(word, commands), command)};
  }
  return UnknownWord{command, "unexpected argument \"" + word + "\" (see " + command + " --help)"};
}

}  // namespace

size_t EditDistance(std::string_view a, std::string_view b) {
  // rows[i][j]: the distance between a's first i characters and b's first j.
  std::vector<std::vector<size_t>> rows(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) rows[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) rows[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t substitution = rows[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      rows[i][j] = std::min({rows[i - 1][j] + 1, rows[i][j - 1] + 1, substitution});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        rows[i][j] = std::min(rows[i][j], rows[i - 2][j - 2] + 1);
      }
    }
  }
  return rows[a.size()][b.size()];
}

std::optional<std::string> NearestWord(std::string_view word,
                                       const std::vector<std::string>& candidates) {
  const std::string bare = Lowercase(WithoutDashes(word));
  if (bare.empty()) return std::nullopt;
  std::optional<std::string> nearest;
  size_t best = EditsAllowed(bare.size()) + 1;
  std::vector<std::string> extended;  // Candidates `word` is the beginning of.
  for (const std::string& candidate : candidates) {
    const std::string known = Lowercase(WithoutDashes(candidate));
    const size_t distance = EditDistance(bare, known);
    if (distance < best) best = distance, nearest = candidate;
    if (known.size() > bare.size() && known.compare(0, bare.size(), bare) == 0) {
      extended.push_back(candidate);
    }
  }
  if (nearest) return nearest;
  if (bare.size() >= 3 && extended.size() == 1) return extended.front();
  return std::nullopt;
}

std::optional<UnknownWord> FindUnknownWord(const CLI::App& app) {
  const std::string program = "softsight";  // Not argv[0], the path it was started by.
  if (std::optional<UnknownWord> root = UnknownWordOf(app, program)) return root;
  for (const CLI::App* sub : app.get_subcommands()) {
    if (std::optional<UnknownWord> word = UnknownWordOf(*sub, program + " " + sub->get_name())) {
      return word;
    }
  }
  return std::nullopt;
}

std::optional<int> AnswerHelpOrUnknownWord(CLI::App& app, const CLI::ParseError& error,
                                           std::ostream& err) {
  if (error.get_exit_code() == 0) return app.exit(error);  // --help, --version.
  if (const std::optional<UnknownWord> unknown = FindUnknownWord(app)) {
    err << unknown->command << ": error: " << EscapeForMessage(unknown->message) << "\n";
    return kInputErrorExitCode;
  }
  return std::nullopt;
}

}  // namespace softsight
