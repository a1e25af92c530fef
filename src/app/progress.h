// A progress line on stderr for batch work: a bar, frames, rate and ETA on a terminal; a line
// every quarter when stderr is a file or pipe, so logs stay readable.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "softsight/pipeline/sink.h"

namespace softsight {

class ProgressBar {
 public:
  ProgressBar(std::string label, std::optional<int64_t> total, bool enabled);
  void update(int64_t done);
  // Clears the bar so the summary starts on a clean line.
  void finish();

 private:
  std::string label_;
  std::optional<int64_t> total_;
  bool enabled_;
  bool terminal_;
  int last_quarter_ = 0;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

// The progress bar as a sink: its total is the run's known frame count (none for a camera).
class ProgressSink : public FrameSink {
 public:
  ProgressSink(std::string label, bool enabled) : label_(std::move(label)), enabled_(enabled) {}
  void begin(const RunInfo& info) override;
  void consume(const Frame& frame, const FrameResult& result) override;
  void end(const RunSummary& summary) override;
  bool uses_image() const override { return false; }

 private:
  std::string label_;
  bool enabled_;
  std::optional<ProgressBar> bar_;
  int64_t done_ = 0;
};

}  // namespace softsight
