#include "control/board.h"

#include <string>

#include <vector>

#include <gtest/gtest.h>

#include "control/plant.h"
#include "control/protocol.h"

namespace softsight {
namespace {

std::string Line(wire::MessageType type, int32_t a = 0, int32_t b = 0) {
  wire::Message m;
  m.type = type;
  m.argc = static_cast<uint8_t>(wire::ArgumentCount(type));
  m.args[0] = a;
  m.args[1] = b;
  char buffer[wire::kLineBufferSize];
  return std::string(buffer, wire::EncodeMessage(m, buffer, sizeof(buffer)));
}

// Sends a line; returns the decoded answer (type kNone when there was none).
wire::Message Send(Board& board, const std::string& line, uint32_t now_ms) {
  std::string reply;
  for (char c : line) {
    const size_t n = board.receive(c, now_ms);
    if (n > 0) reply.assign(board.reply(), n);
  }
  wire::Message m;
  if (!reply.empty()) {
    EXPECT_EQ(wire::DecodeLine(reply.data(), reply.size() - 1, &m), wire::DecodeStatus::kOk);
  }
  return m;
}

std::string GainLine(int32_t seq, int32_t kp_permille, int32_t ki_permille,
                     int32_t vent_permille = 1000) {
  wire::Message m;
  m.type = wire::MessageType::kSetGains;
  m.argc = 4;
  m.args[0] = seq;
  m.args[1] = kp_permille;
  m.args[2] = ki_permille;
  m.args[3] = vent_permille;
  char buffer[wire::kLineBufferSize];
  return std::string(buffer, wire::EncodeMessage(m, buffer, sizeof(buffer)));
}

// $GAIN (docs/protocol.md): the host's gains drive the loop until the next $HELLO; a gain out of
// range, or before the handshake, is refused and changes nothing.
TEST(Board, GainSetsTheInnerLoopForTheSessionAndHelloRestoresTheBoardsOwn) {
  Board board{BoardConfig{}};
  wire::Message m = Send(board, GainLine(1, 50, 120), 0);
  ASSERT_EQ(m.type, wire::MessageType::kError);
  EXPECT_EQ(m.args[1], wire::kErrNoHello);
  EXPECT_FLOAT_EQ(board.kp_per_kpa(), 0.25f);

  Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion), 0);
  m = Send(board, GainLine(2, 50, 120), 0);
  ASSERT_EQ(m.type, wire::MessageType::kState);
  EXPECT_EQ(m.args[0], 2);
  EXPECT_FLOAT_EQ(board.kp_per_kpa(), 0.05f);
  EXPECT_FLOAT_EQ(board.ki_per_kpa_s(), 0.12f);
  // The loop runs on them: 10 kPa of error asks 0.05 * 10 + one period of 0.12 * 10 kPa * 2 ms
  // of duty (the board's own gains would ask 2.5: full inflation).
  Send(board, Line(wire::MessageType::kSetPressure, 3, 20000), 0);
  board.update(2, 10000);
  EXPECT_EQ(board.duty_permille(), 502);

  // Venting at a third of the duty: 10 kPa too much asks a third of 0.05 * 10 of venting (the
  // integral of the period before and this period's cancel).
  Send(board, GainLine(6, 50, 120, 333), 4);
  Send(board, Line(wire::MessageType::kSetPressure, 7, 0), 4);
  board.update(6, 10000);
  EXPECT_EQ(board.duty_permille(), -167);
  Send(board, GainLine(8, 50, 120), 6);

