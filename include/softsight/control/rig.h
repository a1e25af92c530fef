// The simulated rig: the board (the firmware's own logic, compiled into the library) driving a
// pneumatic actuator (PlantOptions below), served on a pseudo-terminal so the host drives it
// exactly as a board on /dev/ttyACM0.
//
// Time is simulated: advance() runs the board's inner loop at its loop_hz and the plant between
// periods. In lock-step use (tests, `softsight control --simulate`) the host advances the rig one
// camera period per frame, so runs are fast and deterministic; RigServer can also advance it with
// the wall clock (`softsight rig --pty`).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

#include "softsight/control/board_config.h"
#include "softsight/control/board_link.h"
#include "softsight/control/transport.h"

namespace softsight {

// The pneumatic actuator the rig simulates: a chamber filled by a pump and emptied by a vent,
// bending with a lag and hysteresis; these are the model's parameters.
struct PlantOptions {
  double chamber_volume_ml = 20.0;       // Chamber + tubing. Larger: slower pressure. Default 20 mL.
  double pump_flow_l_per_min = 1.0;      // Free flow of the pump (standard L/min). Default 1.0.
  double pump_stall_kpa = 120.0;         // Pressure at which the pump's flow drops to 0.
  double vent_flow_l_per_min = 2.0;      // Vent valve flow at 10 kPa, fully open. Default 2.0.
  double leak_l_per_min = 0.001;         // Leak at 10 kPa (linear). Default 0.001.
  double bend_start_kpa = 3.0;           // Below this the actuator does not bend. Default 3 kPa.
  double bend_deg_per_kpa = 6.0;         // Slope of the equilibrium bend. Default 6 deg/kPa.
  double max_bend_deg = 300.0;           // Mechanical end stop of the bend. Default 300 deg.
  double bend_lag_s = 0.15;              // Time constant of the bending response. Default 0.15 s.
  double hysteresis_deg = 3.0;           // Width of the play operator. Default 3 deg.
  // Transport delay of the tube between the valves and the chamber (where the sensor is): the
  // valves' flow reaches the chamber this much later, which makes a fast inner loop oscillate.
  // Default 0 (no tube), at most 0.5 s.
  double tube_delay_s = 0.0;

  bool Check(std::string* error) const;
};

struct RigOptions {
  BoardConfig board{};
  PlantOptions plant{};
  // Body fraction between the base and tip markers (the renderer's defaults sit at 0.1 and 0.9),
  // which relates the bend to the paper's angle (RigSnapshot::angle_deg).
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
  ValveOutputs drive{};
  BoardMode mode = BoardMode::kIdle;
  uint16_t flags = 0;  // The board's <flags> (docs/protocol.md).
  uint32_t board_rejected = 0;

  // The pressure limit guard is overriding the outputs (the limit flag).
  bool limit() const;
};

// Thread-safe: the serial thread feeds bytes while the owner advances time.
class SimulatedRig {
 public:
  // Throws InputError naming the bad option.
  explicit SimulatedRig(const RigOptions& options);
  ~SimulatedRig();

  // Advances simulated time by dt_s (rounded to whole inner-loop periods).
  void advance(double dt_s);
  // Bytes from the host, handled at the current simulated time; answers are appended to `replies`.
  void receive(std::string_view bytes, std::string* replies);
  RigSnapshot snapshot() const;
  const RigOptions& options() const { return options_; }

 private:
  struct Parts;  // The board and the plant (private to control), the noise, the clock.

  RigOptions options_;
  mutable std::mutex mutex_;
  std::unique_ptr<Parts> parts_;
};

// The link options for a RigServer of this process (`--simulate`): its board answers from a
// thread that a busy machine may hold back for longer than a real board's firmware ever takes,
// and its time is simulated (it advances on the host's commands), so a longer wait costs the run
// nothing. Each try waits at least kInProcessReplyTimeoutMs; the rest is as configured.
inline constexpr int kInProcessReplyTimeoutMs = 2000;
LinkOptions InProcessLinkOptions(LinkOptions configured);

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
  // The port disappears: both ends of the pseudo-terminal close and the host sees a hang-up. The
  // rig itself keeps its state; its watchdog vents it as time advances.
  void disconnect();
  bool connected() const { return !port_closed_; }
  // Whether the host has sent anything yet.
  bool contacted() const { return contacted_; }
  // Answers dropped because the host did not read them and the queue was full.
  uint64_t dropped_replies() const { return dropped_replies_; }
  // Answer lines queued for the host so far (a count tests and `rig` can wait on, unlike time).
  uint64_t replies() const { return replies_; }
  // After this many answer lines the server answers nothing more (0: no limit): a pulled cable at
  // a point that does not depend on timing. Call disconnect() once past_reply_limit().
  void set_reply_limit(uint64_t limit) { reply_limit_ = limit; }
  // The host asked again after the last answer allowed: it has read every answer (a hang-up
  // discards what the host has not read yet, so closing earlier would race with its reading).
  bool past_reply_limit() const { return past_reply_limit_; }

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
  std::atomic<uint64_t> replies_{0};
  std::atomic<uint64_t> reply_limit_{0};
  std::atomic<bool> past_reply_limit_{false};
  std::atomic<bool> port_closed_{false};
  std::atomic<bool> contacted_{false};
  std::atomic<bool> shutdown_{false};
  std::thread server_;
  std::thread clock_;
};

}  // namespace softsight
