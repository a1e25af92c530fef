// ZeroMQ endpoints as the user gives them (--publish, --target-from, listen): checked, bound or
// connected, every failure one InputError naming the option and the endpoint.
#pragma once

#include <string>

#include <zmq.hpp>

namespace softsight {

// Binds `socket` to `endpoint` (tcp://HOST:PORT, tcp://*:PORT, ipc://PATH). An ipc path that
// exists is replaced only when it is a socket nobody listens on (a stale one): ZeroMQ would
// otherwise delete whatever file is there. Returns the endpoint as bound (ZMQ_LAST_ENDPOINT).
std::string BindOrThrow(zmq::socket_t& socket, const std::string& endpoint,
                        const std::string& option);
// Connects `socket` to `endpoint` (tcp://HOST:PORT, ipc://PATH); the connection itself is made
// (and remade) in the background, so only a malformed endpoint fails here.
void ConnectOrThrow(zmq::socket_t& socket, const std::string& endpoint, const std::string& option);

}  // namespace softsight
