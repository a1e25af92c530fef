// Tracks softsight's built-in bending scene with a config, and compares every marker found with
// the renderer's exact truth: the library's whole path (config, renderer, session, measurement)
// from an outside program. Prints one line; exit 0 when every marker was found within 0.5 px.
//   track_rendered CONFIG [FRAMES]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include <opencv2/core.hpp>

#include <softsight/softsight.h>  // The whole API: config, renderer, session, measurements.

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s CONFIG [FRAMES]\n", argv[0]);
    return 2;
  }
  try {
    const softsight::TrackingConfig config = softsight::LoadTrackingConfig(argv[1]);
    // Designated initializers name only what they set: the rest keep their defaults (and
    // -Wextra has nothing to say about them).
    softsight::SyntheticScene scene(softsight::SceneOptions{.kind = softsight::SceneKind::kBending});
    const int frames = argc > 2 ? std::atoi(argv[2]) : 30;
    softsight::TrackingSession session(config);
    softsight::Frame frame;
    int found = 0, expected = 0;
    double worst_px = 0.0;
    for (int i = 0; i < frames && i < scene.frame_count(); ++i) {
      const softsight::SceneTruth truth = scene.render(i, frame.image);
      frame.index = i;
      frame.time_s = truth.time_s;
      const softsight::FrameResult& result = session.process(frame);
      for (const softsight::MarkerObservation& marker : result.markers) {
        for (const softsight::MarkerTruth& t : truth.markers) {
          if (t.name != marker.name || !t.centroid_px) continue;
          ++expected;
          if (!marker.observation.position_px) continue;  // Not found: no position.
          ++found;
          const cv::Point2d d = *marker.observation.position_px - *t.centroid_px;
          worst_px = std::max(worst_px, std::hypot(d.x, d.y));
        }
      }
    }
    std::printf("softsight %s: %d of %d marker-frames found, worst %.3f px from the truth\n",
                softsight::kVersion, found, expected, worst_px);
    return found == expected && expected > 0 && worst_px < 0.5 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
