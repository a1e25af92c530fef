// What `--publish` costs and how late its records arrive (issue 28, item 4), on this machine:
//   CaptureToSubscriber  one frame's result (3 markers, the bending scene's columns) through the
//                        CSV sink, then the publish sink, to a subscriber in another thread that
//                        receives and parses it (ipc:// and tcp://127.0.0.1). Reports the
//                        capture-to-row latency of the CSV and the capture-to-receive latency of
//                        the subscriber, median and p99, and the difference of the medians.
//   RunCost/N            the run's own thread per frame: TrackingSession::process on a rendered
//                        640x480 frame, the CSV row and the stream, with N subscribers reading
//                        every topic (N = -1: no --publish at all; 0: --publish, nobody
//                        listening). The subscribers run on this machine's two cores too.
// Each iteration of CaptureToSubscriber waits for the subscriber to have the record, so the
// latency is one record's, never a queue's.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>

#include "pipeline/scene_config_test_util.h"
#include "softsight/config/config.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/sim/scene.h"
#include "stream/publish_sink.h"
#include "stream/subscriber.h"

namespace softsight {
namespace {

const bool kSingleThreaded = [] {
  cv::setNumThreads(1);
  return true;
}();

using Clock = std::chrono::steady_clock;

double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// A scratch folder for the CSV and the ipc socket, removed at the end.
struct Scratch {
  std::filesystem::path dir = std::filesystem::temp_directory_path() /
                              ("softsight_publish_bench_" + std::to_string(::getpid()));
  Scratch() { std::filesystem::create_directories(dir); }
  ~Scratch() {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
  std::string file(const char* name) const { return (dir / name).string(); }
};

// A subscriber thread: receives every message, parses it (as a lab's script would), and notes
// when each frame record arrived.
class ReadingSubscriber {
 public:
  ReadingSubscriber(const std::string& endpoint, std::vector<std::string> topics)
      : subscriber_(endpoint, topics, "bench"), thread_([this] { loop(); }) {}
  ~ReadingSubscriber() {
    stop_ = true;
    thread_.join();
  }
  int64_t last_frame() const { return last_frame_.load(); }
  Clock::time_point last_arrival() const { return Clock::time_point(Clock::duration(arrival_.load())); }
  int64_t hellos() const { return hellos_.load(); }

 private:
  void loop() {
    while (!stop_) {
      const std::optional<StreamMessage> message = subscriber_.receive(20);
      if (!message) continue;
      const auto arrived = Clock::now();
      const nlohmann::json record = nlohmann::json::parse(message->body);
      if (message->topic == "hello") ++hellos_;
      if (message->topic != "frame") continue;
      arrival_ = arrived.time_since_epoch().count();
      last_frame_ = record["frame"].get<int64_t>();
    }
  }

