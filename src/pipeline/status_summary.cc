#include "softsight/pipeline/status_summary.h"

#include <algorithm>

namespace softsight {

void MarkerStatusSummary::add(const FrameResult& result) {
  if (markers_.size() < result.markers.size()) markers_.resize(result.markers.size());
  const bool consecutive = last_frame_ >= 0 && result.frame_index == last_frame_ + 1;
  for (size_t m = 0; m < result.markers.size(); ++m) {
    PerMarker& marker = markers_[m];
    marker.name = result.markers[m].name;
    const Observation& observation = result.markers[m].observation;
    const size_t now = static_cast<size_t>(observation.status());
    for (size_t s = 0; s < kStatusCount; ++s) {
      PerStatus& per = marker.status[s];
      if (s != now) {
        per.open = false;
        continue;
      }
      ++per.frames;
      const bool continues = per.open && consecutive;
      per.open = true;
      if (!continues) {
        ++per.runs;
        if (per.listed.size() < kListedRuns) per.listed.push_back({result.frame_index, 0, 0});
      }
      if (per.runs <= static_cast<int64_t>(kListedRuns)) {
        Run& run = per.listed.back();
        run.last = result.frame_index;
        run.candidates = std::max(run.candidates, observation.candidates);
      }
    }
  }
  last_frame_ = result.frame_index;
}

int64_t MarkerStatusSummary::frames(size_t marker, MarkerStatus status) const {
  if (marker >= markers_.size()) return 0;
  return markers_[marker].status[static_cast<size_t>(status)].frames;
}

std::vector<std::string> MarkerStatusSummary::lines() const {
  std::vector<std::string> out;
  for (const PerMarker& marker : markers_) {
    std::string line;
    for (size_t s = 0; s < kStatusCount; ++s) {
      const auto status = static_cast<MarkerStatus>(s);
      const PerStatus& per = marker.status[s];
      if (status == MarkerStatus::kFound || per.frames == 0) continue;
      // Appended piece by piece (GCC 12 misreads chained operator+ here as an overlap).
      if (line.empty()) {
        line.append(marker.name).append(": ");
      } else {
        line.append("; ");
      }
      line.append(MarkerStatusName(status)).append(" in ").append(std::to_string(per.frames));
      line.append(per.frames == 1 ? " frame: " : " frames: ");
      for (size_t r = 0; r < per.listed.size(); ++r) {
        const Run& run = per.listed[r];
        if (r > 0) line.append(", ");
        line.append(std::to_string(run.first));
        if (run.last != run.first) line.append("-").append(std::to_string(run.last));
        if (status == MarkerStatus::kAmbiguous && run.candidates > 1) {
          line.append(" (").append(std::to_string(run.candidates)).append(" candidates)");
        }
      }
      const int64_t unlisted = per.runs - static_cast<int64_t>(per.listed.size());
      if (unlisted > 0) line.append(" and ").append(std::to_string(unlisted)).append(" more");
    }
    if (!line.empty()) out.push_back(line);
  }
  return out;
}

}  // namespace softsight
