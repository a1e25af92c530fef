// The frame sources and sinks of `softsight control` (RunControl wires them): the rig's frame
// file, the simulated rig rendered in lock-step, the sink that runs the controller on each
// frame's angle, and the simulated board's clock driven by the frames. Private to the command.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "app/control_command.h"
#include "app/target_feed.h"
#include "softsight/control/board_link.h"
#include "softsight/control/rig.h"
#include "pipeline/control_sample_columns.h"
#include "softsight/core/error.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/sink.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/sim/scene.h"

namespace softsight::control_parts {

// Frames of a rig running in another process (`softsight rig --pty --frames FILE`), which
// rewrites FILE atomically (write + rename) at its frame rate: read it at `fps`, wall clock.
class RigFileSource : public FrameSource {
 public:
  RigFileSource(std::string file, double fps) : file_(std::move(file)), fps_(fps) {}
  bool read(Frame& frame) override {
    const auto period = std::chrono::duration<double>(1.0 / fps_);
    if (index_ == 0) start_ = std::chrono::steady_clock::now();
    std::this_thread::sleep_until(start_ + std::chrono::duration_cast<
                                               std::chrono::steady_clock::duration>(period * index_));
    ReadBytes();
    const cv::Mat image = cv::imdecode(bytes_, cv::IMREAD_COLOR);
    if (image.empty()) {
      throw InputError(file_ + ": cannot read the rig's frame at frame " + std::to_string(index_) +
                       " (is `softsight rig --frames " + file_ + "` running?)");
    }
    // The rig rewrites its file every frame with a new picture (its camera has sensor noise): the
    // very bytes of the last read are a relay that stalled, not a new measurement.
    frame.repeated = index_ > 0 && bytes_ == last_bytes_;
    last_bytes_.swap(bytes_);
    frame.image = image;
    frame.index = index_;
    frame.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    ++index_;
    return true;
  }
  std::string description() const override { return "rig frames " + file_; }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override { return fps_; }
  bool is_live() const override { return true; }

 private:
  // The file's bytes into bytes_. Opened without blocking and checked to be a regular file
  // before reading: a pipe (or a file swapped for one mid-run) would block open() and read()
  // deaf to Ctrl-C, with the board left to its watchdog.
  void ReadBytes() {
    const int fd = ::open(file_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
      throw InputError(file_ + ": cannot read the rig's frame at frame " + std::to_string(index_) +
                       " (" + std::strerror(errno) + "; is `softsight rig --frames " + file_ +
                       "` running?)");
    }
    struct stat info {};
    if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
      ::close(fd);
      throw InputError(file_ + ": not a regular file (a pipe or a device?) at frame " +
                       std::to_string(index_) + ": --rig-frames reads the picture file that "
                       "`softsight rig --frames` rewrites");
    }
    bytes_.resize(static_cast<size_t>(info.st_size));
    size_t got = 0;
    while (got < bytes_.size()) {
      const ssize_t n = ::read(fd, bytes_.data() + got, bytes_.size() - got);
      if (n > 0) {
        got += static_cast<size_t>(n);
      } else if (n == 0 || errno != EINTR) {
        break;
      }
    }
    ::close(fd);
    bytes_.resize(got);
  }

  std::string file_;
  double fps_;
  int64_t index_ = 0;
  std::chrono::steady_clock::time_point start_;
  std::vector<uchar> bytes_, last_bytes_;
};

// The simulated rig's camera: each frame renders the rig's current bend, then the rig advances by
// one frame period, in lock-step with the loop (simulated time: as fast as it can). Ends after
// `duration_s`.
class SimulatedRigSource : public FrameSource {
 public:
  SimulatedRigSource(SimulatedRig& rig, SyntheticScene& scene, double fps, double duration_s)
      : rig_(rig), scene_(scene), fps_(fps),
        frames_(static_cast<int64_t>(std::floor(duration_s * fps + 1e-9)) + 1) {}
  bool read(Frame& frame) override {
    if (index_ >= frames_) return false;
    if (index_ > 0) rig_.advance(1.0 / fps_);
    truth_ = rig_.snapshot();
    const double t = static_cast<double>(index_) / fps_;
    scene_.render_at_bend(truth_->bend_deg, t, static_cast<int>(index_), frame.image);
    frame.index = index_++;
    frame.time_s = t;
    return true;
  }
  std::string description() const override { return "simulated rig"; }
  std::optional<int64_t> frame_count() const override { return frames_; }
  std::optional<double> fps() const override { return fps_; }
  // The rig's state when the last frame was rendered.
  const std::optional<RigSnapshot>& truth() const { return truth_; }

