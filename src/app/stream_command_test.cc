// End-to-end tests of the stream (docs/stream.md): `track --publish` while subscribers read it
// (a raw record subscriber and `listen --csv`), a subscriber that stops reading, bad endpoints,
// and `control --target-from` venting when its source falls silent. Every wait is a poll with a
// bound; none needs a sleep to pass.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <cmath>
#include <csignal>
#include <future>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <zmq.hpp>

#include "app/control_command.h"
#include "app/listen_command.h"
#include "app/program_test_util.h"
#include "app/scene_markers_test_util.h"
#include "app/track_command.h"
#include "core/test_util.h"
#include "stream/publish_sink.h"
#include "stream/subscriber.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::ProgramRun;
using testing::ReadLines;
using testing::RunProgram;
using testing::ReadTextFile;
using testing::SplitCsv;
using testing::TempDir;
using testing::WriteTextFile;

// Columns whose values are timings (they differ between runs, and a record's latency_row_ms is
// taken as the record is made, not as the row is).
bool IsTiming(const std::string& column) {
  return column == "latency_result_ms" || column == "latency_row_ms" || column == "proc_ms";
}

TrackOptions BendingRun(const TempDir& dir, const std::string& csv, int64_t frames) {
  WriteTextFile(dir.file("markers.yaml"), testing::kScaledSceneMarkersYaml);
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.source.input = "synth:bending";
  options.csv_file = dir.file(csv);
  options.max_frames = frames;
  options.quiet = true;
  return options;
}

// The CSV as rows of fields, header first.
std::vector<std::vector<std::string>> ReadCsvCells(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  for (const std::string& line : ReadLines(path)) rows.push_back(SplitCsv(line));
  return rows;
}

// A CSV field and the value another route gave for it are the same value: both empty, the same
// word, or the same number (the CSV's "12.3400" is the record's 12.34).
void ExpectSameValue(const std::string& csv_field, const std::string& other, const std::string& where) {
  if (csv_field.empty() || other.empty()) {
    EXPECT_EQ(csv_field, other) << where;
    return;
  }
  char* end_a = nullptr;
  char* end_b = nullptr;
  const double a = std::strtod(csv_field.c_str(), &end_a);
  const double b = std::strtod(other.c_str(), &end_b);
  if (*end_a == '\0' && *end_b == '\0') {
    EXPECT_EQ(a, b) << where << ": " << csv_field << " vs " << other;
  } else {
    EXPECT_EQ(csv_field, other) << where;
  }
}

std::string JsonFieldText(const nlohmann::ordered_json& value) {
  if (value.is_null()) return "";
  if (value.is_string()) return value.get<std::string>();
  return value.dump();
}

