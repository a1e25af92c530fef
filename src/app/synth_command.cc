#include "app/commands.h"
namespace softsight {
CommandRunner SetupSynthCommand(CLI::App& sub) { (void)sub; return [] { return 0; }; }
}  // namespace softsight
