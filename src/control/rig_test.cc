// The closed loop over a real pseudo-terminal: host (BoardLink over LibSerial) -> pty -> simulated
// board + pneumatic plant. Lock-step simulated time: the host advances the rig one camera period per
// frame, so the runs are deterministic and take milliseconds per simulated second.
#include "softsight/control/rig.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "control/protocol.h"
#include "control/rig_test_util.h"
#include "core/test_util.h"
#include "softsight/control/board_link.h"
#include "softsight/control/session.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr double kFps = 30.0;

struct LoopRun {
  std::vector<ControlSample> samples;
  std::vector<RigSnapshot> rig;  // Rig state when each frame was taken.
};

// Closes the loop: the "camera" sees the rig's true angle plus noise, unless `visible` says no.
LoopRun RunLoop(SimulatedRig& rig, BoardLink& link, const ControllerOptions& controller,
                ControlTarget target, double seconds, const std::function<bool(double)>& visible) {
  ControlSession session(controller, link, std::move(target));
  session.start();
  LoopRun out;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.15);
  const int frames = static_cast<int>(std::lround(seconds * kFps));
  for (int k = 0; k <= frames; ++k) {
    const double t = k / kFps;
    if (k > 0) rig.advance(1.0 / kFps);
    const RigSnapshot snap = rig.snapshot();
    std::optional<double> measured;
    if (visible(t)) measured = snap.angle_deg + noise(rng);
    out.samples.push_back(session.step(t, measured));
    out.rig.push_back(snap);
  }
  return out;
}

// The loop over a real pseudo-terminal, opened through LibSerial.
class LoopHarness {
 public:
  explicit LoopHarness(RigOptions rig_options = {}, ControllerOptions controller = {},
                       LinkOptions link = InProcessLinkOptions({}))
      : rig_(rig_options),
        server_(rig_),
        transport_(OpenSerialTransport(server_.port(), 115200)),
        link_(*transport_, link),
        controller_(controller) {}

  LoopRun run(ControlTarget target, double seconds,
          const std::function<bool(double)>& visible = [](double) { return true; }) {
    return RunLoop(rig_, link_, controller_, std::move(target), seconds, visible);
  }

  SimulatedRig& rig() { return rig_; }
  RigServer& server() { return server_; }
  BoardLink& link() { return link_; }

 private:
  SimulatedRig rig_;
  RigServer server_;
  std::unique_ptr<Transport> transport_;
  BoardLink link_;
  ControllerOptions controller_;
};

// The same loop in-process, the link's deadlines in simulated time too (rig_test_util.h): for the
// loop's figures, where the wire adds nothing and waits in real time made the test flaky on a
// loaded machine.
class DirectLoop {
 public:
  explicit DirectLoop(RigOptions rig_options = {}, ControllerOptions controller = {})
      : rig_(rig_options),
        transport_(rig_),
        link_(transport_, LinkOptions{}, transport_.environment()),
        controller_(controller) {}

  LoopRun run(ControlTarget target, double seconds) {
    return RunLoop(rig_, link_, controller_, std::move(target), seconds,
                   [](double) { return true; });
  }

 private:
  SimulatedRig rig_;
  testing::DirectRigTransport transport_;
  BoardLink link_;
  ControllerOptions controller_;
};

ControlTarget AngleTarget(TargetProfile profile) {
  ControlTarget t;
  t.mode = ControlMode::kAngle;
  t.profile = std::move(profile);
  return t;
}

