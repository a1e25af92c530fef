// The host's side of the link against scripted boards, in simulated time: the link's clock is the
// fake transport's, which jumps to the next line (or to the end of a wait) instead of sleeping. So
// the deadlines are checked to the millisecond, and none of these tests waits for real.
#include "softsight/control/board_link.h"

#include <algorithm>
#include <deque>
#include <limits>
#include <stdexcept>
#include <functional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "control/board.h"
#include "softsight/control/session.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

std::string Encode(wire::MessageType type, std::initializer_list<int32_t> args) {
  wire::Message m;
  m.type = type;
  for (int32_t a : args) m.args[m.argc++] = a;
  char buffer[wire::kLineBufferSize];
  return std::string(buffer, wire::EncodeMessage(m, buffer, sizeof(buffer)));
}

wire::Message Decode(const std::string& line) {
  wire::Message m;
  EXPECT_EQ(wire::DecodeLine(line.data(), line.size() - 1, &m), wire::DecodeStatus::kOk) << line;
  return m;
}

// A board behind a Transport, in simulated milliseconds. By default the real board logic
// (board.h) answers every line after `latency_ms`; `rewrite` may change or drop (return "") each
// answer; `chatter_period_ms` > 0 adds a line of debug text that often, for ever.
class FakeBoard : public Transport {
 public:
  FakeBoard() : board_(BoardConfig{}) {}

  void write_line(std::string_view line_in) override {
    written.emplace_back(line_in);
    std::string line(line_in);
    // A firmware from before $GAIN rejects the word unanswered, as it rejects a corrupted line:
    // the board below gets a line whose CRC does not match.
    if (!knows_gain && line.rfind("$GAIN ", 0) == 0) line[4] = 'X';
    for (char c : line) {
      const size_t n = board_.receive(c, static_cast<uint32_t>(now));
      if (n == 0) continue;
      std::string answer(board_.reply(), n);
      if (rewrite) answer = rewrite(answer);
      if (!answer.empty()) queue_.push_back({now + latency_ms, answer});
    }
  }

  std::optional<std::string> read_line(int timeout_ms) override {
    EXPECT_GT(timeout_ms, 0);
    EXPECT_LE(timeout_ms, BoardLink::kStopPollMs);  // Short waits: a stop request is seen soon.
    ++reads;
    const int64_t until = now + timeout_ms;
    int64_t next_chatter = -1;
    if (chatter_period_ms > 0 && now < chatter_until_ms) {
      next_chatter = (now / chatter_period_ms + 1) * chatter_period_ms;
    }
    if (!queue_.empty() && queue_.front().first <= until &&
        (next_chatter < 0 || queue_.front().first <= next_chatter)) {
      now = std::max(now, queue_.front().first);
      std::string line = queue_.front().second;
      queue_.pop_front();
      line.pop_back();  // Transports return lines without '\n'.
      return line;
    }
    if (next_chatter >= 0 && next_chatter <= until) {
      now = next_chatter;
      // Debug text and a stale answer, as a board printing its state at 20 Hz would.
      std::string stale = Encode(wire::MessageType::kState, {0, 0, 1000, 0, 0, 33, 0});
      stale.pop_back();
      return (now / chatter_period_ms) % 2 == 0 ? std::string("debug: p=12.3 kPa") : stale;
    }
    now = until;
    return std::nullopt;
  }

  const std::string& name() const override { return name_; }

  // The command words the host sent, in order ("HELLO", "SETP", ...).
  std::vector<std::string> words() const {
    std::vector<std::string> out;
    for (const std::string& line : written) {
      wire::Message m;
      if (wire::DecodeLine(line.data(), line.size() - 1, &m) == wire::DecodeStatus::kOk) {
        out.push_back(wire::CommandWord(m.type));
      }
    }
    return out;
  }

  int64_t now = 0;
  int64_t latency_ms = 2;
  bool knows_gain = true;
  int64_t chatter_period_ms = 0;
  int64_t chatter_until_ms = 60000;  // Bounded, so that a link that would wait for ever fails.
  std::function<std::string(const std::string&)> rewrite;
  std::vector<std::string> written;
  int reads = 0;

