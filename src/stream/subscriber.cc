#include "stream/subscriber.h"

#include <cerrno>
#include <chrono>

#include <zmq.hpp>

#include "stream/endpoint.h"

namespace softsight {

StreamSubscriber::StreamSubscriber(const std::string& endpoint,
                                   const std::vector<std::string>& topics,
                                   const std::string& option, int64_t max_message_bytes) {
  context_ = std::make_unique<zmq::context_t>(1);
  socket_ = std::make_unique<zmq::socket_t>(*context_, zmq::socket_type::sub);
  socket_->set(zmq::sockopt::linger, 0);
  socket_->set(zmq::sockopt::maxmsgsize, max_message_bytes);
  for (const std::string& topic : topics) socket_->set(zmq::sockopt::subscribe, topic + ' ');
  ConnectOrThrow(*socket_, endpoint, option);
}

StreamSubscriber::~StreamSubscriber() = default;

std::optional<StreamMessage> StreamSubscriber::receive(int timeout_ms) {
  zmq::message_t message;
  try {
    if (timeout_ms > 0) {
      zmq::pollitem_t item{socket_->handle(), 0, ZMQ_POLLIN, 0};
      if (zmq::poll(&item, 1, std::chrono::milliseconds(timeout_ms)) == 0) return std::nullopt;
    }
    if (!socket_->recv(message, zmq::recv_flags::dontwait)) return std::nullopt;
  } catch (const zmq::error_t& e) {
    // A signal (Ctrl-C, SIGTERM) interrupted the wait: nothing received; the caller asks
    // whether to stop.
    if (e.num() == EINTR) return std::nullopt;
    throw;
  }
  const std::string text = message.to_string();
  const size_t space = text.find(' ');
  if (space == std::string::npos) return StreamMessage{text, ""};
  return StreamMessage{text.substr(0, space), text.substr(space + 1)};
}

}  // namespace softsight
