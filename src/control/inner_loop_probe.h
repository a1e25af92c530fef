// Measures the board's plant, valves to pressure sensor, open loop, before the identification's
// pressure steps: inflation from vented, the valves closed, venting (at a quarter duty; the rates
// are scaled to full duty). From the board's
// own clock in its answers (not the host's, so the serial line's latency is left out) it gives the
// dead time between a valve command and the sensed pressure moving (a tube between the valves and
// the chamber), and the pressure rates of full inflation and full venting.
//
// Why: the board's PI pressure loop is tuned for a short tube. Behind a long one (50 ms) it
// oscillates (18-22 kPa at a constant 20 kPa setpoint), and no outer loop settles on it. The
// delay and the rates give gains that suit the tube (InnerLoopGainsFor), which the host sends to
// the board ($GAIN, docs/protocol.md) for the rest of the experiment and for every later run.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "softsight/control/board_link.h"

namespace softsight {

struct InnerLoopMeasurement {
  double dead_time_s = 0.0;        // From the valve command to the sensed pressure moving.
  double inflate_kpa_per_s = 0.0;  // Full inflation (duty 1), near vented.
  double vent_kpa_per_s = 0.0;     // Full venting (a positive rate) ...
  double vent_at_kpa = 0.0;        // ... at this pressure.
};

// A delay up to this is what the board's own gains are made for (a few loop periods of a board
// with its valves at the chamber): the board keeps them.
constexpr double kShortTubeS = 0.015;

// Gains for the board's PI loop behind the measured tube: nothing for a short one (the board's
// own). The chamber is an integrator with dead time (duty -> pressure rate k), so Skogestad's SIMC
// rule for it with the closed-loop time twice the dead time: kp = 1 / (k (3 theta)), with k
// inflation's rate, and the venting duty scaled by inflation's rate over venting's (taken in the
// middle of the range: an orifice's flow grows with the square root of the pressure), so the
// loop has the same gain both ways (phase margin about 70 deg: with the closed-loop time equal to
// the dead time the pressure overshot and the angle's step by 8-13 %). No integral: the chamber
// integrates already, so P alone holds a setpoint (the leak leaves a few pascals), an integral
// overshot by 2 kPa at every step behind a 50 ms tube, and the outer loop's integral removes
// what is left of the angle.
std::optional<InnerLoopGains> InnerLoopGainsFor(const InnerLoopMeasurement& m, double ceiling_kpa);

// The longest the inflation or the venting may take before the probe gives up.
constexpr double kProbeStageS = 5.0;

class InnerLoopProbe {
 public:
  // Inflates to `probe_kpa` (sensed), closes the valves for a moment, vents to near 0.
  explicit InnerLoopProbe(double probe_kpa);

  // The valve duty for the frame at `time_s` (> 0 inflate, 0 closed, < 0 vent); nothing once
  // the probe is done. Throws IdentifyAbort when the pressure does not rise when inflating (or
  // fall when venting) within kProbeStageS.
  std::optional<double> next(double time_s);
  // The board's answer to that duty: its clock and its sensed pressure.
  void answered(int64_t board_time_ms, double pressure_kpa);
  bool done() const { return stage_ == Stage::kDone; }
  // After done(). Throws IdentifyAbort when the answers do not show a rise and a fall.
  InnerLoopMeasurement measurement() const;

 private:
  enum class Stage { kInflate, kClosed, kVent, kDone };
  struct Point {
    double duty = 0.0;
    int64_t board_time_ms = 0;
    double pressure_kpa = 0.0;
  };

  double probe_kpa_;
  Stage stage_ = Stage::kInflate;
  double stage_start_s_ = -1.0;
  std::vector<Point> points_;  // One per frame: the duty sent and the answer to it.
};

}  // namespace softsight
