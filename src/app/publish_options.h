// --publish and its companions, the same on track, live, control and identify: the command-line
// side of stream/publish_sink.h.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "app/flag_table.h"

#include "softsight/io/output_guard.h"
#include "stream/publish_sink.h"

namespace softsight {

// What the options hold until the command runs.
struct PublishArgs {
  std::optional<std::string> endpoint;  // --publish; absent: no stream.
  PublishOptions options;               // --publish-hwm, --publish-wait, --publish-wait-s.

  // The options with the endpoint, when --publish was given.
  std::optional<PublishOptions> resolved() const;
};

// --publish, --publish-hwm, --publish-wait and --publish-wait-s.
const FlagTable<PublishArgs>& PublishFlags();

// The sink for --publish, bound now (nullptr without --publish), its hello naming `config_file`
// and the digest of its bytes. Throws InputError for a bad endpoint, before any output is made.
std::unique_ptr<PublishSink> OpenPublishSink(const std::optional<PublishOptions>& publish,
                                             const std::string& config_file);

// An ipc:// endpoint's socket file, an output no other output or input may be (nullopt for tcp).
std::optional<PathRole> PublishOutput(const std::optional<PublishOptions>& publish);

}  // namespace softsight
