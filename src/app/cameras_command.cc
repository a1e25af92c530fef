// softsight cameras: the V4L2 capture devices and the modes each offers, to choose the
// --camera-width/-height/-fps/-pixel-format of live, track and control; then the GenICam cameras
// Aravis finds (--camera aravis:ID), when the build has Aravis.
#include <iostream>

#include "app/commands.h"
#include "softsight/io/camera_settings.h"

namespace softsight {

CommandRunner SetupCamerasCommand(CLI::App& sub) {
  sub.footer(
      "Each capture device (/dev/videoN) with its name, then one line per pixel format with\n"
      "its sizes and frame rates (e.g. `MJPG: 1280x720@30/15 640x480@30`). With no camera it\n"
      "prints \"no cameras found\" and exits 0 (not an error: nothing is plugged in).\n"
      "Then the GenICam cameras (GigE Vision, USB3 Vision) Aravis finds, one line each with\n"
      "its --camera aravis:ID (finding GigE cameras broadcasts on every network interface and\n"
      "waits about a second). aravis:Fake_1, Aravis' simulated camera, is never listed but\n"
      "always opens.\n"
      "Example: softsight cameras");
  return [] {
    std::vector<std::string> lines = ListCameras();
    if (HaveAravisSupport()) {
      for (std::string& line : ListAravisCameras()) lines.push_back(std::move(line));
    }
    if (lines.empty()) {
      std::cout << "no cameras found (no V4L2 capture device under /dev/video*"
                << (HaveAravisSupport() ? ", no GenICam camera" : "") << ")\n";
      return 0;
    }
    for (const std::string& line : lines) std::cout << line << "\n";
    return 0;
  };
}

}  // namespace softsight