  StreamSubscriber subscriber_;
  std::atomic<bool> stop_{false};
  std::atomic<int64_t> last_frame_{-1};
  std::atomic<Clock::rep> arrival_{0};
  std::atomic<int64_t> hellos_{0};
  std::thread thread_;
};

// Until `done()` (polling `poke` meanwhile, so the publisher reads subscriptions), at most 10 s.
template <typename Done, typename Poke>
bool WaitFor(Done done, Poke poke) {
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (!done()) {
    if (Clock::now() > deadline) return false;
    poke();
    std::this_thread::yield();
  }
  return true;
}

FrameResult SampleResult(const TrackingConfig& config) {
  FrameResult result;
  for (size_t i = 0; i < config.markers.size(); ++i) {
    MarkerObservation marker;
    marker.name = config.markers[i].name;
    marker.observation.position_px = cv::Point2d(100.0 + 50.0 * static_cast<double>(i), 240.25);
    marker.observation.score = 0.93;
    result.markers.push_back(marker);
  }
  result.measurement.angle_deg = 151.2345;
  result.measurement.chord_px = 101.5;
  result.measurement.sagitta_px = 3.25;
  result.measurement.radius_px = 420.0;
  result.measurement.arc_length_px = 102.0;
  result.measurement.tip_disp_px = 12.5;
  result.proc_ms = 1.2;
  return result;
}

void BM_CaptureToSubscriber(benchmark::State& state) {
  Scratch scratch;
  const bool tcp = state.range(0) == 1;
  const TrackingConfig config = testing::ThreeMarkerSceneConfig();
  CsvSink csv(scratch.file("run.csv"), TrackingColumns(config));
  PublishOptions options;
  options.endpoint = tcp ? "tcp://127.0.0.1:*" : "ipc://" + scratch.file("s.ipc");
  PublishSink publish(options);
  publish.set_columns(TrackingColumns(config));
  RunInfo info = DescribeMarkers(config);
  csv.begin(info);
  publish.begin(info);
  ReadingSubscriber subscriber(publish.endpoint(), {"hello", "frame"});
  FrameResult result = SampleResult(config);
  const Frame frame;
  int64_t index = 0;
  const auto send = [&] {
    result.frame_index = index;
    result.time_s = static_cast<double>(index) / 30.0;
    result.captured = Clock::now();
    csv.consume(frame, result);
    publish.consume(frame, result);
  };
  // Until the subscriber is connected and has a record.
  if (!WaitFor([&] { return subscriber.last_frame() >= 0; }, [&] { send(); ++index; })) {
    state.SkipWithError("the subscriber got nothing in 10 s");
    return;
  }
  std::vector<double> received_ms, row_ms;
  for (auto _ : state) {
    send();
    const int64_t sent = index++;
    if (!WaitFor([&] { return subscriber.last_frame() >= sent; }, [] {})) {
      state.SkipWithError("a record did not arrive in 10 s");
      return;
    }
    received_ms.push_back(Ms(subscriber.last_arrival() - result.captured));
    row_ms.push_back(csv.row_latencies_ms().back());
  }
  const double received_median = Percentile(received_ms, 0.5);
  const double row_median = Percentile(row_ms, 0.5);
  state.counters["subscriber_ms_median"] = received_median;
  state.counters["subscriber_ms_p99"] = Percentile(received_ms, 0.99);
  state.counters["csv_row_ms_median"] = row_median;
  state.counters["csv_row_ms_p99"] = Percentile(row_ms, 0.99);
  state.counters["subscriber_minus_row_ms_median"] = received_median - row_median;
  state.SetLabel(tcp ? "tcp://127.0.0.1" : "ipc://");
}
BENCHMARK(BM_CaptureToSubscriber)->Arg(0)->Arg(1)->Iterations(3000)->UseRealTime();

constexpr int kFrames = 32;

const std::vector<cv::Mat>& Frames() {
  static std::vector<cv::Mat> frames;
  if (frames.empty()) {
    SceneOptions options;
    options.size = {640, 480};
    options.frame_count = 10 * kFrames;
    options.max_bend_deg = 120;
    SyntheticScene scene(options, NoiseOptions{});
    for (int i = 0; i < kFrames; ++i) {
      cv::Mat image;
      scene.render(i, image);
      frames.push_back(image);
    }
  }
  return frames;
}

void BM_RunCost(benchmark::State& state) {
  Scratch scratch;
  const int subscribers = static_cast<int>(state.range(0));
  const TrackingConfig config = testing::ThreeMarkerSceneConfig();
  const std::vector<cv::Mat>& images = Frames();
  TrackingSession session(config);
  CsvSink csv(scratch.file("run.csv"), TrackingColumns(config));
  std::unique_ptr<PublishSink> publish;
  std::vector<std::unique_ptr<ReadingSubscriber>> readers;
  RunInfo info = DescribeMarkers(config);
  csv.begin(info);
  if (subscribers >= 0) {
    PublishOptions options;
    options.endpoint = "ipc://" + scratch.file("s.ipc");
    publish = std::make_unique<PublishSink>(options);
    publish->set_columns(TrackingColumns(config));
    publish->begin(info);
    std::vector<std::string> every_topic = {"hello", "frame", "measure", "marker/red",
                                            "marker/blue", "marker/green", "end"};
    for (int i = 0; i < subscribers; ++i) {
      readers.push_back(std::make_unique<ReadingSubscriber>(publish->endpoint(), every_topic));
    }
    const Frame idle;
    const FrameResult nothing = SampleResult(config);
    // Every subscriber connected (its hello arrived) before timing.
    for (const auto& reader : readers) {
      if (!WaitFor([&] { return reader->hellos() > 0; }, [&] { publish->consume(idle, nothing); })) {
        state.SkipWithError("a subscriber did not connect in 10 s");
        return;
      }
    }
  }
  Frame frame;
  int64_t i = 0;
  for (auto _ : state) {
    const int64_t k = i % (2 * kFrames - 2);
    frame.image = images[static_cast<size_t>(k < kFrames ? k : 2 * kFrames - 2 - k)];
    frame.index = i;
    frame.time_s = static_cast<double>(i) / 30.0;
    frame.captured = Clock::now();
    const FrameResult& result = session.process(frame);
    csv.consume(frame, result);
    if (publish) publish->consume(frame, result);
    ++i;
  }
  if (publish) {
    state.counters["dropped"] = static_cast<double>(publish->dropped());
    state.counters["sent"] = static_cast<double>(publish->sent());
  }
  state.SetLabel(subscribers < 0 ? "no --publish" : std::to_string(subscribers) + " subscribers");
}
BENCHMARK(BM_RunCost)->Arg(-1)->Arg(0)->Arg(1)->Arg(10)->Iterations(600)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace softsight