// While `track` runs on the rendered bending scene, a raw subscriber and `listen --csv` each get
// every frame the CSV has, with the CSV's columns in order and its values, then the run's end.
TEST(Stream, TrackPublishesEveryCsvRowToTwoSubscribers) {
  TempDir dir;
  TrackOptions options = BendingRun(dir, "run.csv", 90);
  PublishOptions publish;
  publish.endpoint = "ipc://" + dir.file("s.ipc");
  publish.wait_subscribers = 2;  // Both connected before the first frame: they get every one.
  options.publish = publish;

  // Connected before the run binds: ZeroMQ connects as soon as the endpoint exists.
  StreamSubscriber records(publish.endpoint, {"hello", "frame", "end"}, "test");
  ListenOptions listen;
  listen.endpoint = publish.endpoint;
  listen.csv_file = dir.file("listened.csv");
  listen.quiet = true;
  listen.timeout_s = 60.0;
  std::ostringstream listen_out, listen_err;
  auto listened = std::async(std::launch::async, [&] { return RunListen(listen, listen_out, listen_err); });
  auto tracked = std::async(std::launch::async, [&] { return RunTrack(options); });

  std::optional<nlohmann::ordered_json> hello;
  std::vector<nlohmann::ordered_json> frames;
  bool ended = false;
  for (int waits = 0; !ended && waits < 600;) {
    const std::optional<StreamMessage> message = records.receive(100);
    if (!message) {
      ++waits;  // At most a minute of silence in all.
      continue;
    }
    const nlohmann::ordered_json body = nlohmann::ordered_json::parse(message->body);
    if (message->topic == "hello") hello = body;
    if (message->topic == "frame") frames.push_back(body);
    ended = message->topic == "end";
  }
  const RunSummary summary = tracked.get();
  const ListenSummary heard = listened.get();
  ASSERT_TRUE(ended) << "no end record";
  ASSERT_TRUE(hello.has_value());
  EXPECT_EQ((*hello)["version"], 1);
  EXPECT_EQ((*hello)["format"], "softsight-stream");
  EXPECT_EQ((*hello)["config_digest"].get<std::string>().size(), 16u);

  const std::vector<std::vector<std::string>> csv = ReadCsvCells(options.csv_file);
  ASSERT_EQ(summary.frames, 90);
  ASSERT_EQ(csv.size(), 91u);
  const std::vector<std::string>& header = csv[0];
  EXPECT_EQ((*hello)["columns"].get<std::vector<std::string>>(), header);
  ASSERT_EQ(frames.size(), 90u) << "every frame the CSV has";
  for (size_t r = 0; r < frames.size(); ++r) {
    std::vector<std::string> keys;
    for (const auto& item : frames[r].items()) keys.push_back(item.key());
    ASSERT_EQ(keys, header) << "record " << r;
    for (size_t c = 0; c < header.size(); ++c) {
      if (IsTiming(header[c])) continue;
      ExpectSameValue(csv[r + 1][c], JsonFieldText(frames[r][header[c]]),
                      "record " + std::to_string(r) + " " + header[c]);
    }
  }

  // `listen --csv`: the very rows, the CSV's own digits ("1.0000", not the JSON reader's "1.0"),
  // but for latency_row_ms: each output's own time to its row.
  EXPECT_TRUE(heard.ended);
  EXPECT_EQ(heard.records, 90);
  EXPECT_EQ(heard.frame_gaps, 0);
  const std::vector<std::vector<std::string>> copy = ReadCsvCells(listen.csv_file);
  ASSERT_EQ(copy.size(), csv.size());
  EXPECT_EQ(copy[0], header);
  for (size_t r = 1; r < csv.size(); ++r) {
    for (size_t c = 0; c < header.size(); ++c) {
      if (header[c] != "latency_row_ms") {
        EXPECT_EQ(csv[r][c], copy[r][c]) << "listened row " << r << " " << header[c];
      }
    }
  }
  // The end record says why the run stopped in the summary's words.
  const nlohmann::ordered_json end = nlohmann::ordered_json::parse(heard.end_record);
  EXPECT_EQ(end["stop_reason"], summary.stop_text());
  EXPECT_THAT(DescribeEndRecord(heard.end_record),
              HasSubstr("90 frames (" + summary.stop_text() + ")"));
  EXPECT_THAT(summary.BriefReport(), HasSubstr("90 frames (" + summary.stop_text() + ")"));
  EXPECT_THAT(summary.notes, ::testing::Contains(HasSubstr("none dropped")));
}

// Hostile trial D15: two runs started together on one ipc:// path both bound (ZeroMQ replaces a
// socket file), and one published to nobody. A lock beside the path decides, whatever the timing;
// the run leaves neither the socket file nor the lock behind.
// listen says how the run ended in the run's own words (the end record's stop_reason is the
// summary's), not as raw JSON.
TEST(Stream, ListenSaysTheEndInTheRunsWords) {
  EXPECT_EQ(DescribeEndRecord(R"({"frames":120,"stop_reason":"duration reached","error":"",)"
                              R"("sent":122,"dropped":0})"),
            "the run ended: 120 frames (duration reached), 122 messages sent, 0 dropped");
  EXPECT_EQ(DescribeEndRecord(R"({"frames":3,"stop_reason":"error","error":"a.avi: frame 3: )"
                              R"(cannot decode","sent":5,"dropped":1})"),
            "the run ended: 3 frames (error), 5 messages sent, 1 dropped; error: a.avi: frame 3: "
            "cannot decode");
  EXPECT_EQ(DescribeEndRecord("{\"x\":1}"), "the run ended: {\"x\":1}");
}

