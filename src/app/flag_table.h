// A command's flags as a table: one row per flag says its names, help, check and where its value
// lands, and AddFlags registers the rows into CLI11. The command-line side of core/option_table.h
// (COLMAP's OptionManager: AddDefaultOption(name, &member, help) once per option). A flag that
// several commands take is a row (or a table) of its own in app/shared_flags.h, added to each;
// a flag that sets a config key takes its help (ConfigKeyHelp below) and its range from that
// key's option table row (capture_options.h: the camera's settings).
//
// A table is a FlagTable<Args>, built from the helpers below:
//   ValueFlag<Args>("--fps", &Args::fps).Help("Frame rate of an image sequence")
//       .ShowDefault().Check(NumberIn(1e-3, 1e6))
//   SwitchFlag<Args>("-q,--quiet", &Args::quiet).Help("No progress bar and no summary")
// `Args` holds what the flags set until the command runs; a row reaches its field by a member
// pointer or by a function Args& -> Field& (for fields of fields).
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "softsight/core/option_table.h"

namespace softsight {

template <typename Args>
struct Flag {
  std::string names;  // CLI11's: "-c,--config", "--publish-hwm", or a positional's "csv".
  std::string help;
  // Adds the option to `app`, bound to its field of `args`.
  std::function<CLI::Option*(CLI::App& app, Args& args, const Flag& flag)> bind;
  // What is said about it beyond the binding: its check, its default shown, required, ...
  std::vector<std::function<void(CLI::Option*)>> finish;
  // Other flags of the same command (by name, "--camera"), applied once all rows are added.
  std::vector<std::string> excludes, needs;
};

template <typename Args>
using FlagTable = std::vector<Flag<Args>>;

// Adds every row of `table` to `app`, bound to `args`, which must outlive parsing. Rows are
// added in the table's order (the order --help lists them in); `excludes`/`needs` may name a
// flag added earlier to `app` by another table.
template <typename Args>
void AddFlags(CLI::App& app, const FlagTable<Args>& table, Args* args) {
  std::vector<std::pair<CLI::Option*, const Flag<Args>*>> added;
  for (const Flag<Args>& flag : table) {
    CLI::Option* option = flag.bind(app, *args, flag);
    for (const auto& finish : flag.finish) finish(option);
    added.emplace_back(option, &flag);
  }
  for (const auto& [option, flag] : added) {
    for (const std::string& name : flag->excludes) option->excludes(app.get_option(name));
    for (const std::string& name : flag->needs) option->needs(app.get_option(name));
  }
}

// The help of a flag that sets the config key `key_path` (as written in a config: "capture.fps"),
// from the key's row: its doc, unit and range, then where it lands in a config.
//   "frame rate to ask for [Hz]; 0 (the camera's) or 1..1000 (config: capture.fps)"
std::string ConfigKeyHelp(const OptionSpec& spec, const std::string& key_path);

template <typename Args>
class FlagBuilder {
 public:
  using Bind = decltype(Flag<Args>::bind);
  FlagBuilder(std::string names, Bind bind) {
    flag_.names = std::move(names);
    flag_.bind = std::move(bind);
  }
  FlagBuilder& Help(std::string help) {
    flag_.help = std::move(help);
    return *this;
  }
  // --help shows the field's value before parsing: its default.
  FlagBuilder& ShowDefault() {
    return Finish([](CLI::Option* o) { o->capture_default_str(); });
  }
  FlagBuilder& Required() {
    return Finish([](CLI::Option* o) { o->required(); });
  }
  FlagBuilder& Check(CLI::Validator check) {
    return Finish([check](CLI::Option* o) { o->check(check); });
  }
  FlagBuilder& TypeName(std::string name) {
    return Finish([name](CLI::Option* o) { o->type_name(name); });
  }
  FlagBuilder& Group(std::string group) {
    return Finish([group](CLI::Option* o) { o->group(group); });
  }
  FlagBuilder& Excludes(std::string name) {
    flag_.excludes.push_back(std::move(name));
    return *this;
  }
  FlagBuilder& Needs(std::string name) {
    flag_.needs.push_back(std::move(name));
    return *this;
  }
  // Anything else CLI11 can say about an option (expected(), delimiter(), ...).
  FlagBuilder& Finish(std::function<void(CLI::Option*)> finish) {
    flag_.finish.push_back(std::move(finish));
    return *this;
  }
  operator Flag<Args>() const { return flag_; }  // NOLINT: builders read as table rows

 private:
  Flag<Args> flag_;
};

// A flag that takes a value (or several, for a vector field; an optional field stays empty
// unless given): CLI11's add_option.
template <typename Args, typename Access>
FlagBuilder<Args> ValueFlag(std::string names, Access access) {
  auto field = option_detail::Accessor<Args>(access);
  return {std::move(names), [field](CLI::App& app, Args& args, const Flag<Args>& flag) {
            return app.add_option(flag.names, field(args), flag.help);
          }};
}

// A flag without a value that sets a bool field: CLI11's add_flag.
template <typename Args, typename Access>
FlagBuilder<Args> SwitchFlag(std::string names, Access access) {
  auto field = option_detail::Accessor<Args>(access);
  return {std::move(names), [field](CLI::App& app, Args& args, const Flag<Args>& flag) {
            bool& value = field(args);  // A switch sets a bool.
            return app.add_flag(flag.names, value, flag.help);
          }};
}

// A flag without a value that does something to `args` when given (--colour sets a field to
// true, --gray the same field to false).
template <typename Args>
FlagBuilder<Args> ActionFlag(std::string names, std::function<void(Args&)> action) {
  return {std::move(names), [action](CLI::App& app, Args& args, const Flag<Args>& flag) {
            Args* bound = &args;
            return app.add_flag_callback(flag.names, [action, bound] { action(*bound); },
                                         flag.help);
          }};
}

}  // namespace softsight
