#include "softsight/io/stereo_input.h"

#include <chrono>
#include <cmath>
#include <utility>

#include "softsight/core/error.h"

namespace softsight {
namespace {

std::vector<std::string> FilesOf(const FrameSource& a, const FrameSource* b) {
  std::vector<std::string> files = a.files();
  if (b != nullptr) {
    for (std::string& file : b->files()) files.push_back(std::move(file));
  }
  return files;
}

class IndexPairs : public StereoInput {
 public:
  IndexPairs(std::unique_ptr<FrameSource> left, std::unique_ptr<FrameSource> right,
             int64_t frame_offset, const std::string& offset_name)
      : left_(std::move(left)), right_(std::move(right)) {
    FrameSource& ahead = frame_offset > 0 ? *right_ : *left_;
    Frame dropped;
    for (int64_t skipped = 0; skipped < std::abs(frame_offset); ++skipped) {
      if (!ahead.read(dropped)) {
        throw InputError(offset_name + " " + std::to_string(frame_offset) + ": " +
                         ahead.description() + " has only " + std::to_string(skipped) + " frames");
      }
    }
    (frame_offset > 0 ? right_unpaired_ : left_unpaired_) = std::abs(frame_offset);
  }

  bool read(FramePair& pair) override {
    pair.pair_dt_ms.reset();
    if (!left_->read(pair.left)) return false;
    if (!right_->read(pair.right)) {
      ended_ = right_->description() + " ended first";
      return false;
    }
    return true;
  }
  std::string description() const override {
    return left_->description() + " + " + right_->description();
  }
  std::optional<double> fps() const override { return left_->fps(); }
  bool is_live() const override { return left_->is_live(); }
  int64_t left_unpaired() const override { return left_unpaired_; }
  int64_t right_unpaired() const override { return right_unpaired_; }
  std::optional<std::string> ended_first() const override { return ended_; }
  std::vector<std::string> files() const override { return FilesOf(*left_, right_.get()); }

 private:
  std::unique_ptr<FrameSource> left_, right_;
  int64_t left_unpaired_ = 0, right_unpaired_ = 0;
  std::optional<std::string> ended_;
};

// One view of a time pairing: the current frame and the next (read one ahead), their buffers
// reused (a frame handed out swaps its buffer with the caller's).
struct TimedView {
  std::unique_ptr<FrameSource> source;
  TimePairingOptions::Clock clock;
  double offset_ms = 0.0;  // Subtracted from this view's times.
  Frame current, next;
  bool have_current = false, have_next = false, ended = false;
  int64_t unpaired = 0;

  bool read_into(Frame& frame) {
    if (ended || !source->read(frame)) {
      ended = true;
      return false;
    }
    if (clock == TimePairingOptions::Clock::kCaptureTime &&
        frame.captured == std::chrono::steady_clock::time_point{}) {
      frame.captured = std::chrono::steady_clock::now();
    }
    return true;
  }
  void fill() {
    if (!have_current && have_next) {
      std::swap(current, next);
      have_current = true;
      have_next = false;
    }
    if (!have_current) have_current = read_into(current);
    if (have_current && !have_next) have_next = read_into(next);
  }
  double time_ms(const Frame& frame) const {
    const double ms =
        clock == TimePairingOptions::Clock::kSourceTime
            ? frame.time_s * 1000.0
            : std::chrono::duration<double, std::milli>(frame.captured.time_since_epoch()).count();
    return ms - offset_ms;
  }
  // The frame interval (ms): the source's nominal rate, else its first two frames.
  std::optional<double> interval_ms() const {
    const std::optional<double> fps = source->fps();
    if (fps && *fps > 0) return 1000.0 / *fps;
    if (have_current && have_next) {
      const double dt = time_ms(next) - time_ms(current);
      if (dt > 0) return dt;
    }
    return std::nullopt;
  }
  void drop() {
    have_current = false;
    ++unpaired;
  }
};

class TimePairs : public StereoInput {
 public:
  TimePairs(std::unique_ptr<FrameSource> left, std::unique_ptr<FrameSource> right,
            const TimePairingOptions& options)
      : max_dt_ms_(options.max_dt_ms) {
    left_.source = std::move(left);
    right_.source = std::move(right);
    left_.clock = right_.clock = options.clock;
    right_.offset_ms = options.time_offset_ms;
  }

