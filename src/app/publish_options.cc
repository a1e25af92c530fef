#include "app/publish_options.h"

#include <fstream>
#include <sstream>

#include "app/cli_checks.h"
#include "app/stop_request.h"
#include "softsight/core/error.h"
#include "stream/stream_format.h"

namespace softsight {

void AddPublishOptions(CLI::App& sub, PublishArgs* args) {
  sub.add_option("--publish", args->endpoint,
                 "Also send every frame's result as it happens to other programs: a ZeroMQ "
                 "endpoint to listen on, tcp://*:5556 (any machine), tcp://127.0.0.1:5556 (this "
                 "one) or ipc:///tmp/softsight.ipc; receive with `softsight listen ENDPOINT` or "
                 "Python's softsight.stream.subscribe (docs/stream.md)");
  sub.add_option("--publish-hwm", args->options.high_water_mark,
                 "With --publish: messages queued per subscriber; beyond, a slow subscriber "
                 "misses messages (counted in the summary) and the run never waits")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  sub.add_option("--publish-wait", args->options.wait_subscribers,
                 "With --publish: before the first frame, wait for this many subscribers (each "
                 "`softsight listen` or subscribe() is one), so they get every frame")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  sub.add_option("--publish-wait-s", args->options.wait_timeout_s,
                 "With --publish-wait: the longest wait, seconds; then the run stops with an error")
      ->capture_default_str()
      ->check(NumberIn(1e-3, 86400));
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
