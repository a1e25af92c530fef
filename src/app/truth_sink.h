// Scores each processed frame against the renderer's truth of the same source frame (the one
// TruthScorer, sim/truth_score.h): what `evaluate` and `demo` report.
#pragma once

#include <vector>

#include "softsight/pipeline/sink.h"
#include "softsight/sim/scene.h"
#include "softsight/sim/truth_score.h"

namespace softsight {

class TruthScoreSink : public FrameSink {
 public:
  // `truths[i]` is the truth of source frame i; it must outlive the sink.
  TruthScoreSink(const std::vector<SceneTruth>& truths, size_t marker_count)
      : truths_(truths), scorer_(marker_count) {}

  void consume(const Frame& frame, const FrameResult& result) override {
    scorer_.add(truths_.at(static_cast<size_t>(frame.index)), result);
  }
  bool uses_image() const override { return false; }
  TruthScore score() const { return scorer_.score(); }

 private:
  const std::vector<SceneTruth>& truths_;
  TruthScorer scorer_;
};

}  // namespace softsight