TEST(Stream, OneIpcPathIsOneRunsAndNothingOfItStaysBehind) {
  TempDir dir;
  PublishOptions publish;
  publish.endpoint = "ipc://" + dir.file("one.ipc");
  {
    PublishSink first(publish);
    try {
      PublishSink second(publish);
      ADD_FAILURE() << "two publishers bound one path";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("another program publishes on"));
    }
    EXPECT_TRUE(std::filesystem::exists(dir.file("one.ipc")));
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("one.ipc")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("one.ipc.lock")));
  PublishSink again(publish);  // Free again.
}

// Hostile trial D2: a peer that cancels subscriptions it never made (every topic, over and over)
// while a listener follows the run: the listener still gets every record.
TEST(Stream, HostilePeersChangeNothing) {
  TempDir dir;
  TrackOptions options = BendingRun(dir, "run.csv", 60);
  PublishOptions publish;
  publish.endpoint = "ipc://" + dir.file("h.ipc");
  publish.wait_subscribers = 1;
  options.publish = publish;

  zmq::context_t context;
  zmq::socket_t hostile(context, zmq::socket_type::xsub);
  hostile.set(zmq::sockopt::linger, 0);
  hostile.connect(publish.endpoint);
  ListenOptions listen;
  listen.endpoint = publish.endpoint;
  listen.quiet = true;
  listen.timeout_s = 60.0;
  std::ostringstream listen_out, listen_err;
  auto listened = std::async(std::launch::async, [&] { return RunListen(listen, listen_out, listen_err); });
  auto tracked = std::async(std::launch::async, [&] { return RunTrack(options); });
  // Cancels of every topic (XSUB: a leading 0 byte), sent until the run ends.
  while (tracked.wait_for(std::chrono::milliseconds(2)) != std::future_status::ready) {
    for (const char* topic : {"", "frame ", "hello ", "end ", "frame", "f"}) {
      (void)hostile.send(zmq::buffer(std::string(1, '\0') + topic), zmq::send_flags::dontwait);
    }
  }
  const RunSummary summary = tracked.get();
  const ListenSummary heard = listened.get();
  EXPECT_EQ(summary.frames, 60);
  EXPECT_TRUE(heard.ended);
  EXPECT_EQ(heard.records, 60) << "every record reached the listener";
  EXPECT_EQ(heard.frame_gaps, 0);
}

// A subscriber that stops reading (here: never reads) fills its queue; the run goes on with the
// same rows as a run without a stream, and the drops are counted in its summary.
TEST(Stream, StalledSubscriberLeavesTheRowsAndCountsDrops) {
  TempDir dir;
  const TrackOptions plain = BendingRun(dir, "plain.csv", 150);
  RunTrack(plain);

  TrackOptions options = BendingRun(dir, "published.csv", 150);
  PublishOptions publish;
  publish.endpoint = "ipc://" + dir.file("s.ipc");
  publish.wait_subscribers = 1;
  publish.high_water_mark = 1;
  publish.send_buffer_bytes = 2048;
  options.publish = publish;
  zmq::context_t context(1);
  zmq::socket_t stalled(context, zmq::socket_type::sub);
  stalled.set(zmq::sockopt::rcvhwm, 1);
  stalled.set(zmq::sockopt::rcvbuf, 2048);
  stalled.set(zmq::sockopt::linger, 0);
  stalled.set(zmq::sockopt::subscribe, "");  // Everything, hello included.
  stalled.connect(publish.endpoint);
  const RunSummary summary = RunTrack(options);

  const auto a = ReadCsvCells(plain.csv_file);
  const auto b = ReadCsvCells(options.csv_file);
  ASSERT_EQ(a.size(), 151u);
  ASSERT_EQ(b.size(), a.size());
  for (size_t r = 0; r < a.size(); ++r) {
    ASSERT_EQ(a[r].size(), b[r].size());
    for (size_t c = 0; c < a[r].size(); ++c) {
      if (!IsTiming(a[0][c])) {
        EXPECT_EQ(a[r][c], b[r][c]) << "row " << r << " " << a[0][c];
      }
    }
  }
  EXPECT_EQ(summary.frames, 150);
  EXPECT_THAT(summary.notes, ::testing::Contains(HasSubstr("dropped for a subscriber too slow")));
}

