// What the board is set up with and what it drives: the settings of the inner loop, the valve and
// pump outputs and the board's mode. Public because the simulated rig's options (rig.h) and its
// snapshots carry them; the board's logic itself is internal to the control library.
//
// Shared with the firmware: plain C++11, no heap, C headers only.
#pragma once

#include <stdint.h>

namespace softsight {

// Valve and pump drive, each a PWM duty in [0, 1]. The default is the safe state: pump off, inflate
// valve closed, vent (deflate) valve open.
struct ValveOutputs {
  float inflate = 0.0f;
  float deflate = 1.0f;
  float pump = 0.0f;
};

struct BoardConfig {
  // Hard pressure limit, gauge Pa. The guard (below) keeps the chamber under it whatever the
  // commands and gains. Default 50 kPa: typical for small silicone actuators.
  int32_t pressure_limit_pa = 50000;
  // The guard trips at limit - guard_margin_pa: one loop period of full inflation (plus sensor
  // noise) must fit in the margin. Default 2 kPa (a 1 L/min pump into 20 mL rises ~0.2 kPa per
  // 2 ms period).
  int32_t guard_margin_pa = 2000;
  // Hysteresis of the guard: it releases below trip - guard_release_pa. Default 3 kPa.
  int32_t guard_release_pa = 3000;
  // Inner loop rate (Hz). Default 500; >= 200 so the pressure loop is much faster than a camera.
  uint16_t loop_hz = 500;
  // No valid command for this long -> vent to the safe state. Default 250 ms.
  uint16_t watchdog_ms = 250;
  // Pressure loop gains: duty per kPa of error, and duty per kPa*s. Defaults suit ~20 mL chambers;
  // higher kp is faster but chatters ON/OFF valves.
  float kp_per_kpa = 0.25f;
  float ki_per_kpa_s = 0.5f;
  // |error| below this holds both valves closed (no chatter around the setpoint). Default 150 Pa.
  int32_t deadband_pa = 150;
};

// Returns 0 when `config` is usable, else a static string naming the bad field.
const char* CheckBoardConfig(const BoardConfig& config);

// What the board is doing (the mode behind the <flags> of its $STATE answers).
enum class BoardMode : uint8_t { kIdle, kPressure, kDuty, kStopped, kWatchdog };

}  // namespace softsight
