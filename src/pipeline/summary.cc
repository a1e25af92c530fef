#include "softsight/pipeline/summary.h"

#include <algorithm>
#include <cstdio>

namespace softsight {

const char* StopReasonName(StopReason reason) {
  switch (reason) {
    case StopReason::kEndOfInput:
      return "end of input";
    case StopReason::kMaxFrames:
      return "max frames reached";
    case StopReason::kStopRequested:
      return "stop requested";
    case StopReason::kError:
      return "error";
  }
  return "?";
}

void SummariseTimes(std::vector<double>& times_ms, double* median_ms, double* p99_ms) {
  *median_ms = 0.0;
  *p99_ms = 0.0;
  if (times_ms.empty()) return;
  std::sort(times_ms.begin(), times_ms.end());
  *median_ms = times_ms[times_ms.size() / 2];
  const size_t p99 = std::min(times_ms.size() - 1,
                              static_cast<size_t>(0.99 * static_cast<double>(times_ms.size())));
  *p99_ms = times_ms[p99];
}

std::string RunSummary::stop_text() const {
  return stop_detail.empty() ? StopReasonName(stop_reason) : stop_detail;
}

double RunSummary::found_rate(size_t i) const {
  return frames > 0 ? static_cast<double>(markers.at(i).found) / static_cast<double>(frames)
                    : 0.0;
}

std::string RunSummary::BriefReport() const {
  char text[160];
  std::snprintf(text, sizeof(text), "%lld frames (%s)", static_cast<long long>(frames),
                stop_text().c_str());
  std::string line = text;
  if (dropped > 0) line += ", " + std::to_string(dropped) + " dropped by the source";
  if (!markers.empty()) {
    line += ", found:";
    for (size_t i = 0; i < markers.size(); ++i) {
      std::snprintf(text, sizeof(text), "%s %s %.1f %%", i == 0 ? "" : ",",
                    markers[i].name.c_str(), 100.0 * found_rate(i));
      line += text;
    }
  }
  std::snprintf(text, sizeof(text), ", %.3f ms/frame", proc_ms_median);
  line += text;
  return line;
}

std::string RunSummary::FullReport() const {
  std::string out;
  char line[384];
  std::snprintf(line, sizeof(line), "frames: %lld from %s in %.2f s (%s)\n",
                static_cast<long long>(frames), source.c_str(), wall_s, stop_text().c_str());
  out += line;
  if (first_index && last_index) {
    std::snprintf(line, sizeof(line), "source frames %lld..%lld, %lld dropped by the source\n",
                  static_cast<long long>(*first_index), static_cast<long long>(*last_index),
                  static_cast<long long>(dropped));
    out += line;
  }
  for (size_t i = 0; i < markers.size(); ++i) {
    std::snprintf(line, sizeof(line), "  %-12s found in %lld frames (%.1f %%)\n",
                  markers[i].name.c_str(), static_cast<long long>(markers[i].found),
                  100.0 * found_rate(i));
    out += line;
  }
  const std::vector<std::string> not_found = statuses.lines();
  if (!not_found.empty()) out += "not found:\n";
  for (const std::string& status : not_found) out += "  " + status + "\n";
  std::snprintf(line, sizeof(line), "angle measured in %lld frames\n",
                static_cast<long long>(measured));
  out += line;
  std::snprintf(line, sizeof(line), "processing per frame: median %.3f ms, p99 %.3f ms\n",
                proc_ms_median, proc_ms_p99);
  out += line;
  if (frames > 0) {
    char row[96] = "";
    if (latency_row_ms_median && latency_row_ms_p99) {
      std::snprintf(row, sizeof(row), "; to the CSV row median %.3f ms, p99 %.3f ms",
                    *latency_row_ms_median, *latency_row_ms_p99);
    }
    std::snprintf(line, sizeof(line),
                  "latency from capture (a file's frame: from its decoding): to the result "
                  "median %.3f ms, p99 %.3f ms%s; to every output written median %.3f ms, p99 %.3f ms\n",
                  latency_result_ms_median, latency_result_ms_p99, row, latency_done_ms_median,
                  latency_done_ms_p99);
    out += line;
  }
  for (const std::string& note : notes) out += "note: " + note + "\n";
  if (stop_reason == StopReason::kError) out += "stopped by: " + error + "\n";
  return out;
}

}  // namespace softsight