 private:
  SimulatedRig& rig_;
  SyntheticScene& scene_;
  double fps_;
  int64_t frames_;
  int64_t index_ = 0;
  std::optional<RigSnapshot> truth_;
};

// The controller as a sink: one step per frame with the measured angle. Its columns (by name)
// read the step of the frame being written, so it must come before the CSV sink.
class ControlSink : public FrameSink {
 public:
  // With `stop_at_duration`, done() turns true once `duration_s` of frame time has passed (a
  // camera or the rig's frame file, which have no end of their own).
  ControlSink(ControlSession& session, const BoardLink& link, double duration_s,
              bool stop_at_duration)
      : session_(session), link_(link), duration_s_(duration_s),
        stop_at_duration_(stop_at_duration) {}

  // From then on each frame runs this experiment (open loop) instead of the closed loop, until
  // it is done.
  void identify(IdentificationExperiment* experiment) { experiment_ = experiment; }
  // From then on each frame's target comes from `source`, checked by `feed` (control
  // --target-from): the loop follows it, and vents while the feed says the source is silent.
  void follow(TargetSubscriber* source, TargetFeed* feed) {
    source_ = source;
    feed_ = feed;
  }

  // One frame tracked by one camera: its angle is the measurement.
  void consume(const Frame& frame, const FrameResult& result) override {
    if (frame.repeated) ++stale_frames_;
    step(frame, result.measurement.angle_deg);
  }
  // The run's summary as it ended (also when a wait for the board was stopped or failed): the
  // controller's summary holds it.
  void end(const RunSummary& summary) override { ended_run_ = summary; }
  // Frames the camera repeated (Frame::repeated): no new measurement, the loop held, then vented.
  int64_t stale_frames() const { return stale_frames_; }

  // One step of the loop on `frame`'s time with the angle measured for it, wherever it came from
  // (one camera's tracking, two cameras' 3D angle); absent: no measurement this frame (the
  // controller holds, then vents: ControllerOptions::hold_s).
  void step(const Frame& frame, std::optional<double> measured_deg) {
    if (experiment_ != nullptr) {
      sample_ = StepIdentification(*experiment_, session_, frame.time_s, measured_deg);
      if (experiment_->done()) done_ = true;
    } else if (feed_ != nullptr) {
      if (const std::optional<double> target_deg = feed_->at(frame.time_s, source_->poll())) {
        session_.set_angle_target(*target_deg);
        sample_ = session_.step(frame.time_s, measured_deg);
      } else {
        sample_ = session_.vent(frame.time_s, measured_deg);
      }
    } else {
      sample_ = session_.step(frame.time_s, measured_deg);
    }
    // A command written for this frame: its latency from the frame's capture (absent when this
    // step sent none).
    const auto sent = link_.last_sent();
    latency_command_ms_ =
        sent >= frame.captured && frame.captured != std::chrono::steady_clock::time_point{}
            ? std::optional<double>(
                  std::chrono::duration<double, std::milli>(sent - frame.captured).count())
            : std::nullopt;
    if (latency_command_ms_) command_latencies_ms_.push_back(*latency_command_ms_);
    summary_.duration_s = sample_.time_s;
    summary_.max_pressure_kpa = std::max(summary_.max_pressure_kpa, sample_.board.pressure_kpa);
    summary_.board_rejected = sample_.board.board_rejected;
    if (sample_.measured_deg && sample_.target_deg) {
      const double e = *sample_.measured_deg - *sample_.target_deg;
      sum_sq_ += e * e;
      ++errors_;
      summary_.final_error_deg = e;
    }
    if (sample_.target_deg) collect_step_point(*sample_.target_deg);
    // Closed loop asking for max_kpa, frame after frame: a target the actuator may not reach.
    const bool at_limit = experiment_ == nullptr && sample_.target_deg && sample_.setpoint_kpa &&
                          *sample_.setpoint_kpa >= session_.controller().options().max_kpa - 1e-9;
    if (!at_limit) {
      at_limit_since_s_.reset();
    } else {
      if (!at_limit_since_s_) at_limit_since_s_ = sample_.time_s;
      longest_at_limit_s_ = std::max(longest_at_limit_s_, sample_.time_s - *at_limit_since_s_);
    }
    if (stop_at_duration_ && sample_.time_s >= duration_s_) done_ = true;
  }

  bool done() const { return done_; }
  // The longest stretch of frame time the closed loop spent asking for max_kpa.
  double longest_at_output_limit_s() const { return longest_at_limit_s_; }