  bool read(FramePair& pair) override {
    for (;;) {
      left_.fill();
      right_.fill();
      if (!left_.have_current || !right_.have_current) {
        if (left_.have_current) ended_ = right_.source->description() + " ended first";
        if (right_.have_current) ended_ = left_.source->description() + " ended first";
        return false;
      }
      const double tolerance = Tolerance();
      const double t_left = left_.time_ms(left_.current);
      const double t_right = right_.time_ms(right_.current);
      const double dt = t_right - t_left;
      // Every later frame of the other view is later still: this one has no partner.
      if (dt < -tolerance) {
        right_.drop();
        continue;
      }
      if (dt > tolerance) {
        left_.drop();
        continue;
      }
      // Within the tolerance; a pair only when each is the other's nearest.
      if (left_.have_next && std::abs(left_.time_ms(left_.next) - t_right) < std::abs(dt)) {
        left_.drop();
        continue;
      }
      if (right_.have_next && std::abs(right_.time_ms(right_.next) - t_left) < std::abs(dt)) {
        right_.drop();
        continue;
      }
      std::swap(pair.left, left_.current);
      std::swap(pair.right, right_.current);
      left_.have_current = right_.have_current = false;
      pair.pair_dt_ms = dt;
      return true;
    }
  }
  std::string description() const override {
    return left_.source->description() + " + " + right_.source->description();
  }
  std::optional<double> fps() const override { return left_.source->fps(); }
  bool is_live() const override { return left_.source->is_live(); }
  int64_t left_unpaired() const override { return left_.unpaired; }
  int64_t right_unpaired() const override { return right_.unpaired; }
  std::optional<std::string> ended_first() const override { return ended_; }
  std::vector<std::string> files() const override {
    return FilesOf(*left_.source, right_.source.get());
  }

 private:
  double Tolerance() {
    if (max_dt_ms_) return *max_dt_ms_;
    const std::optional<double> l = left_.interval_ms(), r = right_.interval_ms();
    if (!l && !r) {
      throw InputError("pairing by time: neither " + left_.source->description() + " nor " +
                       right_.source->description() +
                       " gives a frame rate or two frames to measure one");
    }
    max_dt_ms_ = 0.5 * (l && r ? std::min(*l, *r) : l ? *l : *r);
    return *max_dt_ms_;
  }

  TimedView left_, right_;
  std::optional<double> max_dt_ms_;
  std::optional<std::string> ended_;
};

class SideBySide : public StereoInput {
 public:
  explicit SideBySide(std::unique_ptr<FrameSource> source) : source_(std::move(source)) {}

  bool read(FramePair& pair) override {
    pair.pair_dt_ms.reset();
    // Let go of the last halves first: the decoded frame's buffer is then the source's alone to
    // reuse (a read-ahead source gives up a buffer still shared, and allocates a new one).
    pair.left.image.release();
    pair.right.image.release();
    if (!source_->read(full_)) return false;
    const cv::Mat& image = full_.image;
    if (image.cols % 2 != 0) {
      throw InputError(source_->description() + ": frame " + std::to_string(full_.index) +
                       " is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                       ": a side-by-side frame's width must be even (two halves of one size)");
    }
    const int half = image.cols / 2;
    pair.left.image = image.colRange(0, half);  // Headers into the decoded frame.
    pair.right.image = image.colRange(half, image.cols);
    pair.left.index = pair.right.index = full_.index;
    pair.left.time_s = pair.right.time_s = full_.time_s;
    pair.left.captured = pair.right.captured = full_.captured;
    return true;
  }
  std::string description() const override { return source_->description() + " (side by side)"; }
  std::optional<double> fps() const override { return source_->fps(); }
  bool is_live() const override { return source_->is_live(); }
  std::vector<std::string> files() const override { return FilesOf(*source_, nullptr); }

 private:
  std::unique_ptr<FrameSource> source_;
  Frame full_;
};

}  // namespace

bool TimePairingOptions::Check(std::string* error) const {
  if (!std::isfinite(time_offset_ms)) {
    *error = "time_offset_ms: must be a finite number";
    return false;
  }
  if (max_dt_ms && !(*max_dt_ms > 0 && std::isfinite(*max_dt_ms))) {
    *error = "max_dt_ms: must be a positive number of milliseconds";
    return false;
  }
  return true;
}

std::unique_ptr<StereoInput> PairByIndex(std::unique_ptr<FrameSource> left,
                                         std::unique_ptr<FrameSource> right, int64_t frame_offset,
                                         const std::string& offset_name) {
  return std::make_unique<IndexPairs>(std::move(left), std::move(right), frame_offset,
                                      offset_name);
}

std::unique_ptr<StereoInput> PairByTime(std::unique_ptr<FrameSource> left,
                                        std::unique_ptr<FrameSource> right,
                                        const TimePairingOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw InputError("pairing by time: " + error);
  return std::make_unique<TimePairs>(std::move(left), std::move(right), options);
}

std::unique_ptr<StereoInput> SplitSideBySide(std::unique_ptr<FrameSource> source) {
  return std::make_unique<SideBySide>(std::move(source));
}

}  // namespace softsight
