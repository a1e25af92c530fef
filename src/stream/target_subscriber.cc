#include "stream/target_subscriber.h"

#include <chrono>

#include <nlohmann/json.hpp>

#include "stream/stream_format.h"

namespace softsight {
namespace {

constexpr int kPollSliceMs = 50;
// A target message is a few dozen bytes; a larger one is refused unread.
constexpr int64_t kMaxMessageBytes = 4096;

}  // namespace

std::optional<double> ParseTargetBody(const std::string& body, std::string* problem) {
  const nlohmann::json parsed = nlohmann::json::parse(body, nullptr, /*allow_exceptions=*/false);
  if (parsed.is_discarded() || !parsed.is_object()) {
    *problem = "not a JSON object: \"" + body.substr(0, 60) + "\"";
    return std::nullopt;
  }
  const auto angle = parsed.find("angle_deg");
  if (angle == parsed.end() || !angle->is_number()) {
    *problem = "no number angle_deg in " + parsed.dump().substr(0, 60);
    return std::nullopt;
  }
  return angle->get<double>();
}

TargetSubscriber::TargetSubscriber(const std::string& endpoint)
    : endpoint_(endpoint),
      subscriber_(endpoint, {kTargetTopic}, "--target-from", kMaxMessageBytes) {}

void TargetSubscriber::take(const StreamMessage& message, ReceivedTargets& received) {
  ++received.messages;
  std::string problem;
  if (const std::optional<double> deg = ParseTargetBody(message.body, &problem)) {
    received.newest_deg = deg;
  } else {
    if (received.malformed == 0) received.first_problem = problem;
    ++received.malformed;
  }
}

ReceivedTargets TargetSubscriber::poll() {
  ReceivedTargets received;
  while (const std::optional<StreamMessage> message = subscriber_.receive(0)) take(*message, received);
  return received;
}

ReceivedTargets TargetSubscriber::wait(double timeout_s,
                                       const std::function<bool()>& stop_requested) {
  ReceivedTargets received;
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!received.newest_deg && std::chrono::steady_clock::now() < deadline &&
         !(stop_requested && stop_requested())) {
    if (const std::optional<StreamMessage> message = subscriber_.receive(kPollSliceMs)) {
      take(*message, received);
    }
  }
  // Targets already queued behind the first: the newest wins.
  while (const std::optional<StreamMessage> message = subscriber_.receive(0)) take(*message, received);
  return received;
}

}  // namespace softsight