// A bad endpoint is one error line and exit 2, before anything is written; an ipc path that is
// a file is not replaced (ZeroMQ would delete it).
TEST(Stream, BadEndpointIsOneLineExit2AndNothingWritten) {
  TempDir dir;
  WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  WriteTextFile(dir.file("keep.txt"), "a lab's notes\n");
  const std::string track =
      "track -c " + dir.file("markers.yaml") + " -i synth:bending -o " + dir.file("out.csv");
  for (const std::string& endpoint :
       {std::string("udp://1.2.3.4:5"), std::string("tcp://no.such.interface.invalid:5556"),
        "ipc://" + dir.file("keep.txt")}) {
    const ProgramRun run = RunProgram(track + " --publish " + endpoint, dir);
    EXPECT_EQ(run.exit_code, 2) << endpoint;
    EXPECT_THAT(run.stderr_text, HasSubstr("--publish " + endpoint));
    EXPECT_EQ(std::count(run.stderr_text.begin(), run.stderr_text.end(), '\n'), 1) << run.stderr_text;
    EXPECT_FALSE(std::filesystem::exists(dir.file("out.csv"))) << endpoint;
  }
  EXPECT_EQ(ReadTextFile(dir.file("keep.txt")), "a lab's notes\n");
  // A host name is this machine's address (ZeroMQ binds to interfaces and addresses only).
  const ProgramRun localhost = RunProgram(track + " --publish tcp://localhost:*", dir);
  EXPECT_EQ(localhost.exit_code, 0) << localhost.stderr_text;
  const ProgramRun listen = RunProgram("listen udp://1.2.3.4:5", dir);
  EXPECT_EQ(listen.exit_code, 2);
  EXPECT_THAT(listen.stderr_text, HasSubstr("udp://1.2.3.4:5"));
}

// Ctrl-C or SIGTERM while a run waits for its subscribers (--publish-wait): the run stops as
// any stop asks (exit 128 + signal, "stopped by"), not "internal error: Interrupted system call".
TEST(Stream, ASignalDuringThePublishWaitStopsTheRunAsAskedNotAsAnError) {
  TempDir dir;
  WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  const std::string csv = dir.file("run.csv");
  const int status = testing::RunAndSignalOnceRowsAreWritten(
      "track -c " + dir.file("markers.yaml") + " -i synth:bending -o " + csv +
          " --publish ipc://" + dir.file("w.ipc") + " --publish-wait 1 --publish-wait-s 120",
      csv, 1, SIGTERM, dir.file("err.txt"));
  const std::string err = ReadTextFile(dir.file("err.txt"));
  ASSERT_TRUE(WIFEXITED(status)) << err;
  EXPECT_EQ(WEXITSTATUS(status), 143) << err;
  EXPECT_THAT(err, HasSubstr("stopped by SIGTERM"));
  EXPECT_THAT(err, ::testing::Not(HasSubstr("error")));
}

// What `listen` makes of a hostile or broken publisher (hostile trial D13): `messages` repeated
// until listen returns; its error, or "" when it ended normally.
std::string ListenTo(const std::vector<std::string>& messages, const TempDir& dir,
                     const std::string& csv = "", ListenSummary* summary = nullptr) {
  zmq::context_t context;
  zmq::socket_t pub(context, zmq::socket_type::pub);
  pub.set(zmq::sockopt::linger, 0);
  const std::string endpoint = "ipc://" + dir.file("hostile.ipc");
  pub.bind(endpoint);
  ListenOptions listen;
  listen.endpoint = endpoint;
  listen.csv_file = csv;
  listen.count = 2;
  listen.quiet = true;
  std::ostringstream out, err;
  auto listened = std::async(std::launch::async, [&] { return RunListen(listen, out, err); });
  // Sent over and over until listen has what it takes (a subscription needs a moment to arrive;
  // the loop's pace decides nothing).
  while (listened.wait_for(std::chrono::milliseconds(5)) != std::future_status::ready) {
    for (const std::string& m : messages) pub.send(zmq::buffer(m), zmq::send_flags::dontwait);
  }
  try {
    const ListenSummary got = listened.get();
    if (summary) *summary = got;
    return "";
  } catch (const InputError& e) {
    return e.what();
  }
}