 private:
  Board board_;
  std::deque<std::pair<int64_t, std::string>> queue_;
  std::string name_ = "serial port /dev/fake0";
};

LinkEnvironment SimulatedClock(FakeBoard& board, std::function<bool()> stop = {}) {
  LinkEnvironment env;
  env.now_ms = [&board] { return board.now; };
  env.stop_requested = std::move(stop);
  return env;
}

TEST(BoardLink, AnswersArriveAndAreDecoded) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  const BoardInfo info = link.handshake();
  EXPECT_EQ(info.protocol_version, wire::kProtocolVersion);
  EXPECT_DOUBLE_EQ(info.pressure_limit_kpa, 50.0);
  const BoardState state = link.set_pressure_kpa(20.0);
  EXPECT_DOUBLE_EQ(state.setpoint_kpa, 20.0);
  EXPECT_EQ(fake.now, 4);  // Two answers, 2 ms each.
}

TEST(BoardLink, AChatteringBoardCannotExtendTheReplyDeadline) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  link.handshake();
  fake.chatter_period_ms = 50;  // 20 Hz of text, never the answer.
  fake.rewrite = [](const std::string&) { return std::string(); };
  const int64_t sent_ms = fake.now;
  try {
    link.heartbeat();
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("serial port /dev/fake0: no usable answer to PING"),
              std::string::npos)
        << e.what();
  }
  // Three tries, each ending exactly at its 100 ms deadline.
  EXPECT_EQ(fake.now - sent_ms, 300);
  EXPECT_EQ(link.stats().resends, 2u);
  EXPECT_GE(link.stats().rejected_lines + link.stats().stale_answers, 5u);

  // The handshake too.
  BoardLink again(fake, LinkOptions{}, SimulatedClock(fake));
  const int64_t hello_ms = fake.now;
  EXPECT_THROW(again.handshake(), InputError);
  EXPECT_EQ(fake.now - hello_ms, 300);
}

TEST(BoardLink, ALateAnswerWithinTheDeadlineIsTaken) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  link.handshake();
  fake.chatter_period_ms = 30;
  fake.latency_ms = 95;
  EXPECT_NO_THROW(link.read_state());
  EXPECT_EQ(link.stats().resends, 0u);
  // Just late, without retries (a retry would take the late answer: it has the same seq).
  LinkOptions no_retry;
  no_retry.retries = 0;
  BoardLink impatient(fake, no_retry, SimulatedClock(fake));
  fake.latency_ms = 101;
  const int64_t sent_ms = fake.now;
  EXPECT_THROW(impatient.read_state(), InputError);
  EXPECT_EQ(fake.now - sent_ms, 100);
}

TEST(BoardLink, AStopRequestEndsTheWaitButNotTheFinalStop) {
  FakeBoard fake;
  int64_t stop_at_ms = 1 << 30;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake, [&] { return fake.now >= stop_at_ms; }));
  link.handshake();
  fake.chatter_period_ms = 10;
  fake.rewrite = [](const std::string&) { return std::string(); };  // Silent but chattering.
  const int64_t sent_ms = fake.now;
  stop_at_ms = sent_ms + 40;  // Ctrl-C 40 ms into the wait.
  EXPECT_THROW(link.heartbeat(), StopRequested);
  EXPECT_LE(fake.now - sent_ms, 40 + BoardLink::kStopPollMs);
  // STOP goes out and is waited for (bounded) whatever the flag says.
  fake.rewrite = nullptr;
  fake.written.clear();
  EXPECT_NO_THROW(link.stop());
  EXPECT_EQ(fake.words(), std::vector<std::string>{"STOP"});
  // And a stop request before the handshake ends it too.
  BoardLink early(fake, LinkOptions{}, SimulatedClock(fake, [] { return true; }));
  EXPECT_THROW(early.handshake(), StopRequested);
}