  const int32_t kMaxGain = wire::kMaxGainPermille, kMaxVent = wire::kMaxVentPermille;
  const int32_t bad[][3] = {{-1, 120, 1000},         {50, -1, 1000},       {kMaxGain + 1, 120, 1000},
                            {50, kMaxGain + 1, 1000}, {50, 120, 0},        {50, 120, kMaxVent + 1}};
  for (const auto& b : bad) {
    m = Send(board, GainLine(4, b[0], b[1], b[2]), 4);
    ASSERT_EQ(m.type, wire::MessageType::kError) << b[0] << " " << b[1] << " " << b[2];
    EXPECT_EQ(m.args[1], wire::kErrRange);
    EXPECT_FLOAT_EQ(board.kp_per_kpa(), 0.05f);
    EXPECT_FLOAT_EQ(board.ki_per_kpa_s(), 0.12f);
  }
  EXPECT_FLOAT_EQ(board.vent_scale(), 1.0f);
  m = Send(board, GainLine(5, wire::kMaxGainPermille, 0, wire::kMaxVentPermille), 4);
  EXPECT_EQ(m.type, wire::MessageType::kState) << "the largest gains the wire carries are taken";

  Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion), 6);
  EXPECT_FLOAT_EQ(board.kp_per_kpa(), 0.25f);
  EXPECT_FLOAT_EQ(board.ki_per_kpa_s(), 0.5f);
  EXPECT_FLOAT_EQ(board.vent_scale(), 1.0f);
}

TEST(Board, RequiresTheVersionedHandshake) {
  Board board{BoardConfig{}};
  wire::Message m = Send(board, Line(wire::MessageType::kSetPressure, 1, 20000), 0);
  EXPECT_EQ(m.type, wire::MessageType::kError);
  EXPECT_EQ(m.args[1], wire::kErrNoHello);
  EXPECT_EQ(board.mode(), Board::Mode::kIdle);

  m = Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion + 1), 0);
  EXPECT_EQ(m.type, wire::MessageType::kError);
  EXPECT_EQ(m.args[1], wire::kErrVersion);

  m = Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion), 0);
  ASSERT_EQ(m.type, wire::MessageType::kHelloReply);
  EXPECT_EQ(m.args[0], wire::kProtocolVersion);
  EXPECT_EQ(m.args[1], 50000);
  EXPECT_EQ(m.args[2], 500);
  EXPECT_EQ(m.args[3], 250);

  m = Send(board, Line(wire::MessageType::kSetPressure, 7, 20000), 0);
  ASSERT_EQ(m.type, wire::MessageType::kState);
  EXPECT_EQ(m.args[0], 7);
  EXPECT_EQ(m.args[3], 20000);
  EXPECT_TRUE(m.args[5] & wire::kFlagClosedLoop);
  EXPECT_TRUE(m.args[5] & wire::kFlagHandshake);
}

TEST(Board, RefusesOutOfRangeArguments) {
  Board board{BoardConfig{}};
  Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion), 0);
  EXPECT_EQ(Send(board, Line(wire::MessageType::kSetPressure, 1, 50001), 0).args[1],
            wire::kErrRange);
  EXPECT_EQ(Send(board, Line(wire::MessageType::kSetPressure, 1, -1), 0).args[1], wire::kErrRange);
  EXPECT_EQ(Send(board, Line(wire::MessageType::kSetDuty, 1, 1001), 0).args[1], wire::kErrRange);
  EXPECT_EQ(board.mode(), Board::Mode::kIdle);
}

TEST(Board, WatchdogVentsAfter250msWithoutAValidCommand) {
  Board board{BoardConfig{}};
  Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion), 0);
  Send(board, Line(wire::MessageType::kSetDuty, 1, 600), 0);
  EXPECT_GT(board.update(100, 1000).inflate, 0.5f);
  Send(board, Line(wire::MessageType::kPing, 2), 200);  // Heartbeat keeps it alive.
  const std::string garbage = "$DUTY 3 600*00\n";      // Invalid lines do not.
  Send(board, garbage, 300);
  EXPECT_EQ(board.update(450, 1000).inflate, 0.6f);
  EXPECT_EQ(board.mode(), Board::Mode::kDuty);
  const ValveOutputs vented = board.update(451, 1000);
  EXPECT_EQ(board.mode(), Board::Mode::kWatchdog);
  EXPECT_EQ(vented.inflate, 0.0f);
  EXPECT_EQ(vented.pump, 0.0f);
  EXPECT_EQ(vented.deflate, 1.0f);
  EXPECT_TRUE(board.flags() & wire::kFlagWatchdog);
  EXPECT_TRUE(board.flags() & wire::kFlagVented);
  EXPECT_EQ(board.rejected(), 1u);
  // A new command resumes.
  Send(board, Line(wire::MessageType::kSetDuty, 4, 300), 460);
  EXPECT_EQ(board.mode(), Board::Mode::kDuty);
}

