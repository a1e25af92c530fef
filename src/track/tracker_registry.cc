// The name -> factory table behind CreateTracker: adding a method is one row.
#include <memory>
#include <string>
#include <vector>

#include "softsight/core/error.h"
#include "softsight/track/tracker.h"
#include "track/colour_tracker_impl.h"

namespace softsight {
namespace {

using Factory = std::unique_ptr<Tracker> (*)(const MarkerSpec& spec);

struct Method {
  const char* name;
  Factory create;
  bool uses_template;
};

// Each factory checks its own parameters, so the error names the marker and the bad field.
[[noreturn]] void BadParams(const MarkerSpec& spec, const std::string& problem) {
  throw InputError("marker '" + spec.name + "': " + problem);
}

std::unique_ptr<Tracker> CreateColour(const MarkerSpec& spec) {
  std::string problem;
  if (!spec.colour.Check(&problem)) BadParams(spec, problem);
  return std::make_unique<ColourTracker>(spec.colour);
}

// Template matching: the method name picks the measure.
template <MatchMeasure kMeasure>
std::unique_ptr<Tracker> CreateTemplate(const MarkerSpec& spec) {
  TemplateParams params = spec.templ;
  params.measure = kMeasure;
  std::string problem;
  if (!params.Check(&problem)) BadParams(spec, problem);
  return CreateTemplateTracker(params);
}

// In the order --help lists them.
const Method kMethods[] = {
    {"colour", &CreateColour, false},
    {"sad", &CreateTemplate<MatchMeasure::kSad>, true},
    {"ssd", &CreateTemplate<MatchMeasure::kSsd>, true},
    {"zncc", &CreateTemplate<MatchMeasure::kZncc>, true},
};

}  // namespace

const std::vector<MarkerCandidate>& Tracker::candidates() const {
  static const std::vector<MarkerCandidate> kNone;
  return kNone;
}

bool Tracker::membership(const cv::Mat& /*frame_bgr*/, cv::Mat& /*mask*/) const { return false; }

std::optional<cv::Rect> Tracker::search_region() const { return std::nullopt; }

const char* CandidateVerdictName(CandidateVerdict verdict) {
  switch (verdict) {
    case CandidateVerdict::kChosen: return "chosen";
    case CandidateVerdict::kFits: return "fits";
    case CandidateVerdict::kClipped: return "clipped";
    case CandidateVerdict::kSize: return "size";
    case CandidateVerdict::kShape: return "shape";
    case CandidateVerdict::kColour: return "colour";
    case CandidateVerdict::kContrast: return "contrast";
    case CandidateVerdict::kOutsideRoi: return "outside_roi";
  }
  return "fits";
}

std::unique_ptr<Tracker> CreateTracker(const MarkerSpec& spec) {
  for (const Method& method : kMethods) {
    if (spec.method == method.name) return method.create(spec);
  }
  std::string list;
  for (const Method& method : kMethods) list += (list.empty() ? "" : ", ") + std::string(method.name);
  throw InputError("marker '" + spec.name + "': unknown method '" + spec.method + "' (choose " +
                   list + ")");
}

const char* DefaultTrackerMethod(bool has_template) { return has_template ? "zncc" : "colour"; }

bool IsTemplateMethod(const std::string& method) {
  for (const Method& m : kMethods) {
    if (method == m.name) return m.uses_template;
  }
  return false;
}

std::vector<std::string> TrackerMethods() {
  std::vector<std::string> names;
  for (const Method& method : kMethods) names.emplace_back(method.name);
  return names;
}

}  // namespace softsight