TEST(BoardLink, RefusesANonsensicalLimitAtTheHandshake) {
  for (int32_t limit_pa : {0, -50000, 1000001, 2147483647}) {
    FakeBoard fake;
    fake.rewrite = [limit_pa](const std::string& answer) {
      wire::Message m = Decode(answer);
      if (m.type != wire::MessageType::kHelloReply) return answer;
      return Encode(wire::MessageType::kHelloReply, {m.args[0], limit_pa, m.args[2], m.args[3]});
    };
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    try {
      link.handshake();
      ADD_FAILURE() << "limit " << limit_pa << " Pa accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("serial port /dev/fake0: the board's handshake reports a nonsensical "
                          "pressure limit"),
                std::string::npos)
          << what;
      EXPECT_EQ(what.find('\n'), std::string::npos);
    }
  }
}

TEST(BoardLink, ABoardErrIsOneErrorNamingTheCommand) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  link.handshake();
  try {
    link.set_pressure_kpa(60.0);  // Above the board's 50 kPa: ERR 3.
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("refused SETP 60000: argument out of range"),
              std::string::npos)
        << e.what();
  }
}

TEST(BoardLink, InnerLoopGainsGoOutAsGainAndAFirmwareWithoutItIsOneClearError) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  link.handshake();
  link.set_inner_loop_gains(0.05, 0.12, 0.333);
  const wire::Message sent = Decode(fake.written.back());
  ASSERT_EQ(sent.type, wire::MessageType::kSetGains);
  EXPECT_EQ(sent.args[1], 50);
  EXPECT_EQ(sent.args[2], 120);
  EXPECT_EQ(sent.args[3], 333);

  fake.knows_gain = false;
  const int64_t before_ms = fake.now;
  try {
    link.set_inner_loop_gains(0.05, 0.12, 1.0);
    FAIL() << "an old firmware took GAIN";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::StartsWith("serial port /dev/fake0: the board does not know "
                                                "the GAIN command (no answer to 3 tries"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("update it (firmware/README.md), or remove "
                                               "control.inner_loop"));
  }
  // Three tries of GAIN, then a READ that the board answered.
  const std::vector<std::string> words = fake.words();
  EXPECT_EQ(std::vector<std::string>(words.end() - 4, words.end()),
            (std::vector<std::string>{"GAIN", "GAIN", "GAIN", "READ"}));
  EXPECT_EQ(fake.now - before_ms, 3 * 100 + 2);
}

// ---- The session: STOP on every way out, the host's pressure clamp, the board's limit. ----

ControlTarget Pressure(double kpa) {
  ControlTarget t;
  t.mode = ControlMode::kPressure;
  t.pressure_kpa = kpa;
  return t;
}

TEST(ControlSession, ClampsThePressureTargetToMaxKpaAndSaysFromWhat) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  ControllerOptions options;
  options.max_kpa = 45.0;
  ControlSession session(options, link, Pressure(49.0));
  session.start();
  ASSERT_TRUE(session.pressure_clamped_from());
  EXPECT_DOUBLE_EQ(*session.pressure_clamped_from(), 49.0);
  const ControlSample sample = session.step(0.0, std::nullopt);
  EXPECT_DOUBLE_EQ(*sample.setpoint_kpa, 45.0);
  EXPECT_EQ(Decode(fake.written.back()).args[1], 45000);  // What went on the wire.
  session.step(0.1, std::nullopt);
  EXPECT_EQ(Decode(fake.written.back()).args[1], 45000);

  // Within the limit: unchanged, nothing to say.
  FakeBoard fake2;
  BoardLink link2(fake2, LinkOptions{}, SimulatedClock(fake2));
  ControlSession within(options, link2, Pressure(30.0));
  within.start();
  EXPECT_FALSE(within.pressure_clamped_from());
  within.step(0.0, std::nullopt);
  EXPECT_EQ(Decode(fake2.written.back()).args[1], 30000);
}

TEST(ControlSession, ABoardReportingMoreThanItsLimitIsAFaultThatVents) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  ControlSession session(ControllerOptions{}, link, Pressure(20.0));
  session.start();
  session.step(0.0, std::nullopt);
  // The board now claims 80 kPa (its limit is 50).
  fake.rewrite = [](const std::string& answer) {
    wire::Message m = Decode(answer);
    if (m.type != wire::MessageType::kState) return answer;
    return Encode(wire::MessageType::kState,
                  {m.args[0], m.args[1], 80000, m.args[3], m.args[4], m.args[5], m.args[6]});
  };
  try {
    session.step(0.1, std::nullopt);
    FAIL() << "expected a fault";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reports 80 kPa, above its own limit of 50 kPa"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(fake.words().back(), "STOP");
}

