#include "app/shared_flags.h"

#include "softsight/track/tracker.h"

namespace softsight {

std::string MethodHelp() {
  std::string methods;
  for (const std::string& method : TrackerMethods()) {
    methods += (methods.empty() ? "" : ", ") + method;
  }
  return "Use this method for every marker, whatever the config says: " + methods;
}

}  // namespace softsight
