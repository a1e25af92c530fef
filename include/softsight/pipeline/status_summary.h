// Why each marker was not found, over a whole run, for the summary a command prints at its end:
//   red: ambiguous in 13 frames: 0-12 (2 candidates); implausible in 2 frames: 40-41
// An accumulator fed one FrameResult at a time; memory stays bounded on long runs (only the first
// few runs of frames per marker and status are listed, the rest are counted).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "softsight/core/types.h"

namespace softsight {

class MarkerStatusSummary {
 public:
  // How many runs of consecutive frames are listed per marker and status; later ones are counted.
  static constexpr size_t kListedRuns = 4;

  // Adds one frame (markers in the same order every frame). Frames need not be consecutive: a
  // gap in frame indices ends a run.
  void add(const FrameResult& result);

  // Frames in which marker `i` had `status` (0 for an unknown marker).
  int64_t frames(size_t marker, MarkerStatus status) const;

  // One line per marker that was not found in some frame, in marker order, e.g.
  // "red: ambiguous in 13 frames: 0-12 (2 candidates); implausible in 2 frames: 40-41".
  // Markers found in every frame have no line. Empty when all were found throughout.
  std::vector<std::string> lines() const;

 private:
  static constexpr size_t kStatusCount = static_cast<size_t>(MarkerStatus::kStale) + 1;
  struct Run {
    int64_t first = 0, last = 0;
    int candidates = 0;  // The most candidates seen in the run (kAmbiguous only).
  };
  struct PerStatus {
    int64_t frames = 0;
    int64_t runs = 0;
    std::vector<Run> listed{};  // The first kListedRuns runs.
    bool open = false;          // The last frame added had this status (its run may continue).
  };
  struct PerMarker {
    std::string name{};
    std::array<PerStatus, kStatusCount> status{};
  };
  std::vector<PerMarker> markers_;
  int64_t last_frame_ = -1;
};

}  // namespace softsight
