#include "stream/endpoint.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>

#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr char kForms[] = "give tcp://*:PORT, tcp://HOST:PORT or ipc://PATH";

bool StartsWith(const std::string& s, const char* prefix) {
  return s.rfind(prefix, 0) == 0;
}

void CheckScheme(const std::string& endpoint, const std::string& option) {
  if (!StartsWith(endpoint, "tcp://") && !StartsWith(endpoint, "ipc://")) {
    throw InputError(option + " " + endpoint + ": not an endpoint; " + kForms);
  }
  if (!StartsWith(endpoint, "tcp://")) return;
  // ZeroMQ takes a port beyond 65535 modulo 65536: another port than the one asked for.
  const size_t colon = endpoint.rfind(':');
  const std::string port = colon == std::string::npos ? "" : endpoint.substr(colon + 1);
  const bool digits = !port.empty() && port.size() <= 5 &&
                      port.find_first_not_of("0123456789") == std::string::npos;
  if (port != "*" && (!digits || std::stoi(port) < 1 || std::stoi(port) > 65535)) {
    throw InputError(option + " " + endpoint + ": the port must be 1..65535 (or * for any free "
                     "one); " + kForms);
  }
}

// Whether a program accepts connections on the unix socket at `path`.
bool SomeoneListens(const std::string& path) {
  sockaddr_un address{};
  if (path.size() >= sizeof(address.sun_path)) return false;
  address.sun_family = AF_UNIX;
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  const bool connected =
      ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
  ::close(fd);
  return connected;
}

// ZeroMQ unlinks an ipc path before binding it: refuse anything but a stale socket.
void CheckIpcPath(const std::string& endpoint, const std::string& option) {
  const std::string path = endpoint.substr(std::strlen("ipc://"));
  if (path.empty() || path == "*" || path[0] == '@') return;  // Chosen by ZeroMQ, or abstract.
  struct stat info{};
  if (::lstat(path.c_str(), &info) != 0) return;  // Not there: ZeroMQ makes it.
  if (!S_ISSOCK(info.st_mode)) {
    throw InputError(option + " " + endpoint + ": " + path +
                     " exists and is not a socket; refusing to replace it (choose another path)");
  }
  if (SomeoneListens(path)) {
    throw InputError(option + " " + endpoint + ": another program listens on " + path +
                     " (another softsight run?); choose another path");
  }
}

// tcp://HOST:PORT with HOST resolved to one of this machine's IPv4 addresses (localhost ->
// 127.0.0.1); absent when HOST does not resolve.
std::optional<std::string> ResolvedTcp(const std::string& endpoint) {
  const size_t start = std::strlen("tcp://");
  const size_t colon = endpoint.rfind(':');
  if (colon == std::string::npos || colon <= start) return std::nullopt;
  const std::string host = endpoint.substr(start, colon - start);
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), nullptr, &hints, &found) != 0 || found == nullptr) {
    return std::nullopt;
  }
  char text[INET_ADDRSTRLEN] = {};
  const auto* address = reinterpret_cast<const sockaddr_in*>(found->ai_addr);
  const bool ok = ::inet_ntop(AF_INET, &address->sin_addr, text, sizeof(text)) != nullptr;
  ::freeaddrinfo(found);
  if (!ok) return std::nullopt;
  return "tcp://" + std::string(text) + endpoint.substr(colon);
}

}  // namespace

std::string BindOrThrow(zmq::socket_t& socket, const std::string& endpoint,
                        const std::string& option) {
  CheckScheme(endpoint, option);
  if (StartsWith(endpoint, "ipc://")) CheckIpcPath(endpoint, option);
  try {
    socket.bind(endpoint);
  } catch (const zmq::error_t& e) {
    // ZeroMQ binds to an interface's name or an address, not to a host name: tcp://localhost:P
    // is this machine's loopback address, resolved here.
    std::optional<std::string> resolved;
    if (e.num() == ENODEV && StartsWith(endpoint, "tcp://")) resolved = ResolvedTcp(endpoint);
    if (resolved) {
      try {
        socket.bind(*resolved);
        return socket.get(zmq::sockopt::last_endpoint);
      } catch (const zmq::error_t&) {
      }
    }
    const std::string why = e.num() == EADDRINUSE ? "the address is in use (another run?)"
                            : e.num() == ENODEV   ? "no such network interface or host name "
                                                    "here (give an interface, or an address such "
                                                    "as 127.0.0.1)"
                                                  : e.what();
    throw InputError(option + " " + endpoint + ": cannot listen there: " + why + "; " + kForms);
  }
  return socket.get(zmq::sockopt::last_endpoint);
}

void ConnectOrThrow(zmq::socket_t& socket, const std::string& endpoint, const std::string& option) {
  CheckScheme(endpoint, option);
  try {
    socket.connect(endpoint);
  } catch (const zmq::error_t& e) {
    throw InputError(option + " " + endpoint + ": cannot connect: " + e.what() + "; " + kForms);
  }
}

}  // namespace softsight
