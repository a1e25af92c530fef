#include "control/inner_loop_probe.h"

#include <algorithm>
#include <cmath>

#include "control/identify.h"
#include "softsight/core/format.h"

namespace softsight {
namespace {

// The valves stay closed this long between inflating and venting: the tube delivers what it
// holds, and the vent starts from a still pressure.
constexpr double kClosedS = 0.2;
// A change of the sensed pressure beyond this is a response, not the sensor's noise.
constexpr double kResponseKpa = 0.2;
// Venting ends here (near vented, where the orifice's flow has little left to show).
constexpr double kVentedKpa = 0.5;

struct Ramp {
  double rate_kpa_per_s = 0.0;  // Signed.
  double delay_s = 0.0;         // From the command to the ramp's start (extrapolated).
  double mid_kpa = 0.0;         // Where the rate was measured.
  bool found = false;
};

}  // namespace

std::optional<InnerLoopGains> InnerLoopGainsFor(const InnerLoopMeasurement& m, double ceiling_kpa) {
  if (!(m.dead_time_s > kShortTubeS)) return std::nullopt;
  // Venting through an orifice speeds up with the square root of the pressure: its rate in the
  // middle of the range the experiment (and the loop) uses.
  const double vent_mid = m.vent_kpa_per_s *
                          std::sqrt(std::max(0.1, 0.5 * ceiling_kpa) / std::max(0.1, m.vent_at_kpa));
  const double k = std::max({m.inflate_kpa_per_s, vent_mid, 1e-3});
  InnerLoopGains gains;
  gains.kp_per_kpa = std::clamp(1.0 / (k * 2.0 * m.dead_time_s), 0.0, kMaxInnerGain);
  gains.ki_per_kpa_s = 0.0;
  return gains;
}

InnerLoopProbe::InnerLoopProbe(double probe_kpa) : probe_kpa_(probe_kpa) {}

std::optional<double> InnerLoopProbe::next(double time_s) {
  if (stage_ == Stage::kDone) return std::nullopt;
  if (stage_start_s_ < 0.0) stage_start_s_ = time_s;
  const double pressure_kpa = points_.empty() ? 0.0 : points_.back().pressure_kpa;
  const double in_stage_s = time_s - stage_start_s_;
  const auto enter = [&](Stage stage) {
    stage_ = stage;
    stage_start_s_ = time_s;
  };
  switch (stage_) {
    case Stage::kInflate:
      if (pressure_kpa >= probe_kpa_) {
        enter(Stage::kClosed);
      } else if (in_stage_s > kProbeStageS) {
        throw IdentifyAbort("identify: the pressure rose to " + ShortNumber(pressure_kpa, 3) +
                            " kPa only in " + FixedNumber(in_stage_s, 1) +
                            " s of full inflation (pump, valve, leak?); vented");
      }
      break;
    case Stage::kClosed:
      if (in_stage_s >= kClosedS) enter(Stage::kVent);
      break;
    case Stage::kVent:
      if (pressure_kpa <= kVentedKpa) {
        enter(Stage::kDone);
        return std::nullopt;
      }
      if (in_stage_s > kProbeStageS) {
        throw IdentifyAbort("identify: the pressure fell to " + ShortNumber(pressure_kpa, 3) +
                            " kPa only in " + FixedNumber(in_stage_s, 1) +
                            " s of full venting (vent valve?); vented");
      }
      break;
    case Stage::kDone:
      break;
  }
  Point point;
  point.duty = stage_ == Stage::kInflate ? 1.0 : stage_ == Stage::kVent ? -1.0 : 0.0;
  points_.push_back(point);
  return point.duty;
}

void InnerLoopProbe::answered(int64_t board_time_ms, double pressure_kpa) {
  if (points_.empty()) return;
  points_.back().board_time_ms = board_time_ms;
  points_.back().pressure_kpa = pressure_kpa;
}

namespace {

// The ramp after the first answer to a duty of `sign`: the first two answers that moved beyond
// the noise (each the pressure when its command arrived, under the previous command's duty), the
// rate between them and the start extrapolated back from the first.
template <typename Point>
Ramp RampAfter(const std::vector<Point>& points, double sign) {
  Ramp ramp;
  size_t first = 0;
  while (first < points.size() && points[first].duty != sign) ++first;
  if (first == points.size()) return ramp;
  const Point& start = points[first];
  const Point* moved[2] = {nullptr, nullptr};
  int n = 0;
  for (size_t j = first + 1; j < points.size() && points[j - 1].duty == sign && n < 2; ++j) {
    if (sign * (points[j].pressure_kpa - start.pressure_kpa) > kResponseKpa) moved[n++] = &points[j];
  }
  if (n < 2 || moved[1]->board_time_ms <= moved[0]->board_time_ms) return ramp;
  ramp.rate_kpa_per_s = (moved[1]->pressure_kpa - moved[0]->pressure_kpa) /
                        ((moved[1]->board_time_ms - moved[0]->board_time_ms) * 1e-3);
  if (!(sign * ramp.rate_kpa_per_s > 0.0)) return ramp;
  ramp.delay_s = (moved[0]->board_time_ms - start.board_time_ms) * 1e-3 -
                 (moved[0]->pressure_kpa - start.pressure_kpa) / ramp.rate_kpa_per_s;
  ramp.mid_kpa = 0.5 * (moved[0]->pressure_kpa + moved[1]->pressure_kpa);
  ramp.found = true;
  return ramp;
}

}  // namespace

InnerLoopMeasurement InnerLoopProbe::measurement() const {
  const Ramp up = RampAfter(points_, 1.0);
  const Ramp down = RampAfter(points_, -1.0);
  if (!up.found || !down.found) {
    throw IdentifyAbort(std::string("identify: the pressure ") +
                        (up.found ? "fell" : "rose") +
                        " within a single frame: the chamber is too small to time its valves at "
                        "this frame rate (a higher --fps?); vented");
  }
  InnerLoopMeasurement m;
  // The inflation's start is the cleaner one (the vent's rate changes with the pressure).
  m.dead_time_s = std::max(0.0, up.delay_s);
  m.inflate_kpa_per_s = up.rate_kpa_per_s;
  m.vent_kpa_per_s = -down.rate_kpa_per_s;
  m.vent_at_kpa = down.mid_kpa;
  return m;
}

}  // namespace softsight
