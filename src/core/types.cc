#include "softsight/core/types.h"
#include "softsight/core/error.h"

namespace softsight {

const char* MarkerStatusName(MarkerStatus status) {
  switch (status) {
    case MarkerStatus::kFound: return "found";
    case MarkerStatus::kLost: return "lost";
    case MarkerStatus::kAmbiguous: return "ambiguous";
    case MarkerStatus::kImplausible: return "implausible";
    case MarkerStatus::kCovered: return "covered";
    case MarkerStatus::kOutOfFrame: return "out_of_frame";
    case MarkerStatus::kNotStarted: return "not_started";
    case MarkerStatus::kStale: return "stale";
  }
  return "lost";
}

const char* TrackStateName(TrackState state) {
  switch (state) {
    case TrackState::kLost: return "lost";
    case TrackState::kTentative: return "tentative";
    case TrackState::kConfirmed: return "confirmed";
    case TrackState::kCoasting: return "coasting";
  }
  return "lost";
}

}  // namespace softsight
