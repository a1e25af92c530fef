// The registry of marker kinds (softsight/track/tracker_kind.h) and what is asked of it by method
// name: the method names are spelled by the kinds (colour_kind.cc, template_kind.cc) only.
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "softsight/core/error.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"
#include "softsight/track/tracker.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {

std::unique_ptr<TrackerKind> MakeColourKind();    // colour_kind.cc
std::unique_ptr<TrackerKind> MakeTemplateKind();  // template_kind.cc

namespace {

struct Registry {
  std::vector<std::unique_ptr<TrackerKind>> owned;
  std::vector<const TrackerKind*> kinds;
  std::map<std::type_index, const TrackerKind*> by_params_type;

  void add(std::unique_ptr<TrackerKind> kind, std::type_index params_type) {
    if (by_params_type.count(params_type) != 0) {
      throw std::logic_error("tracker kind '" + kind->name() + "': its parameter type is taken");
    }
    for (const std::string& method : kind->methods()) {
      if (KindOfMethodIn(method) != nullptr) {
        throw std::logic_error("tracker kind '" + kind->name() + "': method '" + method +
                               "' names another kind");
      }
    }
    by_params_type[params_type] = kind.get();
    kinds.push_back(kind.get());
    owned.push_back(std::move(kind));
  }
  const TrackerKind* KindOfMethodIn(const std::string& method) const {
    for (const TrackerKind* kind : kinds) {
      for (const std::string& name : kind->methods()) {
        if (name == method) return kind;
      }
    }
    return nullptr;
  }
};

// Built on first use, so a MarkerParams made during static initialisation finds the built-in kinds.
Registry& TheRegistry() {
  static Registry registry = [] {
    Registry r;
    r.add(MakeColourKind(), typeid(ColourParams));
    r.add(MakeTemplateKind(), typeid(TemplateParams));
    return r;
  }();
  return registry;
}

// Each factory checks its own parameters, so the error names the marker and the bad field.
[[noreturn]] void BadParams(const MarkerSpec& spec, const std::string& problem) {
  throw InputError("marker '" + spec.name + "': " + problem);
}

std::string MethodList() {
  std::string list;
  for (const std::string& method : TrackerMethods()) list += (list.empty() ? "" : ", ") + method;
  return list;
}

}  // namespace

namespace tracker_detail {
const TrackerKind& KindOfParams(std::type_index type) {
  const Registry& registry = TheRegistry();
  const auto it = registry.by_params_type.find(type);
  if (it == registry.by_params_type.end()) {
    throw std::logic_error(std::string("no tracker kind registered for parameters ") + type.name());
  }
  return *it->second;
}
}  // namespace tracker_detail

MarkerParams::MarkerParams() : MarkerParams(ColourParams{}) {}

const std::vector<const TrackerKind*>& TrackerKinds() { return TheRegistry().kinds; }

void RegisterTrackerKind(std::unique_ptr<TrackerKind> kind, std::type_index params_type) {
  TheRegistry().add(std::move(kind), params_type);
}

const TrackerKind* KindOfMethod(const std::string& method) {
  return TheRegistry().KindOfMethodIn(method);
}

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
  const TrackerKind& kind = spec.params.kind();
  if (std::string problem; !kind.check(spec.params, &problem)) BadParams(spec, problem);
  return kind.create(spec.params);
}

std::string TrackerMethodName(const MarkerParams& params) {
  return params.kind().method_of(params);
}

MarkerParams ParamsForMethod(const std::string& method, const std::vector<MarkerParams>& known) {
  const TrackerKind* kind = KindOfMethod(method);
  if (kind == nullptr) {
    throw InputError("unknown method '" + method + "' (choose " + MethodList() + ")");
  }
  MarkerParams params = kind->defaults();
  for (const MarkerParams& candidate : known) {
    if (&candidate.kind() == kind) {
      params = candidate;
      break;
    }
  }
  kind->select_method(params, method);
  return params;
}

const char* DefaultTrackerMethod(bool has_template) { return has_template ? "zncc" : "colour"; }

bool IsTemplateMethod(const std::string& method) {
  const TrackerKind* kind = KindOfMethod(method);
  return kind != nullptr && kind->selection() == MarkerSelection::kDragBox;
}

std::vector<std::string> TrackerMethods() {
  std::vector<std::string> names;
  for (const TrackerKind* kind : TrackerKinds()) {
    for (std::string& method : kind->methods()) names.push_back(std::move(method));
  }
  return names;
}

}  // namespace softsight
