// Tracking alone: a red disc moving across frames this program draws itself, followed by one
// colour tracker. It includes only the track module's headers and links only its library
// (softsight::track in CMake, `pkg-config softsight-track`), so it needs neither the config's
// YAML, the video I/O nor the serial port. Prints one line; exit 0 when the tracker found the
// disc in every frame within 0.1 px of its centre.
//   track_colour [FRAMES]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>

#include <opencv2/core.hpp>

#include "softsight/track/colour_tracker.h"
#include "softsight/track/tracker.h"
#include "softsight/version.h"

namespace {

// A dark gray frame with a red disc of radius `radius` centred on (cx, cy), whole pixels only
// (a symmetric disc: its centroid is its centre).
cv::Mat DrawDisc(int cx, int cy, int radius) {
  cv::Mat image(240, 320, CV_8UC3, cv::Scalar(60, 60, 60));
  for (int y = cy - radius; y <= cy + radius; ++y) {
    for (int x = cx - radius; x <= cx + radius; ++x) {
      if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= radius * radius) {
        image.at<cv::Vec3b>(y, x) = cv::Vec3b(30, 30, 220);
      }
    }
  }
  return image;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const int frames = argc > 1 ? std::atoi(argv[1]) : 20;
    softsight::ColourParams colour;
    colour.auto_bgr = cv::Vec3b(30, 30, 220);  // The marker's nominal colour (B, G, R).
    std::unique_ptr<softsight::Tracker> tracker = softsight::CreateTracker({"red", colour});
    int found = 0;
    double worst_px = 0.0;
    for (int i = 0; i < frames; ++i) {
      const int cx = 80 + 5 * i, cy = 120 + (i % 3);
      softsight::Frame frame;
      frame.index = i;
      frame.image = DrawDisc(cx, cy, 9);
      if (!tracker->start(frame)) continue;
      const softsight::Observation seen = tracker->update(frame.image);
      if (!seen.position_px) continue;
      ++found;
      worst_px = std::max(worst_px, std::hypot(seen.position_px->x - cx, seen.position_px->y - cy));
    }
    std::printf("softsight %s track only: red found in %d of %d frames, worst %.3f px\n",
                softsight::kVersion, found, frames, worst_px);
    return found == frames && worst_px < 0.1 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