TEST(ControlSession, TheInnerLoopGainsGoRightAfterTheHandshakeAndAnOldFirmwareStopsTheRun) {
  InnerLoopGains gains;
  gains.kp_per_kpa = 0.05;
  gains.ki_per_kpa_s = 0.12;
  {
    FakeBoard fake;
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    ControlSession session(ControllerOptions{}, link, Pressure(20.0));
    session.set_inner_loop_gains(gains);
    session.start();
    session.step(0.0, std::nullopt);
    session.stop();
    EXPECT_EQ(fake.words(), (std::vector<std::string>{"HELLO", "GAIN", "SETP", "STOP"}));
  }
  {
    FakeBoard fake;
    fake.knows_gain = false;
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    {
      ControlSession session(ControllerOptions{}, link, Pressure(20.0));
      session.set_inner_loop_gains(gains);
      EXPECT_THROW(session.start(), InputError);
    }
    EXPECT_EQ(fake.words().back(), "STOP") << "vented on the way out";
    for (const std::string& word : fake.words()) EXPECT_NE(word, "SETP");
  }
  // A gain out of range: refused before anything is sent.
  {
    FakeBoard fake;
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    ControlSession session(ControllerOptions{}, link, Pressure(20.0));
    InnerLoopGains bad = gains;
    bad.vent_scale = 0.0;
    try {
      session.set_inner_loop_gains(bad);
      FAIL() << "a vent scale of 0 taken";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), ::testing::StartsWith("control.inner_loop.vent_scale: "));
    }
    EXPECT_TRUE(fake.written.empty());
  }
}

TEST(ControlSession, SendsStopOnEveryWayOut) {
  // A board ERR mid-run.
  {
    FakeBoard fake;
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    {
      ControlSession session(ControllerOptions{}, link, Pressure(20.0));
      session.start();
      session.step(0.0, std::nullopt);
      fake.rewrite = [](const std::string& answer) {
        const wire::Message m = Decode(answer);
        return m.type == wire::MessageType::kState && m.args[3] != 0
                   ? Encode(wire::MessageType::kError, {m.args[0], wire::kErrRange})
                   : answer;
      };
      EXPECT_THROW(session.step(0.1, std::nullopt), InputError);
    }
    EXPECT_EQ(fake.words().back(), "STOP");
  }
  // Any other exception between frames (a tracker's, a full disk's).
  {
    FakeBoard fake;
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    try {
      ControlSession session(ControllerOptions{}, link, Pressure(20.0));
      session.start();
      session.step(0.0, std::nullopt);
      throw std::runtime_error("something else failed");
    } catch (const std::runtime_error&) {
    }
    EXPECT_EQ(fake.words(), (std::vector<std::string>{"HELLO", "SETP", "STOP"}));
  }
  // A silent board: the STOP is sent (and waited for, bounded) after the link's error.
  {
    FakeBoard fake;
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    int64_t failed_ms = 0;
    {
      ControlSession session(ControllerOptions{}, link, Pressure(20.0));
      session.start();
      fake.rewrite = [](const std::string&) { return std::string(); };
      const int64_t sent_ms = fake.now;
      EXPECT_THROW(session.step(0.0, std::nullopt), InputError);
      EXPECT_EQ(fake.now - sent_ms, 300);
      failed_ms = fake.now;
    }
    EXPECT_EQ(fake.words().back(), "STOP");
    // Re-sent until its budget is spent, then the watchdog's turn: the exit waits no longer.
    EXPECT_LE(fake.now - failed_ms, kMaxStopMs);
  }
  // A normal end: one STOP, not two.
  {
    FakeBoard fake;
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    {
      ControlSession session(ControllerOptions{}, link, Pressure(20.0));
      session.start();
      session.step(0.0, std::nullopt);
      session.stop();
    }
    EXPECT_EQ(fake.words(), (std::vector<std::string>{"HELLO", "SETP", "STOP"}));
  }
}

