// The board side of the cascade: the protocol endpoint, the inner pressure loop, the pressure
// limit guard and the watchdog. The firmware sketch (firmware/softsight_board) and the simulated
// rig (softsight/control/rig.h) run this same code; the sketch only binds it to pins and timers.
// Private to control: library users see the board through its settings and outputs
// (softsight/control/board_config.h) and through the wire (BoardLink).
//
// Shared with the firmware: plain C++11, no heap, C headers only.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include "control/protocol.h"
#include "softsight/control/board_config.h"

namespace softsight {

// PI pressure loop with anti-windup: pressure error -> signed duty (> 0 inflate, < 0 vent).
class PressureLoop {
 public:
  PressureLoop() {}
  explicit PressureLoop(const BoardConfig& config) : config_(config) {}
  // One period of 1 / loop_hz seconds. Returns the duty in [-1, 1].
  float update(int32_t setpoint_pa, int32_t pressure_pa);
  void reset() { integral_ = 0.0f; }
  // New gains from the host ($GAIN); the integral (a duty) is kept, so the output does not jump.
  // `vent_scale` multiplies the duty when it vents: a vent orifice faster than the pump would
  // otherwise give the loop a higher gain one way than the other.
  void set_gains(float kp_per_kpa, float ki_per_kpa_s, float vent_scale) {
    config_.kp_per_kpa = kp_per_kpa;
    config_.ki_per_kpa_s = ki_per_kpa_s;
    vent_scale_ = vent_scale;
  }
  float kp_per_kpa() const { return config_.kp_per_kpa; }
  float ki_per_kpa_s() const { return config_.ki_per_kpa_s; }
  float vent_scale() const { return vent_scale_; }
  // Drops any integral that pushes towards inflation (used while the limit guard vents).
  void unwind_inflation() {
    if (integral_ > 0.0f) integral_ = 0.0f;
  }

 private:
  BoardConfig config_;
  float integral_ = 0.0f;
  float vent_scale_ = 1.0f;
};

class Board {
 public:
  using Mode = BoardMode;

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
  // The board's own settings (as built; $GAIN changes the loop's gains, not these).
  const BoardConfig& config() const { return config_; }
  // The inner loop's gains in use: the board's own until a $GAIN, again after each $HELLO.
  float kp_per_kpa() const { return loop_.kp_per_kpa(); }
  float ki_per_kpa_s() const { return loop_.ki_per_kpa_s(); }
  float vent_scale() const { return loop_.vent_scale(); }

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