// An in-process simulated board (`--simulate`) is waited for longer than a real board: its
// thread may be held back on a busy machine, and its time is simulated. A longer configured
// deadline stays; the retries are as configured.
TEST(InProcessLink, WaitsAtLeastTheInProcessDeadlineAndKeepsALongerOne) {
  LinkOptions configured;
  configured.reply_timeout_ms = 100;
  configured.retries = 4;
  const LinkOptions in_process = InProcessLinkOptions(configured);
  EXPECT_EQ(in_process.reply_timeout_ms, kInProcessReplyTimeoutMs);
  EXPECT_EQ(in_process.retries, 4);
  EXPECT_EQ(in_process.baud, configured.baud);
  configured.reply_timeout_ms = kInProcessReplyTimeoutMs + 500;
  EXPECT_EQ(InProcessLinkOptions(configured).reply_timeout_ms, kInProcessReplyTimeoutMs + 500);
}

TEST(ClosedLoop, StepTo120DegreesSettlesWithin3sWithSmallOvershoot) {
  LoopHarness h;
  const LoopRun run = h.run(AngleTarget(TargetProfile::Constant(120.0)), 5.0);
  // Overshoot: how far past 120 (smaller angle = more bent) relative to the 60-degree step.
  double min_angle = 180.0;
  for (const RigSnapshot& s : run.rig) min_angle = std::min(min_angle, s.angle_deg);
  const double overshoot = std::max(0.0, 120.0 - min_angle) / 60.0;
  // Settling: the last time the true angle was outside +-2 degrees.
  double settle_s = 0.0;
  for (size_t k = 0; k < run.rig.size(); ++k) {
    if (std::abs(run.rig[k].angle_deg - 120.0) > 2.0) settle_s = run.samples[k].time_s + 1.0 / kFps;
  }
  RecordProperty("settle_s", std::to_string(settle_s));
  RecordProperty("overshoot_percent", std::to_string(overshoot * 100));
  std::printf("step 180->120: settles (+-2 deg) in %.2f s, overshoot %.1f %%\n", settle_s,
              overshoot * 100);
  EXPECT_LT(settle_s, 3.0);
  EXPECT_LT(overshoot, 0.10);
  EXPECT_NEAR(run.rig.back().angle_deg, 120.0, 1.0);
  EXPECT_EQ(h.link().stats().rejected_lines, 0u);
}


// RMS of true angle - target after the first `skip_s` seconds.
double RmsError(const LoopRun& run, double skip_s) {
  double sum_sq = 0.0;
  int n = 0;
  for (size_t k = 0; k < run.rig.size(); ++k) {
    if (run.samples[k].time_s < skip_s) continue;
    const double e = run.rig[k].angle_deg - *run.samples[k].target_deg;
    sum_sq += e * e;
    ++n;
  }
  return std::sqrt(sum_sq / n);
}

TEST(ClosedLoop, FollowsASineTargetAndReportsRmsError) {
  const TargetProfile profile =
      TargetProfile::Parse("step 140\nhold 2\nsine 140 20 0.25 8\n", "sine.txt");
  DirectLoop pi_only;
  const double pi_rms_deg = RmsError(pi_only.run(AngleTarget(profile), 10.0), 2.0);
  // With the feed-forward of the plant's static gain (6 deg bend per kPa, 0.4 deg of angle per
  // degree of bend: 2.4 deg/kPa), as an open-loop characterisation would give it.
  ControllerOptions with_ff;
  with_ff.ff_kpa_per_deg = 1.0 / 2.4;
  with_ff.bias_kpa = 3.0;
  DirectLoop ff(RigOptions{}, with_ff);
  const double ff_rms_deg = RmsError(ff.run(AngleTarget(profile), 10.0), 2.0);
  RecordProperty("sine_rms_deg_pi", std::to_string(pi_rms_deg));
  RecordProperty("sine_rms_deg_pi_ff", std::to_string(ff_rms_deg));
  std::printf("sine 140 +- 20 deg at 0.25 Hz: RMS error %.2f deg (PI), %.2f deg (PI + feed-forward)\n",
              pi_rms_deg, ff_rms_deg);
  EXPECT_LT(pi_rms_deg, 8.0);
  EXPECT_LT(ff_rms_deg, 3.0);
  EXPECT_LT(ff_rms_deg, 0.6 * pi_rms_deg);
  EXPECT_GT(ff_rms_deg, 0.05);  // The plant lags: perfect tracking would mean the test is not real.
}

