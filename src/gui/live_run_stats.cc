#include "gui/live_run_stats.h"

#include <cstdio>

#include "softsight/pipeline/summary.h"

namespace softsight {

void LiveRunStats::add_result(const FrameResult& result) {
  result_ms_.push_back(result.latency_result_ms);
}

void LiveRunStats::add_recording(const LiveRecording& recording) {
  const std::vector<double>& rows = recording.row_latencies_ms();
  row_ms_.insert(row_ms_.end(), rows.begin(), rows.end());
  recorded_ += recording.frames();
  encoder_waits_ += recording.encoder_waits();
}

LiveRunSummary LiveRunStats::summary(int64_t dropped_by_source, const LiveRecording* open) const {
  LiveRunStats all = *this;  // Once, at the end of the run.
  if (open != nullptr) all.add_recording(*open);
  LiveRunSummary out;
  out.frames = static_cast<int64_t>(all.result_ms_.size());
  out.dropped_by_source = dropped_by_source;
  SummariseTimes(all.result_ms_, &out.latency_result_ms_median, &out.latency_result_ms_p99);
  SummariseTimes(all.row_ms_, &out.latency_row_ms_median, &out.latency_row_ms_p99);
  out.recorded_frames = all.recorded_;
  out.encoder_waits = all.encoder_waits_;
  return out;
}

std::string LiveRunSummary::Report() const {
  char line[320];
  std::snprintf(line, sizeof(line), "live: %lld frames tracked, %lld dropped by the source\n",
                static_cast<long long>(frames), static_cast<long long>(dropped_by_source));
  std::string out = line;
  if (frames > 0) {
    std::snprintf(line, sizeof(line),
                  "live: latency from capture to the result median %.3f ms, p99 %.3f ms\n",
                  latency_result_ms_median, latency_result_ms_p99);
    out += line;
  }
  if (recorded_frames == 0) return out + "live: nothing recorded\n";
  std::snprintf(line, sizeof(line),
                "live: recorded %lld frames, each in the CSV and both videos; latency from capture "
                "to the CSV row median %.3f ms, p99 %.3f ms\n",
                static_cast<long long>(recorded_frames), latency_row_ms_median, latency_row_ms_p99);
  out += line;
  if (encoder_waits == 0) return out + "live: the recordings' encoders kept up\n";
  std::snprintf(line, sizeof(line),
                "live: the recordings' encoders fell behind and held up the window %lld times\n",
                static_cast<long long>(encoder_waits));
  return out + line;
}

}  // namespace softsight
