// softsight pressure-control board: the inner loop of the cascade (docs/control.md).
//
// Everything that decides anything lives in the shared code (src/control/board.h and
// protocol.h, unit-tested on the host): the serial protocol, the pressure loop, the pressure limit
// guard and the watchdog. This sketch only binds it to pins and timers. It speaks protocol
// version 2 (every line checked by a CRC-16, docs/protocol.md): after changing the shared code,
// run firmware/copy_shared.sh again before building, or the board keeps the old version and the
// host reports no answer to its handshake. Wiring (Arduino Uno):
//   D5  PWM -> MOSFET -> inflate solenoid valve (pump -> chamber)
//   D6  PWM -> MOSFET -> vent solenoid valve (chamber -> air)
//   D9  PWM -> MOSFET -> pump motor
//   A0  <- pressure sensor (e.g. NXP MPX5100DP: 0.2 V at 0 kPa, 4.7 V at 100 kPa, gauge)
// Build for a board: see firmware/README.md. The host build (firmware/CMakeLists.txt) compiles
// this same file against a small Arduino shim so CI checks it.
#include "softsight_shared.h"

namespace {

const uint8_t kPinInflate = 5;
const uint8_t kPinVent = 6;
const uint8_t kPinPump = 9;
const uint8_t kPinPressure = A0;

// MPX5100 on a 10-bit ADC at 5 V: 41 counts at 0 kPa, 9 counts per kPa (datasheet transfer
// function Vout = Vs * (0.009 * P + 0.04)). Calibrate with the chamber open to air.
const int32_t kSensorZeroCounts = 41;
const int32_t kPaPer10Counts = 1111;

softsight::Board board{softsight::BoardConfig{}};
uint32_t next_loop_us = 0;

int32_t ReadPressurePa() {
  const int32_t counts = analogRead(kPinPressure);
  return (counts - kSensorZeroCounts) * kPaPer10Counts / 10;
}

uint8_t Pwm(float duty) {
  if (duty <= 0.0f) return 0;
  if (duty >= 1.0f) return 255;
  return static_cast<uint8_t>(duty * 255.0f + 0.5f);
}

void Apply(const softsight::ValveOutputs& out) {
  analogWrite(kPinInflate, Pwm(out.inflate));
  analogWrite(kPinVent, Pwm(out.deflate));
  analogWrite(kPinPump, Pwm(out.pump));
}

}  // namespace

void setup() {
  pinMode(kPinInflate, OUTPUT);
  pinMode(kPinVent, OUTPUT);
  pinMode(kPinPump, OUTPUT);
  Apply(softsight::ValveOutputs());  // Safe state from power-up: vented, pump off.
  Serial.begin(115200);
  next_loop_us = micros();
}

void loop() {
  // Commands: each complete line is answered at once (one short line at 115200 baud: ~5 ms).
  while (Serial.available() > 0) {
    const size_t n = board.receive(static_cast<char>(Serial.read()), millis());
    if (n > 0) Serial.write(reinterpret_cast<const uint8_t*>(board.reply()), n);
  }
  // The inner loop at loop_hz, on a fixed schedule (no drift from the serial handling above).
  const uint32_t now_us = micros();
  if (static_cast<int32_t>(now_us - next_loop_us) >= 0) {
    next_loop_us += 1000000UL / board.config().loop_hz;
    Apply(board.update(millis(), ReadPressurePa()));
  }
}
