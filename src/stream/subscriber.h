// The receiving end of a stream (docs/stream.md): a ZeroMQ SUB socket connected to an endpoint,
// taking the given topics. `softsight listen` reads records with it, `control --target-from`
// targets (stream/target_subscriber.h).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace zmq {
class context_t;
class socket_t;
}  // namespace zmq

namespace softsight {

// One message, split at its first space: "frame {...}" -> {"frame", "{...}"}.
struct StreamMessage {
  std::string topic;
  std::string body;
};

class StreamSubscriber {
 public:
  // Connects (in the background: the publisher may start later) and subscribes to each topic
  // exactly ("<topic> "). `option` names the endpoint's option in errors (a malformed one throws
  // InputError). Messages larger than `max_message_bytes` are refused unread.
  StreamSubscriber(const std::string& endpoint, const std::vector<std::string>& topics,
                   const std::string& option, int64_t max_message_bytes = -1);
  ~StreamSubscriber();
  StreamSubscriber(const StreamSubscriber&) = delete;
  StreamSubscriber& operator=(const StreamSubscriber&) = delete;

  // The next message, waiting at most `timeout_ms` (0: only one already there).
  std::optional<StreamMessage> receive(int timeout_ms);

 private:
  std::unique_ptr<zmq::context_t> context_;
  std::unique_ptr<zmq::socket_t> socket_;
};

}  // namespace softsight
