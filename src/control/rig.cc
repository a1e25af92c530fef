#include "softsight/control/rig.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>

#include <random>

#include "control/board.h"
#include "control/control_options.h"
#include "control/plant.h"
#include "control/protocol.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"

namespace softsight {

bool RigOptions::Check(std::string* error) const {
  // Each field's range (board.*, plant.* included) is its row in control/control_options.cc;
  // only rules across fields here.
  if (const auto problem = CheckOptions(RigOptionsTable(), *this)) return Fail(error, *problem);
  if (board.guard_margin_pa + board.guard_release_pa >= board.pressure_limit_pa) {
    return Fail(error, "board.guard_margin_kpa: " + RoundTripNumber(board.guard_margin_pa / 1e3) +
                           " plus guard_release_kpa (" +
                           RoundTripNumber(board.guard_release_pa / 1e3) +
                           ") must stay below pressure_limit_kpa (" +
                           RoundTripNumber(board.pressure_limit_pa / 1e3) + ")");
  }
  // The board's own check (the firmware runs it too); the table's ranges are stricter.
  if (const char* problem = CheckBoardConfig(board)) return Fail(error, std::string("board: ") + problem);
  return true;
}

namespace {

const RigOptions& Checked(const RigOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw InputError("simulated rig: " + error);
  return options;
}

}  // namespace

bool RigSnapshot::limit() const { return (flags & wire::kFlagLimit) != 0; }

struct SimulatedRig::Parts {
  explicit Parts(const RigOptions& options)
      : board(options.board), plant(options.plant), rng(options.seed) {}

  uint32_t now_ms(const RigOptions& options) const {
    return static_cast<uint32_t>(tick * 1000 / options.board.loop_hz);
  }

  Board board;
  PneumaticPlant plant;
  ValveOutputs drive;
  int64_t tick = 0;
  double peak_pressure_pa = 0.0;
  std::mt19937_64 rng;
  std::normal_distribution<double> noise{0.0, 1.0};
};

SimulatedRig::SimulatedRig(const RigOptions& options)
    : options_(Checked(options)), parts_(std::make_unique<Parts>(options_)) {}

SimulatedRig::~SimulatedRig() = default;

void SimulatedRig::advance(double dt_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  Parts& p = *parts_;
  const double period_s = 1.0 / options_.board.loop_hz;
  const int64_t ticks = std::llround(dt_s / period_s);
  for (int64_t i = 0; i < ticks; ++i) {
    // The board samples the sensor and sets the valves once per period; the plant runs under
    // that drive until the next period.
    const double sensed_pa =
        p.plant.pressure_pa() + options_.sensor_noise_kpa * 1e3 * p.noise(p.rng);
    p.drive = p.board.update(p.now_ms(options_), static_cast<int32_t>(std::lround(sensed_pa)));
    p.plant.step(period_s, p.drive);
    p.peak_pressure_pa = std::max(p.peak_pressure_pa, p.plant.pressure_pa());
    ++p.tick;
  }
}

void SimulatedRig::receive(std::string_view bytes, std::string* replies) {
  std::lock_guard<std::mutex> lock(mutex_);
  Parts& p = *parts_;
  const uint32_t now = p.now_ms(options_);
  for (char c : bytes) {
    const size_t n = p.board.receive(c, now);
    if (n > 0) replies->append(p.board.reply(), n);
  }
}

RigSnapshot SimulatedRig::snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const Parts& p = *parts_;
  RigSnapshot s;
  s.time_s = static_cast<double>(p.tick) / options_.board.loop_hz;
  s.pressure_kpa = p.plant.pressure_pa() * 1e-3;
  s.peak_pressure_kpa = p.peak_pressure_pa * 1e-3;
  s.bend_deg = p.plant.bend_deg();
  s.angle_deg = PaperAngleFromBend(s.bend_deg, options_.end_marker_span);
  s.drive = p.drive;
  s.mode = p.board.mode();
  s.flags = p.board.flags();
  s.board_rejected = p.board.rejected();
  return s;
}

LinkOptions InProcessLinkOptions(LinkOptions configured) {
  configured.reply_timeout_ms = std::max(configured.reply_timeout_ms, kInProcessReplyTimeoutMs);
  return configured;
}

RigServer::RigServer(SimulatedRig& rig, bool realtime) : rig_(rig) {
  const int flags = ::fcntl(pty_.master_fd(), F_GETFL);
  ::fcntl(pty_.master_fd(), F_SETFL, flags | O_NONBLOCK);
  server_ = std::thread([this] { serve(); });
  if (realtime) clock_ = std::thread([this] { run_clock(); });
}

