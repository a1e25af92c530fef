#include "control/plant.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "control/control_options.h"

namespace softsight {
namespace {

constexpr double kAtmPa = 101325.0;
constexpr double kLitrePerMinToM3PerS = 1e-3 / 60.0;
constexpr double kRefPa = 10000.0;  // Flows are specified at 10 kPa.
constexpr double kSubstepS = 0.0002;

}  // namespace

bool PlantOptions::Check(std::string* error) const {
  // Each field's range is its row in control/control_options.cc.
  if (const auto problem = CheckOptions(PlantOptionsTable(), *this)) return Fail(error, *problem);
  return true;
}

PneumaticPlant::PneumaticPlant(const PlantOptions& options) : options_(options) {
  assert(options_.Check(nullptr));
  const auto substeps = static_cast<size_t>(std::lround(options_.tube_delay_s / kSubstepS));
  tube_.assign(substeps, ValveOutputs{});
}

double PneumaticPlant::equilibrium_bend_deg(double pressure_pa) const {
  const double bend = options_.bend_deg_per_kpa * (pressure_pa * 1e-3 - options_.bend_start_kpa);
  return std::clamp(bend, 0.0, options_.max_bend_deg);
}

void PneumaticPlant::step(double dt_s, const ValveOutputs& drive) {
  const double gain_pa_per_m3 = kAtmPa / (options_.chamber_volume_ml * 1e-6);
  const double pump_m3_s = options_.pump_flow_l_per_min * kLitrePerMinToM3PerS;
  const double vent_m3_s = options_.vent_flow_l_per_min * kLitrePerMinToM3PerS;
  const double leak_m3_s = options_.leak_l_per_min * kLitrePerMinToM3PerS;
  const double stall_pa = options_.pump_stall_kpa * 1e3;
  double remaining = dt_s;
  while (remaining > 1e-12) {
    const double h = std::min(kSubstepS, remaining);
    remaining -= h;
    const double p = pressure_pa_;
    ValveOutputs acting = drive;
    if (!tube_.empty()) {  // What the valves did tube_delay_s ago reaches the chamber now.
      std::swap(acting, tube_[tube_next_]);
      tube_next_ = (tube_next_ + 1) % tube_.size();
    }
    const double q_in =
        acting.inflate * acting.pump * pump_m3_s * std::max(0.0, 1.0 - p / stall_pa);
    const double q_out =
        acting.deflate * vent_m3_s * std::sqrt(std::max(0.0, p) / kRefPa) + leak_m3_s * p / kRefPa;
    // The vent cannot pull the chamber below atmospheric pressure.
    pressure_pa_ = std::max(0.0, p + h * gain_pa_per_m3 * (q_in - q_out));

    const double target = equilibrium_bend_deg(pressure_pa_);
    const double half = 0.5 * options_.hysteresis_deg;
    play_deg_ = std::clamp(play_deg_, target - half, target + half);
    bend_deg_ += (play_deg_ - bend_deg_) * (h / options_.bend_lag_s);
  }
}

double PaperAngleFromBend(double bend_deg, double end_marker_span) {
  return 180.0 - 0.5 * end_marker_span * bend_deg;
}

double BendFromPaperAngle(double angle_deg, double end_marker_span) {
  return (180.0 - angle_deg) / (0.5 * end_marker_span);
}

}  // namespace softsight