TEST(Stream, ListenRefusesWhatNoSoftsightRunSendsAndNeverForgesACsvRow) {
  TempDir dir;
  const std::string hello =
      R"(hello {"format":"softsight-stream","version":1,"source":"x","config":"c.yaml",)"
      R"("config_digest":"0","columns":["frame","time_s","red_status"]})";
  // A number where the hello has text: one error line, not "internal error: type_error".
  EXPECT_THAT(ListenTo({R"(hello {"format":"softsight-stream","version":1,"source":5})"}, dir),
              HasSubstr("hello has a source that is not text"));
  // A version beyond an int is not read modulo 2^32.
  EXPECT_THAT(ListenTo({R"(hello {"format":"softsight-stream","version":4294967297})"}, dir),
              HasSubstr("version 4294967297"));
  // A status with a line break or a comma would forge or shift rows: refused, the CSV unwritten
  // past its rows so far.
  const std::string csv = dir.file("l.csv");
  EXPECT_THAT(ListenTo({hello, R"(frame {"frame":0,"time_s":0,"red_status":"found\n666,1e9,evil"})"},
                       dir, csv),
              HasSubstr("\"red_status\" is text with a comma"));
  if (std::filesystem::exists(csv)) {
    for (const std::string& line : ReadLines(csv)) EXPECT_THAT(line, ::testing::Not(HasSubstr("evil")));
  }
  // Records before any hello are left out (counted), the ones after it taken.
  ListenSummary summary;
  EXPECT_EQ(ListenTo({R"(frame {"frame":0,"time_s":0,"red_status":"found"})", hello,
                      R"(frame {"frame":1,"time_s":0.1,"red_status":"found"})"},
                     dir, "", &summary),
            "");
  EXPECT_EQ(summary.records, 2);
  EXPECT_GT(summary.before_hello, 0);
}

// `control --target-from`: the first target arrives, then the source says nothing more. The loop
// follows it, and once the source has been silent for controller.target_silence_s (0.5 s of the
// frames' clock) it vents, frame after frame, and says so in the summary.
TEST(Stream, TargetFromVentsWhenTheSourceFallsSilent) {
  TempDir dir;
  WriteTextFile(dir.file("rig.yaml"), testing::kSceneMarkersYaml);
  const std::string endpoint = "ipc://" + dir.file("t.ipc");
  zmq::context_t context(1);
  zmq::socket_t targets(context, zmq::socket_type::xpub);  // Sees the control subscribe.
  targets.set(zmq::sockopt::linger, 0);
  targets.bind(endpoint);

  ControlOptions options;
  options.config_file = dir.file("rig.yaml");
  options.simulate = true;
  options.target_from = endpoint;
  options.target_wait_s = 60.0;
  options.duration_s = 2.0;
  options.csv_file = dir.file("run.csv");
  options.quiet = true;
  auto controlled = std::async(std::launch::async, [&] { return RunControl(options); });

  zmq::pollitem_t item{targets.handle(), 0, ZMQ_POLLIN, 0};
  ASSERT_EQ(zmq::poll(&item, 1, std::chrono::seconds(60)), 1) << "control never subscribed";
  zmq::message_t subscription;
  ASSERT_TRUE(targets.recv(subscription));
  EXPECT_EQ(subscription.to_string(), std::string("\x01") + "target ");
  targets.send(zmq::str_buffer("target {\"angle_deg\": 150}"));
  const ControlSummary summary = controlled.get();

  const auto csv = ReadCsvCells(options.csv_file);
  ASSERT_GT(csv.size(), 50u);
  const auto column = [&](const std::string& name) {
    return static_cast<size_t>(std::find(csv[0].begin(), csv[0].end(), name) - csv[0].begin());
  };
  const size_t time = column("time_s"), target = column("target_deg"), action = column("control_action");
  ASSERT_LT(action, csv[0].size());
  int followed = 0, vented = 0;
  for (size_t r = 1; r < csv.size(); ++r) {
    const double t = std::stod(csv[r][time]);
    if (t < 0.49) {
      EXPECT_EQ(csv[r][target], "150") << "row " << r;
      EXPECT_NE(csv[r][action], "2") << "row " << r;
      ++followed;
    } else if (t > 0.51) {
      EXPECT_EQ(csv[r][action], "2") << "row " << r << ": silent for " << t << " s";
      EXPECT_EQ(csv[r][target], "") << "row " << r;
      ++vented;
    }
  }
  EXPECT_GT(followed, 10);
  EXPECT_GT(vented, 30);
  EXPECT_THAT(summary.notes, ::testing::Contains(HasSubstr("went silent")));
}

}  // namespace
}  // namespace softsight