TEST(ClosedLoop, ShortVisionLossHoldsWithoutWindupAndRecovers) {
  LoopHarness h;
  // Settled at 120 after 3 s, vision lost for 0.5 s, target changed during the loss.
  const TargetProfile profile = TargetProfile::Parse("step 120\nhold 3.2\nstep 110\n", "p.txt");
  auto visible = [](double t) { return t < 3.0 || t > 3.5; };
  const LoopRun run = h.run(AngleTarget(profile), 6.0, visible);
  double held_kpa = -1.0;
  for (size_t k = 0; k < run.samples.size(); ++k) {
    const ControlSample& s = run.samples[k];
    if (s.time_s > 3.0 + 1e-9 && s.time_s <= 3.5) {
      EXPECT_EQ(s.action, ControllerOutput::Action::kHold) << s.time_s;
      if (held_kpa < 0) held_kpa = *s.setpoint_kpa;
      // Holding: the same setpoint, whatever the changed target says (no integration).
      EXPECT_DOUBLE_EQ(*s.setpoint_kpa, held_kpa) << s.time_s;
      EXPECT_FALSE(s.board.vented());
    }
  }
  ASSERT_GT(held_kpa, 20.0);
  // Recovers to the new target without the kick a wound-up integral would give.
  double min_angle = 180.0;
  for (size_t k = 0; k < run.rig.size(); ++k) {
    if (run.samples[k].time_s > 3.5) min_angle = std::min(min_angle, run.rig[k].angle_deg);
  }
  EXPECT_GT(min_angle, 110.0 - 2.0);
  EXPECT_NEAR(run.rig.back().angle_deg, 110.0, 2.0);
}

TEST(ClosedLoop, LongVisionLossVents) {
  LoopHarness h;
  auto visible = [](double t) { return t < 2.0; };
  const LoopRun run = h.run(AngleTarget(TargetProfile::Constant(120.0)), 4.0, visible);
  for (size_t k = 0; k < run.samples.size(); ++k) {
    const ControlSample& s = run.samples[k];
    if (s.time_s > 2.55) {
      EXPECT_EQ(s.action, ControllerOutput::Action::kVent) << s.time_s;
      EXPECT_TRUE(s.board.vented()) << s.time_s;
    }
  }
  EXPECT_LT(run.rig.back().pressure_kpa, 1.0);
  EXPECT_GT(run.rig.back().angle_deg, 175.0);  // Back to (nearly) straight.
}

TEST(ClosedLoop, PortDisappearsMidRunOneClearErrorAndTheWatchdogVents) {
  LoopHarness h;
  ControlSession session(ControllerOptions{}, h.link(),
                         AngleTarget(TargetProfile::Constant(120.0)));
  session.start();
  int frames = 0;
  std::string error;
  try {
    for (int k = 0; k < 150; ++k) {
      if (k > 0) h.rig().advance(1.0 / kFps);
      if (k == 60) h.server().disconnect();  // Cable pulled at 2 s.
      session.step(k / kFps, h.rig().snapshot().angle_deg);
      ++frames;
    }
  } catch (const InputError& e) {
    error = e.what();
  }
  EXPECT_EQ(frames, 60);
  EXPECT_NE(error.find("serial port /dev/pts/"), std::string::npos) << error;
  EXPECT_NE(error.find("disconnected"), std::string::npos) << error;
  const RigSnapshot before = h.rig().snapshot();
  EXPECT_GT(before.pressure_kpa, 15.0);
  EXPECT_EQ(before.mode, BoardMode::kPressure);
  h.rig().advance(0.2);
  EXPECT_EQ(h.rig().snapshot().mode, BoardMode::kPressure);  // Not yet: 250 ms.
  h.rig().advance(0.1);
  EXPECT_EQ(h.rig().snapshot().mode, BoardMode::kWatchdog);
  h.rig().advance(1.0);
  EXPECT_LT(h.rig().snapshot().pressure_kpa, 1.0);
}

