#include "app/publish_options.h"

#include <fstream>
#include <sstream>

#include "app/cli_checks.h"
#include "app/stop_request.h"
#include "softsight/core/error.h"
#include "stream/stream_format.h"

namespace softsight {

const FlagTable<PublishArgs>& PublishFlags() {
  using A = PublishArgs;
  static const FlagTable<PublishArgs> table = {
      ValueFlag<A>("--publish", &A::endpoint)
          .Help("Also send every frame's result as it happens to other programs: a ZeroMQ "
                "endpoint to listen on, tcp://*:5556 (any machine), tcp://127.0.0.1:5556 (this "
                "one) or ipc:///tmp/softsight.ipc; receive with `softsight listen ENDPOINT` or "
                "Python's softsight.stream.subscribe (docs/stream.md)"),
      ValueFlag<A>("--publish-hwm", [](A& a) -> auto& { return a.options.high_water_mark; })
          .Help("With --publish: messages queued per subscriber; beyond, a slow subscriber "
                "misses messages (counted in the summary) and the run never waits")
          .ShowDefault()
          .Check(CLI::Range(1, 1000000)),
      ValueFlag<A>("--publish-wait", [](A& a) -> auto& { return a.options.wait_subscribers; })
          .Help("With --publish: before the first frame, wait for this many subscribers (each "
                "`softsight listen` or subscribe() is one), so they get every frame")
          .ShowDefault()
          .Check(CLI::Range(0, 1000)),
      ValueFlag<A>("--publish-wait-s", [](A& a) -> auto& { return a.options.wait_timeout_s; })
          .Help("With --publish-wait: the longest wait, seconds; then the run stops with an error")
          .ShowDefault()
          .Check(NumberIn(1e-3, 86400)),
  };
  return table;
}

std::optional<PublishOptions> PublishArgs::resolved() const {
  if (!endpoint) return std::nullopt;
  PublishOptions resolved = options;
  resolved.endpoint = *endpoint;
  return resolved;
}

std::unique_ptr<PublishSink> OpenPublishSink(const std::optional<PublishOptions>& publish,
                                             const std::string& config_file) {
  if (!publish) return nullptr;
  PublishOptions options = *publish;
  options.config_file = config_file;
  std::ifstream in(config_file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  options.config_digest = Fnv1a64Hex(bytes.str());
  options.stop_requested = AnyStopRequested;  // Ctrl-C ends --publish-wait's wait.
  return std::make_unique<PublishSink>(std::move(options));
}

std::optional<PathRole> PublishOutput(const std::optional<PublishOptions>& publish) {
  if (!publish || publish->endpoint.rfind("ipc://", 0) != 0) return std::nullopt;
  const std::string path = publish->endpoint.substr(6);
  if (path.empty() || path == "*" || path[0] == '@') return std::nullopt;
  return PathRole{"--publish", path};
}

}  // namespace softsight