TEST(Board, WatchdogSurvivesTheMillisecondClockWrapping) {
  Board board{BoardConfig{}};
  const uint32_t t0 = 0xFFFFFF00u;
  Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion), t0);
  Send(board, Line(wire::MessageType::kSetDuty, 1, 500), t0);
  board.update(t0 + 200u, 0);  // Wraps past 0.
  EXPECT_EQ(board.mode(), Board::Mode::kDuty);
  board.update(t0 + 251u, 0);
  EXPECT_EQ(board.mode(), Board::Mode::kWatchdog);
}

TEST(Board, StopVentsAndPressureGuardOverridesEveryMode) {
  BoardConfig config;
  config.pressure_limit_pa = 30000;
  Board board(config);
  Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion), 0);
  Send(board, Line(wire::MessageType::kSetDuty, 1, 1000), 0);
  EXPECT_EQ(board.update(2, 27999).inflate, 1.0f);
  ValveOutputs out = board.update(4, 28000);  // limit - margin: the guard trips.
  EXPECT_EQ(out.inflate, 0.0f);
  EXPECT_EQ(out.deflate, 1.0f);
  EXPECT_TRUE(board.flags() & wire::kFlagLimit);
  out = board.update(6, 25001);  // Hysteresis: still venting.
  EXPECT_EQ(out.deflate, 1.0f);
  out = board.update(8, 24999);
  EXPECT_EQ(out.inflate, 1.0f);
  Send(board, Line(wire::MessageType::kStop, 2), 10);
  out = board.update(12, 10000);
  EXPECT_EQ(board.mode(), Board::Mode::kStopped);
  EXPECT_EQ(out.deflate, 1.0f);
  EXPECT_EQ(out.pump, 0.0f);
}

TEST(Board, RejectsAndCountsBadLinesAndFlagsThemOnce) {
  Board board{BoardConfig{}};
  Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion), 0);
  std::string flipped = Line(wire::MessageType::kSetPressure, 1, 20000);
  flipped[9] ^= 0x04;
  EXPECT_EQ(Send(board, flipped, 0).type, wire::MessageType::kNone);
  EXPECT_EQ(Send(board, "hello board\n", 0).type, wire::MessageType::kNone);
  EXPECT_EQ(Send(board, std::string(500, 'A') + "\n", 0).type, wire::MessageType::kNone);
  // A reply-type message sent to the board is not a command.
  EXPECT_EQ(Send(board, Line(wire::MessageType::kError, 1, 1), 0).type, wire::MessageType::kNone);
  EXPECT_EQ(board.mode(), Board::Mode::kIdle);
  EXPECT_EQ(board.rejected(), 4u);
  wire::Message m = Send(board, Line(wire::MessageType::kRead, 5), 0);
  EXPECT_EQ(m.args[6], 4);
  EXPECT_TRUE(m.args[5] & wire::kFlagRejected);
  m = Send(board, Line(wire::MessageType::kRead, 6), 0);
  EXPECT_FALSE(m.args[5] & wire::kFlagRejected);
}

