// The candidates of `init`'s marker finder (marker_finder_parts.h, step 1): every compact blob
// the colour tracker's whole-frame acquisition weighs in overlapping hue bands (or gray-level
// bands on gray frames), with the verdicts it gives them.
#include <string>
#include <utility>
#include <vector>

#include "track/marker_finder_parts.h"

namespace softsight::marker_finding {
namespace {

// Gray-level bands of the candidate search on gray frames: bright dots at or above, dark dots at
// or below these levels.
constexpr int kBrightLevels[] = {230, 200, 170, 140, 110};
constexpr int kDarkLevels[] = {25, 50, 80};
// Candidates from different bands closer than this (in marker radii, at least 2 px) are one blob.
constexpr double kSameBlobRadii = 0.5;
// Rejected blobs smaller than this are not drawn or listed (texture specks are many).
constexpr double kListedRejectAreaPx = 20.0;

const char* RejectReason(CandidateVerdict verdict) {
  switch (verdict) {
    case CandidateVerdict::kSize:
      return "size";
    case CandidateVerdict::kShape:
      return "shape (not compact)";
    case CandidateVerdict::kColour:
      return "colour";
    case CandidateVerdict::kContrast:
      return "contrast (background)";
    default:
      return CandidateVerdictName(verdict);
  }
}

// Adds `c` to `list` unless a blob there already is the same one; keeps the larger.
void Merge(std::vector<Candidate>* list, const Candidate& c) {
  for (Candidate& other : *list) {
    const double near = std::max(2.0, kSameBlobRadii * RadiusOf(std::max(c.area_px, other.area_px)));
    if (cv::norm(other.position_px - c.position_px) < near) {
      if (c.area_px > other.area_px) other = c;
      return;
    }
  }
  list->push_back(c);
}

}  // namespace

// One probe of the colour tracker's whole-frame first acquisition with `colour`: what it weighed.
std::vector<MarkerCandidate> Probe(const cv::Mat& frame, const ColourParams& colour) {
  MarkerSpec spec;
  spec.name = "probe";
  spec.params = colour;
  const auto tracker = CreateTracker(spec);
  Frame f;
  f.image = frame;
  tracker->start(f);
  tracker->update(frame);
  return tracker->candidates();
}

// See marker_finder_parts.h.
std::vector<Candidate> FindCandidates(const cv::Mat& frame, const MarkerFinderOptions& options,
                                      const cv::Rect& search, MarkerFinding* finding_out) {
  MarkerFinding& finding = *finding_out;
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  const cv::Rect2d search_area(search.x - 0.5, search.y - 0.5, search.width, search.height);
  ColourParams probe;
  probe.min_area_px = options.min_area_px;
  probe.max_area_px = std::max(options.min_area_px + 1,
                               options.max_area_fraction * frame_rect.area());
  std::vector<ColourParams> bands;
  if (finding.intensity) {
    for (int level : kBrightLevels) {
      probe.gray = HsvRange{level, 255};
      bands.push_back(probe);
    }
    for (int level : kDarkLevels) {
      probe.gray = HsvRange{0, level};
      bands.push_back(probe);
    }
  } else {
    probe.s = {options.min_saturation, 255};
    // Each hue band from the value floor, and again from half of it: a blue or violet dome under
    // warm or side light is dim in value (its largest channel, 24-68 on the side-lit render)
    // while plainly coloured, and the floor cut it into a sliver that did not stand out. The
    // dimmer band's blobs face the same verdicts; where one blob fits in both, the larger counts.
    for (int v_floor : {options.min_value, options.min_value / 2}) {
      probe.v = {v_floor, 255};
      for (int centre = 0; centre < 180; centre += kHueStep) {
        probe.h = HsvRange::HueAround(centre, kHueReach);
        bands.push_back(probe);
      }
    }
  }
  std::vector<Candidate> fitting;
  std::vector<std::pair<Candidate, std::string>> rejects;
  for (const ColourParams& band : bands) {
    for (const MarkerCandidate& c : Probe(frame, band)) {
      if (!search_area.contains(c.position_px)) continue;
      Candidate candidate{c.position_px, c.area_px, c.circularity, false, band.gray};
      if (c.verdict == CandidateVerdict::kFits || c.verdict == CandidateVerdict::kChosen) {
        Merge(&fitting, candidate);
      } else if (!finding.intensity && c.verdict == CandidateVerdict::kShape &&
                 c.circularity >= kMinCandidateCircularity && c.area_px >= options.min_area_px) {
        candidate.elongated = true;
        Merge(&fitting, candidate);
      } else if (c.area_px >= kListedRejectAreaPx) {
        rejects.emplace_back(candidate, RejectReason(c.verdict));
      }
    }
  }
  // A blob that fitted in one band is not also a reject from another (its partial hue there).
  std::vector<Candidate> listed;
  for (const auto& [candidate, why] : rejects) {
    bool known = false;
    for (const Candidate& f : fitting) {
      if (cv::norm(f.position_px - candidate.position_px) < std::max(2.0, RadiusOf(f.area_px))) {
        known = true;
      }
    }
    const size_t before = listed.size();
    if (!known) Merge(&listed, candidate);
    if (listed.size() > before) {
      finding.rejected.push_back({candidate.position_px, RadiusOf(candidate.area_px), why});
    }
  }
  return fitting;
}

}  // namespace softsight::marker_finding
