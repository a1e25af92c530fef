// The board side of the cascade: the protocol endpoint, the inner pressure loop, the pressure
// limit guard and the watchdog. The firmware sketch (firmware/softsight_board) and the simulated
// rig (rig.h) run this same code; the sketch only binds it to pins and timers.
//
// Shared with the firmware: plain C++11, no heap, C headers only.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include "softsight/control/protocol.h"

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

// PI pressure loop with anti-windup: pressure error -> signed duty (> 0 inflate, < 0 vent).
class PressureLoop {
 public:
  PressureLoop() {}
  explicit PressureLoop(const BoardConfig& config) : config_(config) {}
  // One period of 1 / loop_hz seconds. Returns the duty in [-1, 1].
  float update(int32_t setpoint_pa, int32_t pressure_pa);
  void reset() { integral_ = 0.0f; }
  // Drops any integral that pushes towards inflation (used while the limit guard vents).
  void unwind_inflation() {
    if (integral_ > 0.0f) integral_ = 0.0f;
  }

 private:
  BoardConfig config_;
  float integral_ = 0.0f;
};

class Board {
 public:
  enum class Mode : uint8_t { kIdle, kPressure, kDuty, kStopped, kWatchdog };

  explicit Board(const BoardConfig& config);

  // Feeds one received byte at board time `now_ms`. When it completes a line that needs an
  // answer, returns the answer's length (the line is in reply(), ending in '\n'); else 0.
  size_t receive(char c, uint32_t now_ms);
  const char* reply() const { return reply_; }

  // One inner-loop period (call at loop_hz): the sensed pressure in, the valve drive out. The
  // watchdog and the pressure limit guard act here, whatever the mode and the gains.
  ValveOutputs update(uint32_t now_ms, int32_t pressure_pa);

  Mode mode() const { return mode_; }
  uint16_t flags() const;
  uint32_t rejected() const { return rejected_; }
  int32_t setpoint_pa() const { return setpoint_pa_; }
  int32_t duty_permille() const { return duty_permille_; }
  int32_t pressure_pa() const { return pressure_pa_; }
  const BoardConfig& config() const { return config_; }

 private:
  size_t handle(const wire::Message& message, uint32_t now_ms);
  size_t answer_state(int32_t seq, uint32_t now_ms);
  size_t answer_error(int32_t seq, int32_t code);

  BoardConfig config_;
  PressureLoop loop_;
  wire::LineAssembler assembler_;
  char reply_[wire::kLineBufferSize] = {0};
  Mode mode_ = Mode::kIdle;
  bool handshake_ = false;
  bool guard_ = false;
  uint32_t last_valid_ms_ = 0;
  int32_t setpoint_pa_ = 0;
  int32_t command_duty_permille_ = 0;  // As commanded by $DUTY.
  int32_t duty_permille_ = 0;          // As applied in the last period (after the guard).
  int32_t pressure_pa_ = 0;
  uint32_t rejected_ = 0;
  uint32_t rejected_reported_ = 0;
};

}  // namespace softsight
