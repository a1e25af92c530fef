// A pneumatic soft actuator for the simulated rig: pump, inflate and vent valves, a chamber, and the
// bending that follows its pressure with lag and hysteresis.
//
// Pressure (isothermal ideal gas, flows in standard litres): dp/dt = p_atm / V * (Q_in - Q_out),
//   Q_in  = inflate duty * pump duty * pump free flow * (1 - p / pump stall pressure)
//   Q_out = vent duty * vent flow at 10 kPa * sqrt(p / 10 kPa) + leak * p / 10 kPa
// Bending: the equilibrium bend grows linearly with pressure above `bend_start_kpa`; a play
// (backlash) operator of width `hysteresis_deg` models the silicone's hysteresis, and a first-order
// lag `bend_lag_s` its viscoelastic response.
#pragma once

#include <string>

#include "softsight/control/board.h"

namespace softsight {

struct PlantOptions {
  double chamber_volume_ml = 20.0;       // Chamber + tubing. Larger: slower pressure. Default 20 mL.
  double pump_flow_l_per_min = 1.0;      // Free flow of the pump (standard L/min). Default 1.0.
  double pump_stall_kpa = 120.0;         // Pressure at which the pump's flow drops to 0.
  double vent_flow_l_per_min = 2.0;      // Vent valve flow at 10 kPa, fully open. Default 2.0.
  double leak_l_per_min = 0.001;         // Leak at 10 kPa (linear). Default 0.001.
  double bend_start_kpa = 3.0;           // Below this the actuator does not bend. Default 3 kPa.
  double bend_deg_per_kpa = 6.0;         // Slope of the equilibrium bend. Default 6 deg/kPa.
  double max_bend_deg = 300.0;           // Mechanical end stop of the bend. Default 300 deg.
  double bend_lag_s = 0.15;              // Time constant of the bending response. Default 0.15 s.
  double hysteresis_deg = 3.0;           // Width of the play operator. Default 3 deg.

  bool Check(std::string* error) const;
};

class PneumaticPlant {
 public:
  explicit PneumaticPlant(const PlantOptions& options);
  // Advances by dt_s with constant drive (internally sub-stepped for stability).
  void step(double dt_s, const ValveOutputs& drive);

  double pressure_pa() const { return pressure_pa_; }
  double bend_deg() const { return bend_deg_; }
  // Equilibrium bend at a constant pressure, without hysteresis (for tests and feed-forward).
  double equilibrium_bend_deg(double pressure_pa) const;

 private:
  PlantOptions options_;
  double pressure_pa_ = 0.0;
  double play_deg_ = 0.0;  // Output of the play operator (the hysteresis state).
  double bend_deg_ = 0.0;
};

// The paper's angle at the middle marker for a constant-curvature body whose centre line turns
// `bend_deg` in total, when the middle marker sits mid-arc between end markers that are
// `end_marker_span` of the body length apart (the inscribed angle: 180 - turning between them / 2).
double PaperAngleFromBend(double bend_deg, double end_marker_span);
double BendFromPaperAngle(double angle_deg, double end_marker_span);

}  // namespace softsight