TEST(ClosedLoop, GarbageAndBitFlippedAnswersAreRejectedAndCounted) {
  // Answers over a pty take well under a millisecond, but a loaded machine can hold the rig's
  // thread for tens: a short deadline, and retries enough that no frame's command fails.
  LinkOptions fast_retry;
  fast_retry.reply_timeout_ms = 40;
  fast_retry.retries = 5;
  LoopHarness h(RigOptions{}, ControllerOptions{}, fast_retry);
  int answer = 0;
  // Every third answer gets one bit flipped; every fifth is preceded by line noise.
  h.server().set_reply_filter([&answer](const std::string& line) {
    ++answer;
    std::string out = line;
    if (answer % 3 == 0 && out.size() > 4) {
      const size_t i = 1 + static_cast<size_t>(answer) % (out.size() - 2);
      out[i] = static_cast<char>(out[i] ^ (1 << (answer % 7)));
    }
    if (answer % 5 == 0) out = std::string("\x01\xfe garbage \x7f\n$STATE 1 2*00\n") + out;
    return out;
  });
  const LoopRun run = h.run(AngleTarget(TargetProfile::Constant(120.0)), 3.0);
  const LinkStats& stats = h.link().stats();
  std::printf("corrupted link: %llu rejected lines, %llu resends, %llu stale\n",
              static_cast<unsigned long long>(stats.rejected_lines),
              static_cast<unsigned long long>(stats.resends),
              static_cast<unsigned long long>(stats.stale_answers));
  EXPECT_GE(stats.rejected_lines, 40u);
  EXPECT_GE(stats.resends, 20u);  // Each flipped answer is asked for again.
  // The loop still works: every sample carries a genuine answer.
  EXPECT_NEAR(run.rig.back().angle_deg, 120.0, 2.0);
}

