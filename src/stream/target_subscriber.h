// `control --target-from ENDPOINT`: target angles from another program (an experiment script, a
// learning controller) on a ZeroMQ SUB socket. Messages: "target {"angle_deg": 120}" (topic
// "target", docs/stream.md). This class only receives and parses; whether a target is used
// (range, the actuator's reach, how fast it may move, silence) is the control command's
// (app/target_feed.h).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "stream/subscriber.h"

namespace softsight {

// What arrived since the last poll.
struct ReceivedTargets {
  std::optional<double> newest_deg;  // The last well-formed target (earlier ones are superseded).
  int64_t messages = 0;              // Messages on the "target" topic, well-formed or not.
  int64_t malformed = 0;             // Of those, not {"angle_deg": <number>}.
  std::string first_problem;         // Why the first malformed one was, for the summary.
};

class TargetSubscriber {
 public:
  // Connects (in the background: the publisher may start later). Throws InputError naming
  // --target-from for a malformed endpoint.
  explicit TargetSubscriber(const std::string& endpoint);

  // Every message waiting, without blocking.
  ReceivedTargets poll();
  // Blocks until a well-formed target arrives, at most `timeout_s`, calling `stop_requested`
  // every 50 ms (true: gives up). Returns what arrived (newest_deg empty: none in time).
  ReceivedTargets wait(double timeout_s, const std::function<bool()>& stop_requested);

  const std::string& endpoint() const { return endpoint_; }

 private:
  void take(const StreamMessage& message, ReceivedTargets& received);

  std::string endpoint_;
  StreamSubscriber subscriber_;
};

// Parses a target message's body ({"angle_deg": 120}). Returns the angle, or nullopt with
// `problem` set.
std::optional<double> ParseTargetBody(const std::string& body, std::string* problem);

}  // namespace softsight