TEST(Board, InnerLoopHoldsThePressureSetpointOnThePlant) {
  BoardConfig config;
  Board board(config);
  PneumaticPlant plant{PlantOptions{}};
  Send(board, Line(wire::MessageType::kHello, wire::kProtocolVersion), 0);
  const double period_s = 1.0 / config.loop_hz;
  uint32_t now_ms = 0;
  double max_pa = 0.0;
  for (int k = 0; k < 1000; ++k) {  // 2 s at 500 Hz.
    now_ms = static_cast<uint32_t>(k * 2);
    if (k % 10 == 0) Send(board, Line(wire::MessageType::kSetPressure, k, 25000), now_ms);
    plant.step(period_s, board.update(now_ms, static_cast<int32_t>(plant.pressure_pa())));
    if (k > 500) max_pa = std::max(max_pa, plant.pressure_pa());
  }
  EXPECT_NEAR(plant.pressure_pa(), 25000.0, 300.0);
  EXPECT_LT(max_pa, 25600.0);
}

TEST(Board, ConfigCheckNamesTheField) {
  BoardConfig config;
  EXPECT_EQ(CheckBoardConfig(config), nullptr);
  config.loop_hz = 100;
  ASSERT_NE(CheckBoardConfig(config), nullptr);
  EXPECT_NE(std::string(CheckBoardConfig(config)).find("loop_hz"), std::string::npos);
}

TEST(Plant, BendsWithPressureAndShowsHysteresis) {
  PlantOptions options;
  options.leak_l_per_min = 0.0;  // So the pressure stays where the valves leave it.
  PneumaticPlant plant(options);
  ValveOutputs inflate{1.0f, 0.0f, 1.0f};
  ValveOutputs hold{0.0f, 0.0f, 0.0f};
  while (plant.pressure_pa() < 20000.0) plant.step(0.002, inflate);
  plant.step(2.0, hold);
  const double up_bend = plant.bend_deg();
  EXPECT_NEAR(up_bend, plant.equilibrium_bend_deg(plant.pressure_pa()) - 1.5, 0.3);
  // Over-inflate then come back to the same pressure: the bend stays higher (hysteresis).
  while (plant.pressure_pa() < 25000.0) plant.step(0.002, inflate);
  while (plant.pressure_pa() > 20000.0) plant.step(0.002, ValveOutputs{0.0f, 0.3f, 0.0f});
  plant.step(2.0, hold);
  EXPECT_GT(plant.bend_deg(), up_bend + 2.0);
}

// A tube between the valves and the chamber: the chamber sees the valves' drive tube_delay_s
// later, so its pressure is the tubeless plant's shifted by the delay.
TEST(Plant, ATubeDelaysWhatTheValvesDoByItsDelay) {
  PlantOptions without;
  PlantOptions with = without;
  with.tube_delay_s = 0.05;
  PneumaticPlant direct(without), tubed(with);
  const ValveOutputs inflate{1.0f, 0.0f, 1.0f};
  std::vector<double> direct_kpa;
  for (int k = 0; k < 100; ++k) {  // 0.2 s in 2 ms steps.
    direct.step(0.002, inflate);
    tubed.step(0.002, inflate);
    direct_kpa.push_back(direct.pressure_pa() * 1e-3);
    if (k < 24) {
      EXPECT_EQ(tubed.pressure_pa(), 0.0) << "the flow is still in the tube at " << (k + 1) * 2 << " ms";
    } else {
      EXPECT_NEAR(tubed.pressure_pa() * 1e-3, k >= 25 ? direct_kpa[k - 25] : 0.0, 1e-6) << k;
    }
  }
  EXPECT_GT(tubed.pressure_pa(), 1000.0);
}

TEST(Plant, PaperAngleRelatesToTheRenderersBend) {
  // Straight: 180. Markers at 0.1 and 0.9 of the body with a 150-degree total bend turn
  // 120 degrees between them; the inscribed angle at the middle is 180 - 120 / 2 = 120.
  EXPECT_DOUBLE_EQ(PaperAngleFromBend(0.0, 0.8), 180.0);
  EXPECT_DOUBLE_EQ(PaperAngleFromBend(150.0, 0.8), 120.0);
  EXPECT_DOUBLE_EQ(BendFromPaperAngle(120.0, 0.8), 150.0);
}

}  // namespace
}  // namespace softsight