  // The controller's CSV columns: target_deg, setpoint_kpa, board_pressure_kpa,
  // board_setpoint_kpa, duty, board_flags, control_action, link_rejected, board_rejected; for
  // rows of one camera's results (FrameResult) or two cameras' (StereoFrameResult).
  template <typename Row = FrameResult>
  std::vector<BasicCsvColumn<Row>> columns() const {
    std::vector<BasicCsvColumn<Row>> columns = ControlSampleColumns<Row>(&sample_);
    columns.push_back(NumberColumn<Row>("link_rejected", [this](const Row&) -> std::optional<double> {
      return static_cast<double>(link_.stats().rejected_lines);
    }));
    columns.push_back(NumberColumn<Row>("board_rejected", [this](const Row&) -> std::optional<double> {
      return static_cast<double>(sample_.board.board_rejected);
    }));
    return columns;
  }

  // latency_command_ms: from the frame's capture to the serial command its step sent (goes
  // between the CSV's latency_result_ms and latency_row_ms).
  template <typename Row = FrameResult>
  BasicCsvColumn<Row> latency_column() const {
    return NumberColumn<Row>(
        "latency_command_ms", [this](const Row&) { return latency_command_ms_; }, "%.3f");
  }
  // The angle the loop was given for the frame being written (the measurement of step()).
  std::optional<double> measured_deg() const { return sample_.measured_deg; }

  // The figures so far (frames, errors, pressures); the link's counters are the caller's.
  ControlSummary summary() const {
    ControlSummary out = summary_;
    out.run = ended_run_;
    std::vector<double> latencies = command_latencies_ms_;
    SummariseTimes(latencies, &out.latency_command_ms_median, &out.latency_command_ms_p99);
    if (errors_ > 0) out.rms_error_deg = std::sqrt(sum_sq_ / static_cast<double>(errors_));
    if (!step_points_.empty()) {
      out.metrics = ComputeStepMetrics(step_points_);
      out.metrics.rms_error_deg = out.rms_error_deg;  // Over the whole run, not the last step.
    }
    out.steps = ComputeEveryStepMetrics(run_points_);
    // A target that moves (a ramp, a sine), not only jumps: how it is followed.
    int changes = 0;
    for (size_t k = 1; k < run_points_.size(); ++k) {
      changes += run_points_[k].target_deg != run_points_[k - 1].target_deg;
    }
    if (changes > static_cast<int>(out.steps.size()) + 10) {
      out.tracking = ComputeTrackingMetrics(run_points_);
    }
    return out;
  }

 private:
  ControlSession& session_;
  const BoardLink& link_;
  double duration_s_;
  bool stop_at_duration_;
  // The frames since the target last jumped (with the one before the jump), for the step
  // figures, at most kMaxStepPoints of them (an hour at 30 fps): a longer hold keeps its first
  // hour, which is where a step settles.
  static constexpr size_t kMaxStepPoints = 108000;
  void collect_step_point(double target_deg) {
    const TrackingPoint point{sample_.time_s, target_deg, sample_.measured_deg};
    const StepMetricsOptions defaults;
    if (!step_points_.empty() &&
        std::abs(target_deg - step_points_.back().target_deg) > defaults.step_threshold_deg) {
      const TrackingPoint before = step_points_.back();
      step_points_.clear();
      step_points_.push_back(before);
    }
    if (step_points_.size() < kMaxStepPoints) step_points_.push_back(point);
    if (run_points_.size() < kMaxStepPoints) run_points_.push_back(point);
  }

  IdentificationExperiment* experiment_ = nullptr;
  TargetSubscriber* source_ = nullptr;
  TargetFeed* feed_ = nullptr;
  std::optional<double> at_limit_since_s_;  // Frame time the output reached max_kpa, while there.
  double longest_at_limit_s_ = 0.0;
  std::vector<TrackingPoint> step_points_;
  // Every frame of the run (its first hour), for the figures of each step of a staircase and the
  // tracking of a moving target.
  std::vector<TrackingPoint> run_points_;
  ControlSample sample_;
  std::optional<double> latency_command_ms_;
  std::vector<double> command_latencies_ms_;
  ControlSummary summary_;
  RunSummary ended_run_;
  double sum_sq_ = 0.0;
  int64_t errors_ = 0;
  bool done_ = false;
  int64_t stale_frames_ = 0;  // Frames the camera repeated (see stale_frames()).
};

// A simulated board with frames from elsewhere (--simulate --input): its clock follows the
// frames' timestamps, as it would follow the wall clock on a bench.
class RigClockSink : public FrameSink {
 public:
  explicit RigClockSink(SimulatedRig& rig) : rig_(rig) {}
  void consume(const Frame& frame, const FrameResult& result) override {
    (void)result;
    if (previous_s_ && frame.time_s > *previous_s_) rig_.advance(frame.time_s - *previous_s_);
    previous_s_ = frame.time_s;
  }

 private:
  SimulatedRig& rig_;
  std::optional<double> previous_s_;
};

}  // namespace softsight::control_parts
