#include "stream/publish_sink.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>
#include <zmq.hpp>

#include "softsight/core/error.h"
#include "softsight/pipeline/summary.h"
#include "stream/endpoint.h"

namespace softsight {
namespace {

// At the end, how long queued messages may still take to reach their subscribers before the
// socket closes: the "end" record reaches a reading subscriber, a stalled one cannot hold the
// program's exit longer.
constexpr int kLingerMs = 1000;
// The wait for subscribers polls the socket this often (to send each new one the hello).
constexpr int kWaitPollMs = 50;

// The largest subscription message read (bytes), and the most distinct prefixes remembered.
constexpr int kMaxSubscriptionBytes = 1024;
constexpr size_t kMaxSubscriptionPrefixes = 4096;

bool Matches(const std::string& prefix, const std::string& topic) {
  // A message is "<topic> {...}": a subscription matches when it is a prefix of that.
  const std::string head = topic + ' ';
  return head.rfind(prefix, 0) == 0 || prefix.rfind(head, 0) == 0;
}

}  // namespace

bool PublishOptions::Check(std::string* error) const {
  if (endpoint.empty()) {
    *error = "endpoint: empty (give tcp://*:PORT, tcp://HOST:PORT or ipc://PATH)";
  } else if (high_water_mark < 1 || high_water_mark > 1000000) {
    *error = "high_water_mark " + std::to_string(high_water_mark) + ": must be in 1..1000000";
  } else if (wait_subscribers < 0 || wait_subscribers > 1000) {
    *error = "wait_subscribers " + std::to_string(wait_subscribers) + ": must be in 0..1000";
  } else if (!(wait_timeout_s > 0.0 && wait_timeout_s <= 86400.0)) {
    *error = "wait_timeout_s: must be in (0, 86400]";
  } else if (send_buffer_bytes < 0) {
    *error = "send_buffer_bytes: must be 0 or more";
  } else {
    return true;
  }
  return false;
}

PublishSink::PublishSink(PublishOptions options)
    : options_(std::move(options)), formatter_(columns_) {
  if (std::string problem; !options_.Check(&problem)) throw InputError("--publish: " + problem);
  context_ = std::make_unique<zmq::context_t>(1);
  socket_ = std::make_unique<zmq::socket_t>(*context_, zmq::socket_type::xpub);
  socket_->set(zmq::sockopt::sndhwm, options_.high_water_mark);
  socket_->set(zmq::sockopt::linger, kLingerMs);
  if (options_.send_buffer_bytes > 0) socket_->set(zmq::sockopt::sndbuf, options_.send_buffer_bytes);
  // Every subscription reaches read_subscriptions(), also a second subscriber to a topic someone
  // already has (it needs its own hello). Cancellations are not read: ZeroMQ passes on a cancel
  // from a peer that never subscribed as readily as a real one, and one shared count would let
  // any peer stop the topics of all (ZeroMQ's own filter is per subscriber, and stays right).
  socket_->set(zmq::sockopt::xpub_verbose, 1);
  // A subscription is a topic's prefix, a few bytes: a larger message from a peer is dropped
  // with its connection (a 6 MB subscription grew the publisher by 200 MB).
  socket_->set(zmq::sockopt::maxmsgsize, int64_t{kMaxSubscriptionBytes});
  // A full queue refuses the message (counted) instead of losing it silently; send() then hands
  // it to the subscribers with room.
  socket_->set(zmq::sockopt::xpub_nodrop, 1);
  // A socket file is claimed with a lock beside it before the bind: ZeroMQ replaces a socket
  // file when it binds, so two runs started together on one path both bound, and one published to
  // nobody. The lock makes the second one's refusal certain, not a matter of timing.
  if (options_.endpoint.rfind("ipc://", 0) == 0) {
    const std::string path = options_.endpoint.substr(6);
    if (!path.empty() && path != "*" && path[0] != '@') {
      lock_path_ = path + ".lock";
      // Removed at the end only when this run made it: a file of that name is someone's.
      lock_fd_ = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
      lock_made_ = lock_fd_ >= 0;
      if (!lock_made_) lock_fd_ = ::open(lock_path_.c_str(), O_RDONLY | O_CLOEXEC);
      if (lock_fd_ >= 0 && ::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
        release_lock();
        throw InputError("--publish " + options_.endpoint + ": another program publishes on " +
                         path + " (another softsight run?); choose another path");
      }
    }
  }
  try {
    bound_endpoint_ = BindOrThrow(*socket_, options_.endpoint, "--publish");
  } catch (...) {
    release_lock();
    throw;
  }
  ipc_path_ = lock_path_.empty() ? "" : options_.endpoint.substr(6);
}

PublishSink::~PublishSink() {
  // The socket first (its queued messages get their linger), then the socket file and the lock:
  // nothing of the run is left on the disk.
  socket_.reset();
  if (!ipc_path_.empty()) ::unlink(ipc_path_.c_str());
  release_lock();
}

void PublishSink::release_lock() {
  if (lock_fd_ < 0) return;
  if (lock_made_) ::unlink(lock_path_.c_str());
  ::close(lock_fd_);
  lock_fd_ = -1;
}

std::string PublishSink::hello() const {
  nlohmann::ordered_json hello;
  hello["format"] = kStreamFormatName;
  hello["version"] = kStreamFormatVersion;
  hello["source"] = info_.source;
  hello["config"] = options_.config_file;
  hello["config_digest"] = options_.config_digest;
  hello["fps"] = info_.fps ? nlohmann::ordered_json(*info_.fps) : nlohmann::ordered_json();
  hello["frame_count"] =
      info_.frame_count ? nlohmann::ordered_json(*info_.frame_count) : nlohmann::ordered_json();
  hello["live"] = info_.live;
  hello["markers"] = info_.marker_names;
  hello["columns"] = row_names_.empty() ? columns_.names() : row_names_;
  nlohmann::ordered_json topics = nlohmann::ordered_json::array();
  topics.push_back(kHelloTopic);
  for (const TopicColumns& topic : topics_) topics.push_back(topic.topic);
  topics.push_back(kEndTopic);
  hello["topics"] = topics;
  return std::string(kHelloTopic) + ' ' + hello.dump();
}

bool PublishSink::wanted(const std::string& topic) const {
  return std::any_of(subscriptions_.begin(), subscriptions_.end(),
                     [&](const auto& entry) { return Matches(entry.first, topic); });
}

void PublishSink::read_subscriptions() {
  zmq::message_t message;
  bool changed = false, send_hello = false;
  while (socket_->recv(message, zmq::recv_flags::dontwait)) {
    // XPUB hands each (un)subscription over as one byte (1 subscribe, 0 unsubscribe) + prefix.
    if (message.size() == 0) continue;
    const auto* bytes = static_cast<const char*>(message.data());
    const std::string prefix(bytes + 1, message.size() - 1);
    if (bytes[0] != 1) continue;  // A cancellation (see the constructor).
    ++subscriptions_seen_;
    send_hello = send_hello || Matches(prefix, kHelloTopic);
    // Distinct prefixes are remembered up to a bound (what the run's topics can match is a few
    // hundred): a flood of distinct ones costs the loop nothing more.
    const auto it = subscriptions_.find(prefix);
    if (it != subscriptions_.end()) {
      ++it->second;
    } else if (subscriptions_.size() < kMaxSubscriptionPrefixes) {
      subscriptions_.emplace(prefix, 1);
      changed = true;
    }
  }
  if (changed) {
    topic_wanted_.assign(topics_.size(), 0);
    for (size_t i = 0; i < topics_.size(); ++i) topic_wanted_[i] = wanted(topics_[i].topic);
  }
  // Every subscriber to hello gets it again: each new one needs it, the others ignore repeats.
  if (send_hello) send(hello());
}

void PublishSink::send(const std::string& message) {
  ++sent_;
  if (socket_->send(zmq::buffer(message), zmq::send_flags::dontwait)) return;
  // Some subscriber's queue is full: it misses this message (counted); the others get it.
  ++dropped_;
  socket_->set(zmq::sockopt::xpub_nodrop, 0);
  (void)socket_->send(zmq::buffer(message), zmq::send_flags::dontwait);
  socket_->set(zmq::sockopt::xpub_nodrop, 1);
}

void PublishSink::begin(const RunInfo& info) {
  info_ = info;
  topics_ = row_names_.empty()
                ? StreamTopics(columns_, info.marker_names)
                : StreamTopics(row_names_, info.marker_names, row_marker_suffixes_);
  topic_wanted_.assign(topics_.size(), 0);
  if (info.frame_count) {
    send_latency_ms_.reserve(static_cast<size_t>(std::clamp<int64_t>(*info.frame_count, 0, int64_t{1} << 22)));
  }
  read_subscriptions();
  if (options_.wait_subscribers == 0) return;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(options_.wait_timeout_s);
  const auto hello_subscribers = [this] {
    int count = 0;
    for (const auto& [prefix, n] : subscriptions_) count += Matches(prefix, kHelloTopic) ? n : 0;
    return count;
  };
  while (hello_subscribers() < options_.wait_subscribers) {
    if (options_.stop_requested && options_.stop_requested()) return;
    if (std::chrono::steady_clock::now() >= deadline) {
      throw InputError("--publish " + options_.endpoint + ": " +
                       std::to_string(hello_subscribers()) + " of " +
                       std::to_string(options_.wait_subscribers) + " subscribers within " +
                       std::to_string(static_cast<int>(std::ceil(options_.wait_timeout_s))) +
                       " s (--publish-wait); start them first, or give --publish-wait 0");
    }
    zmq::pollitem_t item{socket_->handle(), 0, ZMQ_POLLIN, 0};
    try {
      zmq::poll(&item, 1, std::chrono::milliseconds(kWaitPollMs));
    } catch (const zmq::error_t& e) {
      if (e.num() != EINTR) throw;  // A signal: the loop asks whether to stop.
    }
    read_subscriptions();
  }
}

void PublishSink::consume(const Frame& frame, const FrameResult& result) {
  (void)frame;
  read_subscriptions();
  for (size_t i = 0; i < topics_.size(); ++i) {
    if (!topic_wanted_[i]) continue;
    formatter_.format(topics_[i], result, message_);
    send(message_);
    if (i == 0 && result.captured != std::chrono::steady_clock::time_point{}) {
      send_latency_ms_.push_back(std::chrono::duration<double, std::milli>(
                                     std::chrono::steady_clock::now() - result.captured)
                                     .count());
    }
  }
}

void PublishSink::set_row_columns(std::vector<std::string> names,
                                  std::vector<std::string> marker_suffixes) {
  row_names_ = std::move(names);
  row_marker_suffixes_ = std::move(marker_suffixes);
}

void PublishSink::publish_row(std::string_view csv_row) {
  read_subscriptions();
  row_fields_.clear();
  for (size_t start = 0;;) {
    const size_t comma = csv_row.find(',', start);
    row_fields_.push_back(csv_row.substr(start, comma == std::string_view::npos
                                                    ? std::string_view::npos
                                                    : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  for (size_t i = 0; i < topics_.size(); ++i) {
    if (!topic_wanted_[i]) continue;
    FormatRecord(topics_[i], row_names_, row_fields_, message_);
    send(message_);
  }
}

void PublishSink::end(const RunSummary& summary) {
  read_subscriptions();
  nlohmann::ordered_json end;
  end["frames"] = summary.frames;
  end["stop_reason"] = summary.stop_text();  // The printed summary's words (RunOptions::describe_stop).
  end["error"] = summary.error;
  end["sent"] = sent_ + 1;  // This record too.
  end["dropped"] = dropped_;
  send(std::string(kEndTopic) + ' ' + end.dump());
}

void PublishSink::report(RunSummary& summary) const {
  std::string note = "--publish " + bound_endpoint_ + ": messages sent " + std::to_string(sent_) +
                     ", subscriptions " + std::to_string(subscriptions_seen_);
  if (dropped_ > 0) {
    note += "; " + std::to_string(dropped_) + " of them dropped for a subscriber too slow to read (its queue of " +
            std::to_string(options_.high_water_mark) + " was full)";
  } else {
    note += ", none dropped";
  }
  if (!send_latency_ms_.empty()) {
    std::vector<double> sorted = send_latency_ms_;
    double median = 0.0, p99 = 0.0;
    SummariseTimes(sorted, &median, &p99);
    char figures[96];
    std::snprintf(figures, sizeof(figures), "; frame record sent %.3f / %.3f ms after capture (median / p99)",
                  median, p99);
    note += figures;
  }
  summary.notes.push_back(note);
}

}  // namespace softsight
