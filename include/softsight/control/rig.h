// The simulated rig: the board (board.h, the firmware's own logic) driving a pneumatic actuator
// (plant.h), served on a pseudo-terminal so the host drives it exactly as a board on /dev/ttyACM0.
//
// Time is simulated: advance() runs the board's inner loop at its loop_hz and the plant between
// periods. In lock-step use (tests, `softsight control --simulate`) the host advances the rig one
// camera period per frame, so runs are fast and deterministic; RigServer can also advance it with
// the wall clock (`softsight rig --pty`).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <random>
#include <string>
#include <string_view>
#include <thread>

#include "softsight/control/board.h"
#include "softsight/control/plant.h"
#include "softsight/control/transport.h"

namespace softsight {

struct RigOptions {
  BoardConfig board;
  PlantOptions plant;
  // Body fraction between the base and tip markers (the renderer's defaults sit at 0.1 and 0.9),
  // which relates the bend to the paper's angle (PaperAngleFromBend).
  double end_marker_span = 0.8;
  double sensor_noise_kpa = 0.05;  // Pressure sensor noise, standard deviation. Default 0.05 kPa.
  uint64_t seed = 1;               // Sensor noise.

  bool Check(std::string* error) const;
};

struct RigSnapshot {
  double time_s = 0.0;
  double pressure_kpa = 0.0;       // True chamber pressure.
  double peak_pressure_kpa = 0.0;  // Highest true pressure since the start.
  double bend_deg = 0.0;           // Total turning of the centre line (the renderer's bend_deg).
  double angle_deg = 180.0;        // The paper's angle at the middle marker.
  ValveOutputs drive;
  Board::Mode mode = Board::Mode::kIdle;
  uint16_t flags = 0;
  uint32_t board_rejected = 0;
};

// Thread-safe: the serial thread feeds bytes while the owner advances time.
class SimulatedRig {
 public:
  // Throws InputError naming the bad option.
  explicit SimulatedRig(const RigOptions& options);

  // Advances simulated time by dt_s (rounded to whole inner-loop periods).
  void advance(double dt_s);
  // Bytes from the host, handled at the current simulated time; answers are appended to `replies`.
  void receive(std::string_view bytes, std::string* replies);
  RigSnapshot snapshot() const;
  const RigOptions& options() const { return options_; }

 private:
  uint32_t now_ms_locked() const;

  RigOptions options_;
  mutable std::mutex mutex_;
  Board board_;
  PneumaticPlant plant_;
  ValveOutputs drive_;
  int64_t tick_ = 0;
  double peak_pressure_pa_ = 0.0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
};

// Serves a SimulatedRig on a new pseudo-terminal. Writes to the pty never block: answers wait in
// a bounded queue (kMaxPendingBytes) while the host is not reading, and when that is full new
// answers are dropped whole and counted, as a board's full serial buffer would lose them. So a
// host that floods commands and never reads cannot stall the rig or its shutdown.
class RigServer {
 public:
  // Opens the pseudo-terminal and starts answering. With `realtime`, a second thread advances the
  // rig with the wall clock. Throws InputError when no pseudo-terminal is available.
  explicit RigServer(SimulatedRig& rig, bool realtime = false);
  ~RigServer();

  // About a hundred $STATE answers: far more than a host that reads ever leaves unread.
  static constexpr size_t kMaxPendingBytes = 4096;

  // The device path for the host (/dev/pts/N).
  const std::string& port() const { return pty_.slave_path(); }
  // Rewrites each answer line (with its '\n') before it is sent; "" drops it. For tests.
  void set_reply_filter(std::function<std::string(const std::string&)> filter);
  // Sends raw bytes to the host (tests: garbage on the line).
  void inject(std::string_view bytes);
  // The port disappears: both ends of the pseudo-terminal close and the host sees a hang-up. The
  // rig itself keeps its state; its watchdog vents it as time advances.
  void disconnect();
  bool connected() const { return !port_closed_; }
  // Whether the host has sent anything yet.
  bool contacted() const { return contacted_; }
  // Answers dropped because the host did not read them and the queue was full.
  uint64_t dropped_replies() const { return dropped_replies_; }

 private:
  void serve();
  // Queues `bytes` (whole, or not at all when the queue is full); caller holds write_mutex_.
  bool enqueue_locked(std::string_view bytes);
  // Writes what the pty takes now, without blocking; caller holds write_mutex_.
  void flush_locked();
  void run_clock();
  void stop_threads();

  SimulatedRig& rig_;
  PseudoTerminal pty_;
  std::mutex write_mutex_;
  std::function<std::string(const std::string&)> filter_;
  std::string pending_;  // Bytes for the host not yet taken by the pty (write_mutex_).
  std::atomic<uint64_t> dropped_replies_{0};
  std::atomic<bool> port_closed_{false};
  std::atomic<bool> contacted_{false};
  std::atomic<bool> shutdown_{false};
  std::thread server_;
  std::thread clock_;
};

}  // namespace softsight