TEST(ControlSession, RefusesNonFiniteTargets) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (double v : {nan, inf, -inf, -2.0, 1e9}) {
    EXPECT_THROW(ControlSession(ControllerOptions{}, link, Pressure(v)), InputError) << v;
    ControlTarget duty;
    duty.mode = ControlMode::kDuty;
    duty.duty = v;
    EXPECT_THROW(ControlSession(ControllerOptions{}, link, duty), InputError) << v;
  }
  EXPECT_TRUE(fake.written.empty());  // Nothing was sent.
}


// ---- Second hostile round: what the board says is believed only when it is physically possible;
// the host never commands more than its own limits; a stop ends in bounded time. ----

// Rewrites every $STATE answer's argument `index` to `value` (the other answers pass through).
std::function<std::string(const std::string&)> StateArgument(int index, int32_t value) {
  return [index, value](const std::string& answer) {
    wire::Message m = Decode(answer);
    if (m.type != wire::MessageType::kState) return answer;
    m.args[index] = value;
    return Encode(wire::MessageType::kState,
                  {m.args[0], m.args[1], m.args[2], m.args[3], m.args[4], m.args[5], m.args[6]});
  };
}

TEST(BoardLink, PhysicallyImpossibleAnswersAreRejectedNeverUsed) {
  struct Case {
    int index;
    int32_t value;
    const char* why;
  };
  const Case cases[] = {
      {2, -1000000000, "below vacuum"},           // -1,000,000 kPa.
      {2, 2000001000, "above any sensor's range"},  // 2000.001 kPa.
      {3, 1000000000, "echoed setpoint outside"},  // 1e6 kPa.
      {4, 999999, "a duty outside -1..1"},
      {5, -1, "undefined flag bits"},
      {5, 255, "undefined flag bits"},
      {6, -5, "negative count of rejected lines"},
      {1, -20, "negative board clock"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.why);
    FakeBoard fake;
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    link.handshake();
    fake.rewrite = StateArgument(c.index, c.value);
    try {
      link.set_pressure_kpa(10.0);
      ADD_FAILURE() << "an impossible answer was taken";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("serial port /dev/fake0: no usable answer to SETP: 3 lines from the "
                          "board rejected"),
                std::string::npos)
          << what;
      EXPECT_NE(what.find(c.why), std::string::npos) << what;
    }
  }
  // The edges themselves are possible: full vacuum and a duty of exactly -1.
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  link.handshake();
  fake.rewrite = StateArgument(2, -101325);
  EXPECT_DOUBLE_EQ(link.set_pressure_kpa(0.0).pressure_kpa, -101.325);
  fake.rewrite = StateArgument(4, -1000);
  EXPECT_DOUBLE_EQ(link.set_duty(-1.0).duty, -1.0);
}

TEST(BoardLink, AStopEndsWithinItsBoundHoweverLongTheTimeoutsAre) {
  FakeBoard fake;
  LinkOptions options;
  options.reply_timeout_ms = 10000;  // Both the largest allowed: 110 s for an ordinary command.
  options.retries = 10;
  BoardLink link(fake, options, SimulatedClock(fake));
  link.handshake();
  fake.rewrite = [](const std::string&) { return std::string(); };  // The board falls silent.
  const int64_t sent_ms = fake.now;
  try {
    link.stop();
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no answer to STOP after 1500 ms (the board's watchdog "
                                         "vents)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_LE(fake.now - sent_ms, kMaxStopMs);
  EXPECT_GE(fake.now - sent_ms, kMaxStopMs - BoardLink::kStopPollMs);
}

TEST(BoardLink, AStopIsResentUntilItsBudgetIsSpentNotOnlyRetriesTimes) {
  // A loaded machine can miss three 100 ms deadlines in a row; STOP, the command that vents,
  // keeps trying for kMaxStopMs. The board here answers only the sixth copy it gets.
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));  // 100 ms per try, 2 retries.
  link.handshake();
  int stops_seen = 0;
  fake.rewrite = [&stops_seen](const std::string& reply) {
    return ++stops_seen < 6 ? std::string() : reply;
  };
  const int64_t sent_ms = fake.now;
  link.stop();  // Answered: no error.
  EXPECT_EQ(stops_seen, 6);
  EXPECT_EQ(link.stats().resends, 5u);
  const std::vector<std::string> words = fake.words();
  EXPECT_EQ(std::count(words.begin(), words.end(), "STOP"), 6);
  EXPECT_GE(fake.now - sent_ms, 5 * LinkOptions{}.reply_timeout_ms);
  EXPECT_LT(fake.now - sent_ms, kMaxStopMs);
}

