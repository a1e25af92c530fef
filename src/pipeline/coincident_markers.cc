#include "pipeline/coincident_markers.h"

#include <algorithm>
#include <limits>

namespace softsight {

std::vector<size_t> FindCoincidentMarkers(
    const std::vector<MarkerObservation>& current,
    const std::vector<std::optional<cv::Point2d>>& previous_px, double min_separation_px) {
  CV_Assert(current.size() == previous_px.size());
  auto jump = [&](size_t i) {
    return previous_px[i] ? cv::norm(*current[i].observation.position_px - *previous_px[i])
                          : std::numeric_limits<double>::infinity();
  };
  std::vector<size_t> rejected;
  for (size_t i = 0; i < current.size(); ++i) {
    if (!current[i].observation.found()) continue;
    for (size_t j = i + 1; j < current.size(); ++j) {
      if (!current[j].observation.found()) continue;
      const double distance =
          cv::norm(*current[i].observation.position_px - *current[j].observation.position_px);
      if (distance >= min_separation_px) continue;
      const double jump_i = jump(i), jump_j = jump(j);
      if (jump_i > jump_j) {
        rejected.push_back(i);
      } else if (jump_j > jump_i) {
        rejected.push_back(j);
      } else {
        rejected.push_back(i);
        rejected.push_back(j);
      }
    }
  }
  std::sort(rejected.begin(), rejected.end());
  rejected.erase(std::unique(rejected.begin(), rejected.end()), rejected.end());
  return rejected;
}

std::vector<size_t> FindMarkersOnAMissingMarkersPlace(
    const std::vector<MarkerObservation>& current,
    const std::vector<std::optional<cv::Point2d>>& recent_px, double min_separation_px) {
  CV_Assert(current.size() == recent_px.size());
  std::vector<size_t> rejected;
  for (size_t i = 0; i < current.size(); ++i) {
    if (!current[i].observation.found()) continue;
    const cv::Point2d p = *current[i].observation.position_px;
    if (recent_px[i] && cv::norm(p - *recent_px[i]) < min_separation_px) continue;
    for (size_t j = 0; j < current.size(); ++j) {
      if (j == i || current[j].observation.found() || !recent_px[j]) continue;
      if (cv::norm(p - *recent_px[j]) < min_separation_px) {
        rejected.push_back(i);
        break;
      }
    }
  }
  return rejected;
}

}  // namespace softsight
