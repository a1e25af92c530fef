// softsight cameras: the V4L2 capture devices and the modes each offers, to choose the
// --camera-width/-height/-fps/-pixel-format of live, track and control.
#include <iostream>

#include "app/commands.h"
#include "softsight/io/camera_settings.h"

namespace softsight {

CommandRunner SetupCamerasCommand(CLI::App& sub) {
  sub.footer(
      "Each capture device (/dev/videoN) with its name, then one line per pixel format with\n"
      "its sizes and frame rates (e.g. `MJPG: 1280x720@30/15 640x480@30`). With no camera it\n"
      "prints \"no cameras found\" and exits 0 (not an error: nothing is plugged in).\n"
      "Example: softsight cameras");
  return [] {
    const std::vector<std::string> lines = ListCameras();
    if (lines.empty()) {
      std::cout << "no cameras found (no V4L2 capture device under /dev/video*)\n";
      return 0;
    }
    for (const std::string& line : lines) std::cout << line << "\n";
    return 0;
  };
}

}  // namespace softsight