TEST(ControlSession, AMinKpaAtOrAboveTheBoardLimitSendsNoSetpointOnlyStop) {
  for (double min_kpa : {50.0, 60.0}) {
    FakeBoard fake;
    BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
    ControllerOptions options;
    options.min_kpa = min_kpa;
    options.max_kpa = 70.0;
    try {
      ControlSession session(options, link, ControlTarget{});
      session.start();
      session.step(0.0, 150.0);
      ADD_FAILURE() << "min_kpa " << min_kpa << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("is not below the board's pressure limit of 50 kPa"),
                std::string::npos)
          << e.what();
    }
    const std::vector<std::string> words = fake.words();
    EXPECT_EQ(std::count(words.begin(), words.end(), "SETP"), 0);
    ASSERT_FALSE(words.empty());
    EXPECT_EQ(words.back(), "STOP");
  }
}

TEST(ControlSession, TheCsvSetpointIsTheClampedOneOnTheWire) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  ControllerOptions options;
  options.min_kpa = 40.0;
  options.max_kpa = 45.0;
  ControlSession session(options, link, ControlTarget{});  // Target straight: the PI asks ~0.
  session.start();
  for (int i = 0; i < 5; ++i) {
    const ControlSample sample = session.step(0.1 * i, 180.0);
    if (!sample.setpoint_kpa) continue;  // A vent has no setpoint.
    const wire::Message sent = Decode(fake.written.back());
    EXPECT_DOUBLE_EQ(*sample.setpoint_kpa, sent.args[1] * 1e-3) << "frame " << i;
    EXPECT_GE(*sample.setpoint_kpa, 40.0);
    EXPECT_LE(*sample.setpoint_kpa, 45.0);
  }
}

TEST(ControlSession, OpenLoopDutyClosesTheValvesBeforeMaxKpa) {
  FakeBoard fake;
  BoardLink link(fake, LinkOptions{}, SimulatedClock(fake));
  // The chamber rises 4 kPa per frame while the valve is open; it never rises when closed.
  int32_t pressure_pa = 0;
  fake.rewrite = [&pressure_pa, &fake](const std::string& answer) {
    wire::Message m = Decode(answer);
    if (m.type != wire::MessageType::kState) return answer;
    const wire::Message command = Decode(fake.written.back());
    if (command.type == wire::MessageType::kSetDuty && command.args[1] > 0) pressure_pa += 4000;
    return Encode(wire::MessageType::kState,
                  {m.args[0], m.args[1], pressure_pa, m.args[3], m.args[4], m.args[5], m.args[6]});
  };
  ControllerOptions options;
  options.max_kpa = 30.0;
  ControlTarget target;
  target.mode = ControlMode::kDuty;
  target.duty = 1.0;
  ControlSession session(options, link, target);
  session.start();
  double highest_kpa = 0.0;
  for (int i = 0; i < 30; ++i) {
    highest_kpa = std::max(highest_kpa, session.step(0.05 * i, std::nullopt).board.pressure_kpa);
  }
  EXPECT_LE(highest_kpa, 30.0);
  EXPECT_GE(highest_kpa, 26.0);  // It did inflate up to the limit, not stop short.
  EXPECT_GT(session.duty_held_at_limit(), 20);
  // Venting is always allowed.
  FakeBoard fake2;
  BoardLink link2(fake2, LinkOptions{}, SimulatedClock(fake2));
  target.duty = -1.0;
  ControlSession venting(options, link2, target);
  venting.start();
  venting.step(0.0, std::nullopt);
  EXPECT_EQ(Decode(fake2.written.back()).args[1], -1000);
  EXPECT_EQ(venting.duty_held_at_limit(), 0);
}

}  // namespace
}  // namespace softsight
