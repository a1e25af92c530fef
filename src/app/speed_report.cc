// softsight_speed_report CONFIG VIDEO OUT_DIR: what a user waits for when tracking a recording,
// each figure beside references measured in the same run on the same file, so the ratios hold
// on another (or a busier) machine. Prints Markdown table rows for the README (scripts/bench.sh).
//   - one BGR -> gray pass over the video's first frame (the per-frame reference of every table),
//   - a bare decode loop of the file: OpenCV's FFmpeg reader and nothing else (not
//     OpenFrameSource: a file's source also checks for damage (the decoder's marks, key frames,
//     a Motion JPEG's coded data), which is `track`'s cost, not the decoder's),
//   - `track`'s pipeline (CSV written) with decoding in line, then decoding on its own thread
//     (ReadAheadSource, as `track` runs), wall time per frame,
//   - the tracking alone (median proc_ms of the same runs),
//   - the process's CPU time per frame (every thread: FFmpeg decodes on helper threads) of the
//     decode loop and of the threaded run: on N cores the run cannot take less wall time than
//     its CPU time / N, which is the bound to compare the threaded run with (decoding may
//     already keep every core busy, and then max(decode, track) is out of reach).
// Each is the median of `kRepeats` runs. A benchmark, not a test: it asserts nothing.
// softsight_speed_report --decode VIDEO: the bare decode loop alone, once (for its peak memory).
// softsight_speed_report --source VIDEO: the file's FrameSource alone (the decode and the damage
// and key-frame checks), once: what of `track`'s cost is reading.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <time.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "softsight/config/config.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/tracking_session.h"
#include "io/read_ahead_source.h"

namespace softsight {
namespace {

constexpr int kRepeats = 3;
using Clock = std::chrono::steady_clock;

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// CPU time of the whole process (every thread) so far, ms.
double ProcessCpuMs() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) * 1e3 + static_cast<double>(now.tv_nsec) * 1e-6;
}

// One BGR -> gray pass over `frame`, ms (median of 200).
double GrayPassMs(const cv::Mat& frame) {
  cv::Mat gray;
  std::vector<double> times;
  for (int i = 0; i < 200; ++i) {
    const auto start = Clock::now();
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
    times.push_back(MsSince(start));
  }
  return Median(times);
}

struct Pass {
  double ms_per_frame;
  double proc_ms_median = 0.0;
  int64_t frames;
  double cpu_ms_per_frame = 0.0;  // The process's, every thread.
};

// Reads every frame by `read_one` (true while there is one), timed per frame.
template <typename ReadOne>
Pass TimeReads(ReadOne read_one) {
  int64_t frames = 0;
  const auto start = Clock::now();
  const double cpu_start = ProcessCpuMs();
  while (read_one()) ++frames;
  const double n = static_cast<double>(std::max<int64_t>(frames, 1));
  return {MsSince(start) / n, 0.0, frames, (ProcessCpuMs() - cpu_start) / n};
}

Pass DecodeOnly(const std::string& video) {
  cv::VideoCapture capture(video, cv::CAP_FFMPEG);
  cv::Mat image;
  return TimeReads([&] { return capture.read(image); });
}

Pass SourceOnly(const std::string& video) {
  std::unique_ptr<FrameSource> source = OpenFrameSource({video, {}, 30.0});
  Frame frame;
  return TimeReads([&] { return source->read(frame); });
}

Pass Track(const TrackingConfig& config, const std::string& video, const std::string& csv,
           bool read_ahead) {
  std::unique_ptr<FrameSource> source = OpenFrameSource({video, {}, 30.0});
  if (read_ahead) source = std::make_unique<ReadAheadSource>(std::move(source));
  TrackingSession session(config);
  CsvSink sink(csv, TrackingColumns(config));
  const auto start = Clock::now();
  const double cpu_start = ProcessCpuMs();
  const RunSummary summary = RunPipeline(*source, session, {&sink});
  const double ms = MsSince(start);
  const double n = static_cast<double>(std::max<int64_t>(summary.frames, 1));
  return {ms / n, summary.proc_ms_median, summary.frames, (ProcessCpuMs() - cpu_start) / n};
}

int Main(int argc, char** argv) {
  const std::string mode = argc == 3 ? argv[1] : "";
  if (mode == "--source" || mode == "--decode") {
    const Pass read = mode == "--source" ? SourceOnly(argv[2]) : DecodeOnly(argv[2]);
    std::printf("%lld frames, %.3f ms/frame, CPU %.3f ms/frame\n",
                static_cast<long long>(read.frames), read.ms_per_frame, read.cpu_ms_per_frame);
    return 0;
  }
  if (argc != 4) {
    std::cerr << "usage: softsight_speed_report CONFIG VIDEO OUT_DIR\n"
                 "       softsight_speed_report --decode VIDEO\n"
                 "       softsight_speed_report --source VIDEO\n";
    return 2;
  }
  const TrackingConfig config = LoadTrackingConfig(argv[1]);
  const std::string video = argv[2];
  const std::string csv = (std::filesystem::path(argv[3]) / "speed_report.csv").string();
  Frame first;
  OpenFrameSource({video, {}, 30.0})->read(first);

  std::vector<double> gray, decode, inline_ms, ahead_ms, proc, decode_cpu, ahead_cpu;
  int64_t frames = 0;
  for (int r = 0; r < kRepeats; ++r) {
    // Interleaved, so a change of the machine's load touches every figure alike.
    gray.push_back(GrayPassMs(first.image));
    const Pass decoded = DecodeOnly(video);
    decode.push_back(decoded.ms_per_frame);
    decode_cpu.push_back(decoded.cpu_ms_per_frame);
    const Pass in_line = Track(config, video, csv, false);
    const Pass ahead = Track(config, video, csv, true);
    ahead_cpu.push_back(ahead.cpu_ms_per_frame);
    inline_ms.push_back(in_line.ms_per_frame);
    ahead_ms.push_back(ahead.ms_per_frame);
    proc.push_back(in_line.proc_ms_median);
    proc.push_back(ahead.proc_ms_median);
    frames = ahead.frames;
  }
  const double g = Median(gray), d = Median(decode), a = Median(inline_ms), b = Median(ahead_ms),
               p = Median(proc), dc = Median(decode_cpu), bc = Median(ahead_cpu);
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  char row[1024];
  std::snprintf(row, sizeof(row),
                "| `track`, %dx%d %s file (%lld frames): wall time per frame with decoding in line "
                "/ on its own thread (as `track` runs) | %.3f / %.3f ms (%.2fx) | bare decode loop "
                "of the file %.3f ms/frame, tracking alone %.3f ms, gray pass %.3f ms; CPU time "
                "per frame (every thread): decode loop %.3f ms (%.1f cores busy), `track` on its "
                "own thread %.3f ms, so at least %.3f ms of wall time on %u cores; max(decode, "
                "tracking) %.3f ms, the threaded run %.2fx of it |\n",
                first.image.cols, first.image.rows,
                std::filesystem::path(video).extension().string().c_str(),
                static_cast<long long>(frames), a, b, a / b, d, p, g, dc, dc / d, bc,
                bc / cores, cores, std::max(d, p), b / std::max(d, p));
  std::cout << row;
  return 0;
}

}  // namespace
}  // namespace softsight

int main(int argc, char** argv) {
  try {
    return softsight::Main(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "softsight_speed_report: " << e.what() << "\n";
    return 2;
  }
}
