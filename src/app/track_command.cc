#include "app/commands.h"
namespace softsight {
CommandRunner SetupTrackCommand(CLI::App& sub) { (void)sub; return [] { return 0; }; }
}  // namespace softsight
