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
// The probe's valve duty, inflating and venting: a quarter of the full flow, so the actuator
// bends no faster than in the pressure steps (a soft actuator on a small chamber at full duty
// bends 50 deg a frame, which no tracker follows); the rates are scaled to full duty.
constexpr double kProbeDuty = 0.25;

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
  const double inflate = std::max(m.inflate_kpa_per_s, 1e-3);
  InnerLoopGains gains;
  gains.kp_per_kpa = std::clamp(1.0 / (inflate * 3.0 * m.dead_time_s), 0.0, kMaxInnerGain);
  gains.ki_per_kpa_s = 0.0;
  // Venting at the inflation's rate per unit of duty: the same loop gain, and margin, both ways.
  gains.vent_scale = std::clamp(inflate / std::max(vent_mid, 1e-3), kMinVentScale, kMaxVentScale);
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
                            " s of inflation at a quarter duty (pump, valve, leak?); vented");
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
                            " s of venting at a quarter duty (vent valve?); vented");
      }
      break;
    case Stage::kDone:
      break;
  }
  Point point;
  point.duty = stage_ == Stage::kInflate ? kProbeDuty : stage_ == Stage::kVent ? -kProbeDuty : 0.0;
  points_.push_back(point);
  return point.duty;
}

void InnerLoopProbe::answered(int64_t board_time_ms, double pressure_kpa) {
  if (points_.empty()) return;
  points_.back().board_time_ms = board_time_ms;
  points_.back().pressure_kpa = pressure_kpa;
}

namespace {

// The ramp after the first answer to a duty of `sign`: a least-squares line through the first
// kRampPoints answers that moved beyond the noise (each the pressure when its command arrived,
// under the previous command's duty), its rate, and its start extrapolated back to the pressure
// when the duty was sent.
constexpr size_t kRampPoints = 6;

template <typename Point>
Ramp RampAfter(const std::vector<Point>& points, double sign) {
  // `sign`: the probe's duty that way; the ramp is the pressure's answer to it.
  Ramp ramp;
  size_t first = 0;
  while (first < points.size() && points[first].duty != sign) ++first;
  if (first == points.size()) return ramp;
  const Point& start = points[first];
  const double way = sign > 0.0 ? 1.0 : -1.0;
  double n = 0, st = 0, sp = 0, stt = 0, stp = 0;
  for (size_t j = first + 1; j < points.size() && points[j - 1].duty == sign && n < kRampPoints;
       ++j) {
    if (way * (points[j].pressure_kpa - start.pressure_kpa) <= kResponseKpa) continue;
    const double t = (points[j].board_time_ms - start.board_time_ms) * 1e-3;
    const double p = points[j].pressure_kpa;
    n += 1;
    st += t;
    sp += p;
    stt += t * t;
    stp += t * p;
  }
  const double det = n * stt - st * st;
  if (n < 3 || !(det > 0.0)) return ramp;
  ramp.rate_kpa_per_s = (n * stp - st * sp) / det;
  if (!(way * ramp.rate_kpa_per_s > 0.0)) return ramp;
  const double offset = (sp - ramp.rate_kpa_per_s * st) / n;  // The line's pressure at t = 0.
  ramp.delay_s = (start.pressure_kpa - offset) / ramp.rate_kpa_per_s;
  ramp.mid_kpa = sp / n;
  ramp.found = true;
  return ramp;
}

}  // namespace

InnerLoopMeasurement InnerLoopProbe::measurement() const {
  const Ramp up = RampAfter(points_, kProbeDuty);
  const Ramp down = RampAfter(points_, -kProbeDuty);
  if (!up.found || !down.found) {
    throw IdentifyAbort(std::string("identify: the pressure ") +
                        (up.found ? "fell" : "rose") +
                        " within a single frame: the chamber is too small to time its valves at "
                        "this frame rate (a higher --fps?); vented");
  }
  InnerLoopMeasurement m;
  // The inflation's start is the cleaner one (the vent's rate changes with the pressure).
  m.dead_time_s = std::max(0.0, up.delay_s);
  m.inflate_kpa_per_s = up.rate_kpa_per_s / kProbeDuty;
  m.vent_kpa_per_s = -down.rate_kpa_per_s / kProbeDuty;
  m.vent_at_kpa = down.mid_kpa;
  return m;
}

}  // namespace softsight
