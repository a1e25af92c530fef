// `--publish ENDPOINT` (track, live, control, identify): every frame's result, as it happens, to
// other programs on a ZeroMQ XPUB socket, in the records of stream/stream_format.h
// (docs/stream.md). The program's own (not installed): libzmq stays out of the library.
//
// A slow or absent subscriber never slows the run: sends never block. Each subscriber has a
// queue of `high_water_mark` messages; a message that would overflow a queue is counted as a
// drop (the subscribers with room still get it), and the run's summary says how many.
// An XPUB socket (not a PUB) sees each subscription arrive: a new subscriber to "hello" gets
// the run's hello at once, however late it joins, and topics nobody asked for are not even
// formatted.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "softsight/io/csv_columns.h"
#include "softsight/pipeline/sink.h"
#include "stream/stream_format.h"

namespace zmq {
class context_t;
class socket_t;
}  // namespace zmq

namespace softsight {

struct PublishOptions {
  // Where subscribers connect: tcp://*:5556 (every interface), tcp://127.0.0.1:5556 (this
  // machine only), ipc:///tmp/softsight.ipc (a socket file; never replaces a file that is not
  // a socket, nor one another program listens on).
  std::string endpoint;
  // Messages queued per subscriber before further ones are dropped (ZMQ_SNDHWM). Default 1000:
  // about 6 s of every topic (5 a frame) of a 3-marker run at 30 fps. Range 1..1000000.
  int high_water_mark = 1000;
  // Before the first frame, wait until this many subscriptions to "hello" have arrived
  // (softsight listen and softsight.stream.subscribe each make one), so that they see every
  // frame. 0 (default): start at once.
  int wait_subscribers = 0;
  // How long that wait may take, s; then the run stops with an error. Default 30.
  double wait_timeout_s = 30.0;
  // Asked while waiting: true ends the wait at once (Ctrl-C, SIGTERM), and the run then stops
  // before its first frame as a stop asks. Empty: never.
  std::function<bool()> stop_requested;
  // The hello's config_digest (Fnv1a64Hex of the config file's bytes) and config file name.
  std::string config_digest;
  std::string config_file;
  // The kernel's send buffer per connection, bytes (ZMQ_SNDBUF); 0: the system's default. Tests
  // make it small, so that a subscriber that stops reading fills its queue quickly.
  int send_buffer_bytes = 0;

  // Returns false and names the bad field.
  bool Check(std::string* error) const;
};

class PublishSink : public FrameSink {
 public:
  // Binds at once: a malformed or busy endpoint throws InputError naming it (--publish ...),
  // before the caller opens any output.
  explicit PublishSink(PublishOptions options);
  ~PublishSink() override;
  PublishSink(const PublishSink&) = delete;
  PublishSink& operator=(const PublishSink&) = delete;

  // The columns of every record: the CSV's table (by value; the same closures write both).
  // Before begin().
  void set_columns(CsvColumnTable columns) { columns_ = std::move(columns); }
  // Instead, rows of another table (track-stereo's StereoColumns), published by publish_row():
  // its column names, and the suffixes of a marker's columns (its marker/<name> topic). Before
  // begin().
  void set_row_columns(std::vector<std::string> names, std::vector<std::string> marker_suffixes);
  // One row of that table as its CSV text (fields separated by commas; no field holds one):
  // the records of the topics someone subscribed to. Between begin() and end().
  void publish_row(std::string_view csv_row);

  // Learns the markers (the topics), then waits for PublishOptions::wait_subscribers.
  void begin(const RunInfo& info) override;
  void consume(const Frame& frame, const FrameResult& result) override;
  // The "end" record: frames, why the run stopped, messages sent and dropped.
  void end(const RunSummary& summary) override;
  // A note: the endpoint, messages sent, subscriptions seen and messages dropped.
  void report(RunSummary& summary) const override;
  bool uses_image() const override { return false; }  // Rows only.

  // The endpoint as bound (a tcp port given as * is the one chosen).
  const std::string& endpoint() const { return bound_endpoint_; }
  int64_t sent() const { return sent_; }        // Messages handed to ZeroMQ.
  int64_t dropped() const { return dropped_; }  // Of those, missed by at least one subscriber.

 private:
  // Reads the subscriptions that arrived; a new one to "hello" gets the hello.
  void read_subscriptions();
  // Sends without blocking; a full queue counts a drop (the others still get the message).
  void send(const std::string& message);
  std::string hello() const;
  bool wanted(const std::string& topic) const;

  PublishOptions options_;
  CsvColumnTable columns_;
  RecordFormatter formatter_;
  // set_row_columns(): the table's names (empty: `columns_` is the table) and marker suffixes;
  // publish_row()'s fields, reused.
  std::vector<std::string> row_names_, row_marker_suffixes_;
  std::vector<std::string_view> row_fields_;
  std::unique_ptr<zmq::context_t> context_;
  std::unique_ptr<zmq::socket_t> socket_;
  std::string bound_endpoint_;
  // ipc:// only: the socket file (removed at the end) and the lock held beside it while bound.
  std::string ipc_path_, lock_path_;
  int lock_fd_ = -1;
  bool lock_made_ = false;
  // Lets go of the lock beside an ipc:// path (and removes it when this run made it).
  void release_lock();
  RunInfo info_;
  std::vector<TopicColumns> topics_;
  std::vector<char> topic_wanted_;         // Per topic: some subscription matches it.
  // Prefix -> how many subscriptions asked for it (cancellations are not counted: see the .cc).
  std::map<std::string, int> subscriptions_;
  int64_t subscriptions_seen_ = 0;
  std::string message_;                    // Reused: no allocation per record once grown.
  int64_t sent_ = 0, dropped_ = 0;
  std::vector<double> send_latency_ms_;
};

// The stream of a step whose rows are not one view's FrameResult (a pair's StereoFrameResult):
// each row as its CSV table writes it, published through `publish` (set_row_columns /
// publish_row), which this sink begins, ends and reports as the run does. So the stream of any
// run is the CSV's columns, whatever its step.
template <typename Input, typename Row>
class PublishRowsSink : public BasicFrameSink<Input, Row> {
 public:
  // `marker_suffixes`: the suffixes of a marker's columns (its marker/<name> topic).
  PublishRowsSink(PublishSink& publish, BasicCsvColumnTable<Row> columns,
                  std::vector<std::string> marker_suffixes)
      : publish_(publish), columns_(std::move(columns)) {
    publish_.set_row_columns(columns_.names(), std::move(marker_suffixes));
  }
  void begin(const RunInfo& info) override { publish_.begin(info); }
  bool uses_image() const override { return false; }
  void consume(const Input& input, const Row& row) override {
    (void)input;
    columns_.append_row(row, text_);
    publish_.publish_row(text_);
  }
  void end(const RunSummary& summary) override { publish_.end(summary); }
  void report(RunSummary& summary) const override { publish_.report(summary); }

 private:
  PublishSink& publish_;
  BasicCsvColumnTable<Row> columns_;
  std::string text_;  // Reused: no allocation per row once grown.
};

}  // namespace softsight
