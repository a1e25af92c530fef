// `softsight track`: frames from a file or camera -> TrackingSession -> sinks (CSV, annotated
// video, raw recording, progress), through RunPipeline.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "softsight/core/types.h"
#include "softsight/config/config.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/sink.h"
#include "softsight/pipeline/summary.h"
#include "app/python_hook.h"
#include "stream/publish_sink.h"

namespace softsight {

struct TrackOptions {
  std::string config_file;
  FrameSourceSpec source;
  std::string csv_file;
  std::optional<std::string> method;         // Overrides every marker's method.
  // Overrides every template marker's mode: true matches BGR, false gray (--colour / --gray).
  std::optional<bool> template_colour;
  std::optional<std::string> annotated_file; // Annotated video (overlay drawn on each frame).
  // Raw recording: every processed frame as read (lossless HuffYUV .avi/.mkv, or an image pattern), so a
  // camera run can be tracked again later and gives the same rows.
  std::optional<std::string> record_file;
  std::optional<int64_t> max_frames;
  // --publish: every frame's record to subscribers as it happens (stream/publish_sink.h).
  std::optional<PublishOptions> publish;
  // --hook: a Python file run on every frame, its values in the CSV and the stream.
  HookArgs hook;
  bool quiet = false;                        // No progress bar, no summary.
  bool brief = false;                        // No progress bar, a one-line summary.
};

// The run's config, checked as RunTrack checks it (also what every input of a multi-input run
// shares). Throws InputError naming the file and key.
TrackingConfig LoadTrackConfig(const TrackOptions& options);

// What a test puts in RunTrack's place of the outside world. Empty members: the real thing.
struct TrackSeams {
  // The source the run reads, in place of OpenFrameSource(options.source) and its thread (a
  // camera's stand-in that hands over frames on the pipeline's own thread).
  std::function<std::unique_ptr<FrameSource>()> open_source;
  // Called on a recording's encoding thread before each frame is encoded (AsyncFrameWriter's
  // before_encode): a test holds it there so that the encoder falls behind.
  std::function<void(int64_t index)> before_encode;
};

// Runs the whole job through RunPipeline. Throws InputError for bad input, before the run
// (config, source, outputs) or from it (a corrupt frame, a full disk; every CSV row written
// before stays intact). `summary_out` (optional) receives the summary even when it throws.
// `more_sinks` see every frame after the command's own (e.g. demo's truth scorer).
RunSummary RunTrack(const TrackOptions& options, RunSummary* summary_out = nullptr,
                    const std::vector<FrameSink*>& more_sinks = {}, const TrackSeams& seams = {});

}  // namespace softsight
