// The softsight program is a table of subcommands (main.cc). Each subcommand lives in its own
// <name>_command.cc: its Setup function adds the options to `sub` and returns the function that
// runs the command once the command line is parsed. That function returns the exit code; user
// errors are thrown as InputError and reported once, by main().
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace softsight {

using CommandRunner = std::function<int()>;

CommandRunner SetupTrackCommand(CLI::App& sub);
CommandRunner SetupControlCommand(CLI::App& sub);
CommandRunner SetupIdentifyCommand(CLI::App& sub);
CommandRunner SetupRigCommand(CLI::App& sub);
CommandRunner SetupSynthCommand(CLI::App& sub);
CommandRunner SetupEvaluateCommand(CLI::App& sub);
CommandRunner SetupDemoCommand(CLI::App& sub);
CommandRunner SetupCalibrateCommand(CLI::App& sub);
CommandRunner SetupTrackStereoCommand(CLI::App& sub);
// `track-stereo` in the live plugin, where `track-stereo --window` runs (app/command_table.h):
// the same command, with the stereo window (app/track_stereo_window.cc).
CommandRunner SetupTrackStereoWindowCommand(CLI::App& sub);
CommandRunner SetupPlotCommand(CLI::App& sub);
CommandRunner SetupLiveCommand(CLI::App& sub);
// `serve` lives in the live plugin too (it drives the live window's controller; app/serve_command.cc).
CommandRunner SetupServeCommand(CLI::App& sub);
CommandRunner SetupCamerasCommand(CLI::App& sub);
CommandRunner SetupConfigCommand(CLI::App& sub);
CommandRunner SetupInitCommand(CLI::App& sub);
CommandRunner SetupPickCommand(CLI::App& sub);
CommandRunner SetupListenCommand(CLI::App& sub);

}  // namespace softsight