RigServer::~RigServer() { stop_threads(); }

void RigServer::stop_threads() {
  shutdown_ = true;
  if (server_.joinable()) server_.join();
  if (clock_.joinable()) clock_.join();
}

void RigServer::set_reply_filter(std::function<std::string(const std::string&)> filter) {
  std::lock_guard<std::mutex> lock(write_mutex_);
  filter_ = std::move(filter);
}

bool RigServer::enqueue_locked(std::string_view bytes) {
  if (pending_.size() + bytes.size() > kMaxPendingBytes) return false;
  pending_.append(bytes.data(), bytes.size());
  return true;
}

void RigServer::flush_locked() {
  while (!pending_.empty()) {
    const ssize_t w = ::write(pty_.master_fd(), pending_.data(), pending_.size());
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return;  // EAGAIN: the host is not reading; try again when the pty has room.
    pending_.erase(0, static_cast<size_t>(w));
  }
}

void RigServer::disconnect() {
  // The clock keeps nothing of the port; only the serving thread must stop before the close.
  port_closed_ = true;
  if (server_.joinable()) server_.join();
  std::lock_guard<std::mutex> lock(write_mutex_);
  flush_locked();  // Answers already queued reach the host before the line goes dead.
  pty_.close();
}

void RigServer::serve() {
  std::string replies;
  char buffer[256];
  while (!port_closed_ && !shutdown_) {
    bool waiting_to_write = false;
    {
      std::lock_guard<std::mutex> lock(write_mutex_);
      waiting_to_write = !pending_.empty();
    }
    // At the reply limit nothing more is answered: the last answers are delivered, and the next
    // request (the host read them all) marks the point where disconnect() may close the line.
    const bool at_limit = reply_limit_ != 0 && replies_ >= reply_limit_;
    // At the limit a request is only looked at once every answer is out; it is never read.
    const bool look_for_requests = !(at_limit && waiting_to_write);
    // A short timeout: shutdown and disconnect are seen within 5 ms whatever the host does.
    pollfd p{pty_.master_fd(),
             static_cast<short>((look_for_requests ? POLLIN : 0) | (waiting_to_write ? POLLOUT : 0)),
             0};
    const int ready = ::poll(&p, 1, 5);
    if (ready > 0 && (p.revents & POLLOUT) != 0) {
      std::lock_guard<std::mutex> lock(write_mutex_);
      flush_locked();
    }
    if (at_limit) {
      if (!waiting_to_write && ready > 0 && (p.revents & POLLIN) != 0) {
        past_reply_limit_ = true;
        break;
      }
      if (ready > 0 && (p.revents & POLLOUT) == 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));  // A hang-up: no busy loop.
      }
      continue;
    }
    if (ready <= 0 || (p.revents & POLLIN) == 0) {
      // POLLHUP without data: nobody has the port open (we keep the slave, so rarely). Wait.
      if (ready > 0 && (p.revents & POLLOUT) == 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      continue;
    }
    const ssize_t n = ::read(pty_.master_fd(), buffer, sizeof(buffer));
    if (n <= 0) continue;
    contacted_ = true;
    replies.clear();
    rig_.receive(std::string_view(buffer, static_cast<size_t>(n)), &replies);
    if (replies.empty()) continue;
    std::lock_guard<std::mutex> lock(write_mutex_);
    size_t start = 0;
    while (start < replies.size()) {
      const size_t end = replies.find('\n', start);
      std::string line = replies.substr(start, end == std::string::npos ? end : end - start + 1);
      start = end == std::string::npos ? replies.size() : end + 1;
      if (filter_) line = filter_(line);
      if (reply_limit_ != 0 && replies_ >= reply_limit_) break;  // The cable is pulled here.
      if (!enqueue_locked(line)) {
        ++dropped_replies_;
      } else if (!line.empty()) {
        ++replies_;
      }
    }
    flush_locked();
  }
}

void RigServer::run_clock() {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::microseconds(1000000 / rig_.options().board.loop_hz);
  auto next = Clock::now();
  const double period_s = 1.0 / rig_.options().board.loop_hz;
  while (!shutdown_) {
    next += period;
    std::this_thread::sleep_until(next);
    rig_.advance(period_s);
    // After a stall (a suspended process), catch up without a burst of thousands of periods.
    if (Clock::now() - next > std::chrono::milliseconds(100)) next = Clock::now();
  }
}

}  // namespace softsight