TEST(ClosedLoop, CorruptedCommandsAreRejectedByTheBoardAndNeverActedOn) {
  LoopHarness h;
  h.link().handshake();
  // A second writer on the line, under the host's lock (which only softsight processes honour).
  const int fd = ::open(h.server().port().c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  auto transport = MakeFdTransport(fd, "a second writer");
  // A setpoint with one flipped bit in its value ("30000" -> "38000"), CRC unchanged.
  wire::Message setp;
  setp.type = wire::MessageType::kSetPressure;
  setp.argc = 2;
  setp.args[0] = 5;
  setp.args[1] = 30000;
  char buffer[wire::kLineBufferSize];
  const std::string line(buffer, wire::EncodeMessage(setp, buffer, sizeof(buffer)));
  ASSERT_EQ(line.substr(0, 14), "$SETP 5 30000*");
  std::string flipped = line;
  flipped[9] = static_cast<char>(flipped[9] ^ 0x08);  // "30000" -> "38000".
  transport->write_line(flipped);
  transport->write_line("$SETP 5 300");  // Truncated, then a newline from the next write.
  transport->write_line("\nrandom noise\n");
  EXPECT_FALSE(transport->read_line(50).has_value());  // Never answered.
  h.rig().advance(0.5);
  EXPECT_EQ(h.rig().snapshot().mode, BoardMode::kIdle);  // Never acted on.
  EXPECT_LT(h.rig().snapshot().pressure_kpa, 0.5);
  EXPECT_EQ(h.rig().snapshot().board_rejected, 3u);
  const BoardState state = h.link().read_state();
  EXPECT_EQ(state.board_rejected, 3u);
  EXPECT_TRUE(state.flags & wire::kFlagRejected);
  // The genuine line is acted on.
  transport->write_line(line);
  ASSERT_TRUE(transport->read_line(200).has_value());
  EXPECT_EQ(h.rig().snapshot().mode, BoardMode::kPressure);
}

TEST(ClosedLoop, PressureNeverExceedsTheLimitWhateverTheGains) {
  struct Gains {
    double kp, ki, kd, rate;
    float board_kp, board_ki;
  };
  const Gains gains[] = {{0.25, 1.3, 0.0, 60.0, 0.25f, 0.5f},   // Defaults.
                         {50.0, 0.0, 0.0, 0.0, 0.25f, 0.5f},    // Bang-bang outer loop.
                         {5.0, 50.0, 1.0, 0.0, 50.0f, 100.0f},  // Everything far too high.
                         {0.0, 20.0, 0.0, 1000.0, 0.01f, 0.0f}, // Sluggish inner, wild integral.
                         {2.0, 5.0, 0.5, 0.0, 10.0f, 0.0f}};
  for (const Gains& g : gains) {
    RigOptions rig;
    rig.board.pressure_limit_pa = 35000;
    rig.board.kp_per_kpa = g.board_kp;
    rig.board.ki_per_kpa_s = g.board_ki;
    ControllerOptions c;
    c.kp_kpa_per_deg = g.kp;
    c.ki_kpa_per_deg_s = g.ki;
    c.kd_kpa_s_per_deg = g.kd;
    c.max_rate_kpa_per_s = g.rate;
    c.max_kpa = 200.0;  // Above the board's limit on purpose: the board must hold it.
    LoopHarness h(rig, c);
    // Asks for far more bending than 35 kPa can give, then an oscillating target.
    const TargetProfile profile =
        TargetProfile::Parse("step 20\nhold 2\nsine 100 80 2 2\n", "limit.txt");
    const LoopRun run = h.run(AngleTarget(profile), 4.0);
    const double peak_kpa = h.rig().snapshot().peak_pressure_kpa;
    EXPECT_LE(peak_kpa, 35.0) << "kp " << g.kp << " board kp " << g.board_kp;
    std::printf("gains kp %.2f ki %.2f kd %.2f board kp %.2f ki %.2f: peak %.2f kPa (limit 35)\n",
                g.kp, g.ki, g.kd, g.board_kp, g.board_ki, peak_kpa);
    EXPECT_GT(peak_kpa, 20.0) << "the run must drive the plant towards the limit";
    EXPECT_FALSE(run.samples.empty());
  }
  // Open loop at full inflation duty as well.
  RigOptions rig;
  rig.board.pressure_limit_pa = 35000;
  LoopHarness h(rig);
  ControlTarget full;
  full.mode = ControlMode::kDuty;
  full.duty = 1.0;
  const LoopRun run = h.run(full, 3.0);
  EXPECT_LE(h.rig().snapshot().peak_pressure_kpa, 35.0);
  EXPECT_GT(h.rig().snapshot().peak_pressure_kpa, 30.0);
  bool limited = false;
  for (const ControlSample& s : run.samples) limited |= s.board.limit();
  EXPECT_TRUE(limited);  // The guard, not the plant, stopped the pressure.
}

TEST(OpenLoop, PressureSetpointIsHeldByTheBoard) {
  LoopHarness h;
  ControlTarget target;
  target.mode = ControlMode::kPressure;
  target.pressure_kpa = 20.0;
  const LoopRun run = h.run(target, 2.0);
  EXPECT_NEAR(run.rig.back().pressure_kpa, 20.0, 0.5);
  EXPECT_NEAR(run.samples.back().board.pressure_kpa, 20.0, 0.5);
  EXPECT_TRUE(run.samples.back().board.flags & wire::kFlagClosedLoop);
}

TEST(RigServer, AHostThatFloodsAndNeverReadsCannotBlockShutdown) {
  SimulatedRig rig{RigOptions{}};
  auto server = std::make_unique<RigServer>(rig);
  const int fd = ::open(server->port().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  wire::Message ping;
  ping.type = wire::MessageType::kPing;
  ping.argc = 1;
  char buffer[wire::kLineBufferSize];
  std::string pings;
  for (int i = 1; i <= 64; ++i) {
    ping.args[0] = i;
    pings.append(buffer, wire::EncodeMessage(ping, buffer, sizeof(buffer)));
  }
  // Flood PINGs (each answered with a 30-byte ERR) and never read, until the rig has to drop
  // answers: its queue and the pty's buffers are full. Bounded: 5 MB of answers at most.
  for (int batch = 0; batch < 20000 && server->dropped_replies() == 0; ++batch) {
    size_t done = 0;
    while (done < pings.size()) {
      const ssize_t n = ::write(fd, pings.data() + done, pings.size() - done);
      if (n > 0) {
        done += static_cast<size_t>(n);
        continue;
      }
      pollfd p{fd, POLLOUT, 0};
      ::poll(&p, 1, 100);  // The rig reads what we write: room comes back.
    }
  }
  const uint64_t dropped = server->dropped_replies();
  EXPECT_GT(dropped, 0u);
  // What reached the host is whole answers, never part of a dropped one: every complete line
  // decodes (only the last may still be incomplete, its rest in the rig's queue).
  std::string received;
  ssize_t n;
  while ((n = ::read(fd, buffer, sizeof(buffer))) > 0) received.append(buffer, static_cast<size_t>(n));
  size_t start = 0, answers = 0;
  for (size_t end; (end = received.find('\n', start)) != std::string::npos; start = end + 1) {
    wire::Message m;
    EXPECT_EQ(wire::DecodeLine(received.data() + start, end - start, &m), wire::DecodeStatus::kOk)
        << received.substr(start, end - start);
    ++answers;
  }
  EXPECT_GT(answers, 100u);
  std::printf("flooded rig: %zu answers were waiting unread, %llu dropped\n", answers,
              static_cast<unsigned long long>(dropped));
  // The serving thread is not stuck in a write: shutdown returns (a hang fails by timeout).
  server.reset();
  ::close(fd);
}

TEST(Handshake, NoBoardOnTheLineIsOneClearError) {
  PseudoTerminal silent;  // Nobody answers on the master side.
  auto transport = OpenSerialTransport(silent.slave_path(), 115200);
  LinkOptions options;
  options.reply_timeout_ms = 20;
  options.retries = 1;
  BoardLink link(*transport, options);
  try {
    link.handshake();
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(silent.slave_path()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no answer"), std::string::npos) << e.what();
  }
}

TEST(Handshake, MissingPortIsOneClearError) {
  try {
    OpenSerialTransport("/dev/does-not-exist-42", 115200);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("serial port /dev/does-not-exist-42"), std::string::npos)
        << e.what();
  }
}


// Two hosts on one board: the second would reset it under the first one's loop. The port is
// locked while open; the second open is one error, and the first host goes on.
TEST(Handshake, ASecondHostOnThePortIsRefusedAndTheFirstGoesOn) {
  LoopHarness h;
  h.link().handshake();
  try {
    OpenSerialTransport(h.server().port(), 115200);
    ADD_FAILURE() << "a second host opened the port";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "serial port " + h.server().port() +
                                         ": in use by another softsight process; one host per "
                                         "board");
  }
  EXPECT_NO_THROW(h.link().heartbeat());
}

TEST(Handshake, APathThatIsNoTerminalIsOneErrorNamingWhatItIs) {
  const testing::TempDir dir;
  const std::string file = dir.file("not_a_port.txt");
  std::FILE* f = std::fopen(file.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fclose(f);
  for (const auto& [path, what] : {std::pair<std::string, std::string>{"/dev/null", "a device that is not a terminal"},
                                   {file, "a regular file, not a serial device"}}) {
    try {
      OpenSerialTransport(path, 115200);
      ADD_FAILURE() << path << " opened";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("serial port " + path + ": " + what), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace softsight
