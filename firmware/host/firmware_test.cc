// Runs the sketch itself (softsight_board.ino) against the Arduino shim: pins, timing, serial.
#include <string>

#include <gtest/gtest.h>

#include "shim_control.h"
#include "control/protocol.h"

void setup();
void loop();

namespace softsight {
namespace {

constexpr uint8_t kInflate = 5, kVent = 6, kPump = 9, kSensor = 14;

std::string Line(wire::MessageType type, int32_t a = 0, int32_t b = 0) {
  wire::Message m;
  m.type = type;
  m.argc = static_cast<uint8_t>(wire::ArgumentCount(type));
  m.args[0] = a;
  m.args[1] = b;
  char buffer[wire::kLineBufferSize];
  return std::string(buffer, wire::EncodeMessage(m, buffer, sizeof(buffer)));
}

// Counts of the MPX5100 on a 10-bit ADC for a gauge pressure (the sketch's calibration).
int Counts(double kpa) { return 41 + static_cast<int>(kpa * 9.0 + 0.5); }

class Sketch : public ::testing::Test {
 protected:
  void SetUp() override {
    arduino_shim::Reset();
    arduino_shim::SetAnalog(kSensor, Counts(0.0));
    setup();
  }
  // Runs loop() every 100 us for `ms` milliseconds.
  void Run(int ms) {
    for (int i = 0; i < ms * 10; ++i) {
      now_us_ += 100;
      arduino_shim::SetMicros(now_us_);
      loop();
    }
  }
  wire::Message Command(const std::string& line) {
    arduino_shim::SerialInput(line);
    Run(1);
    std::string out = arduino_shim::TakeSerialOutput();
    wire::Message m;
    if (!out.empty()) {
      EXPECT_EQ(out.back(), '\n');
      EXPECT_EQ(wire::DecodeLine(out.data(), out.size() - 1, &m), wire::DecodeStatus::kOk) << out;
    }
    return m;
  }
  uint32_t now_us_ = 0;
};

TEST_F(Sketch, StartsVentedAtTheRightBaudRate) {
  EXPECT_EQ(arduino_shim::Baud(), 115200u);
  EXPECT_EQ(arduino_shim::Mode(kInflate), 1);
  EXPECT_EQ(arduino_shim::Pwm(kInflate), 0);
  EXPECT_EQ(arduino_shim::Pwm(kPump), 0);
  EXPECT_EQ(arduino_shim::Pwm(kVent), 255);
}

TEST_F(Sketch, HandshakeThenPressureLoopDrivesThePins) {
  const wire::Message hi = Command(Line(wire::MessageType::kHello, wire::kProtocolVersion));
  ASSERT_EQ(hi.type, wire::MessageType::kHelloReply);
  EXPECT_EQ(hi.args[2], 500);  // loop_hz

  const wire::Message state = Command(Line(wire::MessageType::kSetPressure, 1, 20000));
  ASSERT_EQ(state.type, wire::MessageType::kState);
  EXPECT_EQ(state.args[0], 1);
  Run(4);
  EXPECT_EQ(arduino_shim::Pwm(kInflate), 255);  // 20 kPa error: full inflation.
  EXPECT_EQ(arduino_shim::Pwm(kPump), 255);
  EXPECT_EQ(arduino_shim::Pwm(kVent), 0);

  arduino_shim::SetAnalog(kSensor, Counts(20.0));  // At the setpoint: both valves closed.
  Run(4);
  EXPECT_EQ(arduino_shim::Pwm(kVent), 0);
  EXPECT_EQ(arduino_shim::Pwm(kPump), 0);
  const wire::Message read = Command(Line(wire::MessageType::kRead, 2));
  EXPECT_NEAR(read.args[2], 20000, 150);  // The sensed pressure, in Pa.

  arduino_shim::SetAnalog(kSensor, Counts(49.0));  // Above the guard (50 kPa - 2 kPa margin).
  Run(4);
  EXPECT_EQ(arduino_shim::Pwm(kInflate), 0);
  EXPECT_EQ(arduino_shim::Pwm(kVent), 255);
  EXPECT_TRUE(Command(Line(wire::MessageType::kPing, 3)).args[5] & wire::kFlagLimit);
}

TEST_F(Sketch, WatchdogVentsWhenTheHostGoesQuiet) {
  Command(Line(wire::MessageType::kHello, wire::kProtocolVersion));
  Command(Line(wire::MessageType::kSetDuty, 1, 800));
  Run(200);
  EXPECT_EQ(arduino_shim::Pwm(kInflate), 204);  // 0.8 * 255.
  Run(60);  // 261 ms since the command.
  EXPECT_EQ(arduino_shim::Pwm(kInflate), 0);
  EXPECT_EQ(arduino_shim::Pwm(kVent), 255);
  EXPECT_TRUE(Command(Line(wire::MessageType::kRead, 2)).args[5] & wire::kFlagWatchdog);
}

TEST_F(Sketch, CorruptedCommandsAreNotAnsweredNorActedOn) {
  Command(Line(wire::MessageType::kHello, wire::kProtocolVersion));
  std::string bad = Line(wire::MessageType::kSetDuty, 1, 900);
  bad[7] ^= 0x01;
  EXPECT_EQ(Command(bad).type, wire::MessageType::kNone);
  EXPECT_EQ(Command(std::string("\xff\x00garbage\n", 10)).type, wire::MessageType::kNone);
  Run(10);
  EXPECT_EQ(arduino_shim::Pwm(kInflate), 0);
  EXPECT_EQ(Command(Line(wire::MessageType::kRead, 2)).args[6], 2);  // Both counted.
}

TEST_F(Sketch, SpeaksVersion2WithACrcAndIgnoresTwoBitErrorsAnXorWouldPass) {
  arduino_shim::SerialInput("$HELLO 2*0C18\n");  // Typed by hand, from docs/protocol.md.
  Run(1);
  EXPECT_EQ(arduino_shim::TakeSerialOutput(), "$HI 2 50000 500 250*4995\n");
  // The sketch's board lives for the whole program: count from here.
  const int32_t rejected_before = Command(Line(wire::MessageType::kRead, 1)).args[6];
  // A version-1 line (XOR checksum) is not even well formed for this board: no answer.
  EXPECT_EQ(Command("$HELLO 1*53\n").type, wire::MessageType::kNone);
  // "$SETP 10 20000" with bit 0 flipped in two bytes ("$SETP 11 20001"): version 1's XOR was
  // unchanged and the board inflated; the CRC rejects it.
  std::string bad = Line(wire::MessageType::kSetPressure, 10, 20000);
  bad[7] ^= 0x01;
  bad[13] ^= 0x01;
  ASSERT_EQ(bad.substr(0, 15), "$SETP 11 20001*");
  EXPECT_EQ(Command(bad).type, wire::MessageType::kNone);
  Run(10);
  EXPECT_EQ(arduino_shim::Pwm(kInflate), 0);
  EXPECT_EQ(arduino_shim::Pwm(kPump), 0);
  EXPECT_EQ(arduino_shim::Pwm(kVent), 255);
  EXPECT_EQ(Command(Line(wire::MessageType::kRead, 2)).args[6] - rejected_before, 2);  // Both.
}

TEST_F(Sketch, TakesTheHostsInnerLoopGainsTypedAsInTheReadme) {
  Command(Line(wire::MessageType::kHello, wire::kProtocolVersion));
  arduino_shim::SerialInput("$GAIN 2 73 0 335*4F8D\n");  // firmware/README.md, docs/protocol.md.
  Run(1);
  wire::Message m;
  const std::string answer = arduino_shim::TakeSerialOutput();
  ASSERT_FALSE(answer.empty());
  ASSERT_EQ(wire::DecodeLine(answer.data(), answer.size() - 1, &m), wire::DecodeStatus::kOk);
  EXPECT_EQ(m.type, wire::MessageType::kState);
  EXPECT_EQ(m.args[0], 2);
}

}  // namespace
}  // namespace softsight
