// A pneumatic soft actuator for the simulated rig: pump, inflate and vent valves, a chamber, and the
// bending that follows its pressure with lag and hysteresis.
//
// Pressure (isothermal ideal gas, flows in standard litres): dp/dt = p_atm / V * (Q_in - Q_out),
//   Q_in  = inflate duty * pump duty * pump free flow * (1 - p / pump stall pressure)
//   Q_out = vent duty * vent flow at 10 kPa * sqrt(p / 10 kPa) + leak * p / 10 kPa
// Bending: the equilibrium bend grows linearly with pressure above `bend_start_kpa`; a play
// (backlash) operator of width `hysteresis_deg` models the silicone's hysteresis, and a first-order
// lag `bend_lag_s` its viscoelastic response. A tube of `tube_delay_s` between the valves and the
// chamber delays the valves' drive: the flows act with the drive of tube_delay_s ago.
//
// Private to control: the rig (softsight/control/rig.h) runs it; its options are RigOptions::plant.
#pragma once

#include <vector>

#include "softsight/control/board_config.h"
#include "softsight/control/rig.h"  // PlantOptions

namespace softsight {

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
  // The drive of the last tube_delay_s, one entry per substep (a ring, sized once).
  std::vector<ValveOutputs> tube_;
  size_t tube_next_ = 0;
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
