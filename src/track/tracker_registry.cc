// The method names and what each builds, the only place they are spelled: adding a method is one
// row (and, for a new kind of tracker, one MarkerParams alternative).
#include <memory>
#include <string>
#include <vector>

#include "softsight/core/error.h"
#include "softsight/track/tracker.h"
#include "track/colour_tracker_impl.h"

namespace softsight {
namespace {

// A method: its name (spelled here only), the parameter set it uses, and for template matching
// its measure.
struct Method {
  const char* name;
  bool uses_template;
  MatchMeasure measure;  // Template methods only.
};

// In the order --help lists them.
const Method kMethods[] = {
    {"colour", false, MatchMeasure::kZncc},
    {"sad", true, MatchMeasure::kSad},
    {"ssd", true, MatchMeasure::kSsd},
    {"zncc", true, MatchMeasure::kZncc},
};

// Each factory checks its own parameters, so the error names the marker and the bad field.
[[noreturn]] void BadParams(const MarkerSpec& spec, const std::string& problem) {
  throw InputError("marker '" + spec.name + "': " + problem);
}

std::string MethodList() {
  std::string list;
  for (const Method& method : kMethods) list += (list.empty() ? "" : ", ") + std::string(method.name);
  return list;
}

}  // namespace

const std::vector<MarkerCandidate>& Tracker::candidates() const {
  static const std::vector<MarkerCandidate> kNone;
  return kNone;
}

bool Tracker::membership(const cv::Mat& /*frame_bgr*/, cv::Mat& /*mask*/) const { return false; }

std::optional<Observation> Tracker::adopt(size_t /*index*/) { return std::nullopt; }

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
    case CandidateVerdict::kPartial: return "partial";
  }
  return "fits";
}

std::unique_ptr<Tracker> CreateTracker(const MarkerSpec& spec) {
  std::string problem;
  if (const auto* colour = std::get_if<ColourParams>(&spec.params)) {
    if (!colour->Check(&problem)) BadParams(spec, problem);
    return std::make_unique<ColourTracker>(*colour);
  }
  const TemplateParams& templ = std::get<TemplateParams>(spec.params);
  if (!templ.Check(&problem)) BadParams(spec, problem);
  return CreateTemplateTracker(templ);
}

std::string TrackerMethodName(const MarkerParams& params) {
  const auto* templ = std::get_if<TemplateParams>(&params);
  for (const Method& method : kMethods) {
    if (method.uses_template == (templ != nullptr) && (!templ || method.measure == templ->measure)) {
      return method.name;
    }
  }
  return kMethods[0].name;  // Unreachable: every measure has its method.
}

MarkerParams ParamsForMethod(const std::string& method, const ColourParams& colour,
                             const TemplateParams& templ) {
  for (const Method& m : kMethods) {
    if (method != m.name) continue;
    if (!m.uses_template) return colour;
    TemplateParams params = templ;
    params.measure = m.measure;
    return params;
  }
  throw InputError("unknown method '" + method + "' (choose " + MethodList() + ")");
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
