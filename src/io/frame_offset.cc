#include "softsight/io/frame_offset.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "softsight/core/types.h"
#include "softsight/io/frame_source.h"

namespace softsight {
namespace {

constexpr int kReduction = 4;  // The motion signal's frames are reduced this much on each side.

std::string Format(const char* format, double a, long long b = 0) {
  char text[96];
  std::snprintf(text, sizeof(text), format, a, b);
  return text;
}

// The first frame whose mean grey level rose by at least `min_step` from the previous one.
std::optional<int64_t> FirstFlash(const std::vector<double>& brightness, double min_step,
                                  double* step) {
  for (size_t i = 1; i < brightness.size(); ++i) {
    if (brightness[i] - brightness[i - 1] >= min_step) {
      *step = brightness[i] - brightness[i - 1];
      return static_cast<int64_t>(i);
    }
  }
  return std::nullopt;
}

// Pearson's r of left.motion[i] and right.motion[i + lag] over the frames both have (frame 0 of
// each has no motion); absent when they overlap by fewer than `min_overlap` frames or either
// does not vary there.
std::optional<double> CorrelationAt(const std::vector<double>& left,
                                    const std::vector<double>& right, int64_t lag,
                                    int64_t min_overlap) {
  const int64_t first = std::max<int64_t>(1, 1 - lag);
  const int64_t end =
      std::min<int64_t>(static_cast<int64_t>(left.size()), static_cast<int64_t>(right.size()) - lag);
  const int64_t n = end - first;
  if (n < min_overlap || n < 3) return std::nullopt;
  double sum_l = 0, sum_r = 0;
  for (int64_t i = first; i < end; ++i) {
    sum_l += left[static_cast<size_t>(i)];
    sum_r += right[static_cast<size_t>(i + lag)];
  }
  const double mean_l = sum_l / static_cast<double>(n), mean_r = sum_r / static_cast<double>(n);
  double sll = 0, srr = 0, slr = 0;
  for (int64_t i = first; i < end; ++i) {
    const double dl = left[static_cast<size_t>(i)] - mean_l;
    const double dr = right[static_cast<size_t>(i + lag)] - mean_r;
    sll += dl * dl;
    srr += dr * dr;
    slr += dl * dr;
  }
  // A signal that does not vary (a still scene: only sensor noise or nothing) correlates with
  // nothing. 1e-6 grey levels squared per frame is far below a moving edge.
  if (!(sll > 1e-6 * static_cast<double>(n)) || !(srr > 1e-6 * static_cast<double>(n))) {
    return std::nullopt;
  }
  return slr / std::sqrt(sll * srr);
}

}  // namespace

void SyncSignal::add(const cv::Mat& frame) {
  CV_Assert(frame.depth() == CV_8U && (frame.channels() == 3 || frame.channels() == 1));
  if (frame.channels() == 3) {
    cv::cvtColor(frame, gray_, cv::COLOR_BGR2GRAY);
  } else {
    frame.copyTo(gray_);
  }
  brightness_.push_back(cv::mean(gray_)[0]);
  const cv::Size small_size(std::max(1, gray_.cols / kReduction), std::max(1, gray_.rows / kReduction));
  cv::resize(gray_, small_, small_size, 0, 0, cv::INTER_AREA);
  small_.convertTo(difference_, CV_32F);
  difference_ -= cv::mean(difference_);
  if (previous_.empty() || previous_.size() != difference_.size()) {
    motion_.push_back(0.0);
  } else {
    cv::absdiff(difference_, previous_, absolute_);
    motion_.push_back(cv::mean(absolute_)[0]);
  }
  cv::swap(difference_, previous_);
}

SyncSignal MeasureSyncSignal(FrameSource& source, std::optional<int64_t> max_frames) {
  SyncSignal signal;
  Frame frame;
  while ((!max_frames || static_cast<int64_t>(signal.size()) < *max_frames) && source.read(frame)) {
    signal.add(frame.image);
  }
  return signal;
}

bool FrameOffsetOptions::Check(std::string* error) const {
  if (max_offset_frames < 0 || max_offset_frames > 100000) {
    *error = "max_offset_frames: must be in [0, 100000], got " + std::to_string(max_offset_frames);
    return false;
  }
  if (!(flash_min_step > 0 && flash_min_step <= 255)) {
    *error = "flash_min_step: must be in (0, 255] grey levels";
    return false;
  }
  if (!(min_correlation > 0 && min_correlation <= 1)) {
    *error = "min_correlation: must be in (0, 1]";
    return false;
  }
  if (!(min_margin >= 0 && min_margin <= 2)) {
    *error = "min_margin: must be in [0, 2]";
    return false;
  }
  if (min_overlap_frames < 3) {
    *error = "min_overlap_frames: must be >= 3, got " + std::to_string(min_overlap_frames);
    return false;
  }
  return true;
}

const char* FrameOffsetMethodName(FrameOffsetEstimate::Method method) {
  return method == FrameOffsetEstimate::Method::kFlash ? "flash" : "motion";
}

FrameOffsetEstimate EstimateFrameOffset(const SyncSignal& left, const SyncSignal& right,
                                        const FrameOffsetOptions& options) {
  FrameOffsetEstimate estimate;
  const int64_t max_offset = options.max_offset_frames;

  // A flash seen by both, within the range: the step up is sharp to the frame.
  estimate.left_flash_frame =
      FirstFlash(left.brightness(), options.flash_min_step, &estimate.left_flash_step);
  estimate.right_flash_frame =
      FirstFlash(right.brightness(), options.flash_min_step, &estimate.right_flash_step);
  if (estimate.left_flash_frame && estimate.right_flash_frame &&
      std::abs(*estimate.right_flash_frame - *estimate.left_flash_frame) <= max_offset) {
    estimate.method = FrameOffsetEstimate::Method::kFlash;
    estimate.offset_frames = *estimate.right_flash_frame - *estimate.left_flash_frame;
    return estimate;
  }

  // The motion: the correlation over every offset in range.
  estimate.method = FrameOffsetEstimate::Method::kMotion;
  const int64_t shorter = static_cast<int64_t>(std::min(left.size(), right.size()));
  const int64_t min_overlap = std::max(options.min_overlap_frames, shorter / 2);
  estimate.correlation.resize(static_cast<size_t>(2 * max_offset + 1));
  for (int64_t lag = -max_offset; lag <= max_offset; ++lag) {
    estimate.correlation[static_cast<size_t>(lag + max_offset)] =
        CorrelationAt(left.motion(), right.motion(), lag, min_overlap);
  }
  const auto& c = estimate.correlation;
  // Local maxima (an absent neighbour does not count against one); the best, then the best
  // other that is not the best's own shoulder.
  std::optional<size_t> best;
  std::vector<size_t> peaks;
  for (size_t k = 0; k < c.size(); ++k) {
    if (!c[k]) continue;
    const bool above_previous = k == 0 || !c[k - 1] || *c[k] >= *c[k - 1];
    const bool above_next = k + 1 == c.size() || !c[k + 1] || *c[k] >= *c[k + 1];
    if (above_previous && above_next) peaks.push_back(k);
    if (!best || *c[k] > *c[*best]) best = k;
  }
  if (!best) {
    estimate.refusal =
        "no motion to correlate (a still scene, or " + std::to_string(left.size()) + " and " +
        std::to_string(right.size()) + " frames: too few to overlap by " +
        std::to_string(min_overlap) + ")";
    return estimate;
  }
  estimate.peak_correlation = c[*best];
  estimate.peak_offset = static_cast<int64_t>(*best) - max_offset;
  for (size_t k : peaks) {
    if (k + 1 >= *best && k <= *best + 1) continue;
    if (!estimate.second_correlation || *c[k] > *estimate.second_correlation) {
      estimate.second_correlation = c[k];
      estimate.second_offset = static_cast<int64_t>(k) - max_offset;
    }
  }
  if (*estimate.peak_correlation < options.min_correlation) {
    estimate.refusal = Format("the motion correlates at best r = %.2f (offset %lld)",
                              *estimate.peak_correlation, *estimate.peak_offset) +
                       Format(", below %.2f: not clearly the same motion", options.min_correlation);
    return estimate;
  }
  if (estimate.second_correlation &&
      *estimate.peak_correlation - *estimate.second_correlation < options.min_margin) {
    estimate.refusal = Format("two offsets fit the motion alike: r = %.2f at %lld",
                              *estimate.peak_correlation, *estimate.peak_offset) +
                       Format(" and r = %.2f at %lld (a repeating motion?)",
                              *estimate.second_correlation, *estimate.second_offset);
    return estimate;
  }
  estimate.offset_frames = estimate.peak_offset;
  return estimate;
}

FrameOffsetEstimate FindFrameOffset(FrameSource& left, FrameSource& right,
                                    const FrameOffsetOptions& options,
                                    std::optional<int64_t> max_frames,
                                    const FrameOffsetNames& names) {
  const std::string range = "within +-" + std::to_string(options.max_offset_frames) + " frames";
  std::string error;
  if (!options.Check(&error)) {
    throw InputError("cannot find the frame offset between " + names.inputs + ": " + error);
  }
  const SyncSignal left_signal = MeasureSyncSignal(left, max_frames);
  const SyncSignal right_signal = MeasureSyncSignal(right, max_frames);
  FrameOffsetEstimate estimate = EstimateFrameOffset(left_signal, right_signal, options);
  if (!estimate.offset_frames) {
    throw InputError("cannot find the frame offset between " + names.inputs + " " + range +
                     ": " + estimate.refusal + "; pass " + names.option);
  }
  return estimate;
}

std::string DescribeFrameOffset(const FrameOffsetEstimate& estimate,
                                const FrameOffsetOptions& options) {
  const int64_t offset = estimate.offset_frames.value_or(0);
  char text[256];
  std::snprintf(text, sizeof(text),
                "frame offset %lld (right frame = left frame %c %lld), found from ",
                static_cast<long long>(offset), offset >= 0 ? '+' : '-',
                static_cast<long long>(std::abs(offset)));
  std::string line = text;
  if (estimate.method == FrameOffsetEstimate::Method::kFlash) {
    std::snprintf(text, sizeof(text),
                  "a flash: left frame %lld, right frame %lld (brightness steps %.1f and %.1f "
                  "grey levels)",
                  static_cast<long long>(estimate.left_flash_frame.value_or(-1)),
                  static_cast<long long>(estimate.right_flash_frame.value_or(-1)),
                  estimate.left_flash_step, estimate.right_flash_step);
    return line + text;
  }
  std::snprintf(text, sizeof(text), "the motion: correlation %.3f",
                estimate.peak_correlation.value_or(0.0));
  line += text;
  if (estimate.second_correlation) {
    std::snprintf(text, sizeof(text), ", next best peak %.3f at offset %lld",
                  *estimate.second_correlation,
                  static_cast<long long>(estimate.second_offset.value_or(0)));
    line += text;
  } else {
    line += ", no other peak";
  }
  return line + " (searched +-" + std::to_string(options.max_offset_frames) + ")";
}

}  // namespace softsight
