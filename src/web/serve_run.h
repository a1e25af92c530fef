// Internal to web: `softsight serve`, the live bench in a browser. The same pieces as the live
// window (src/gui): a LiveController fed by a LiveFeed drives the tracking session and its run;
// the browser is one more sink of that run (every tracked frame's CSV row as JSON, and its
// picture as JPEG, over a WebSocket) and one more source of the controller's commands (checked
// by ParsePageCommand, then the very calls the window's mouse and keys make). So a page edits,
// records and saves exactly as the window does, and a recording made from a page reproduces
// under `softsight track`.
#pragma once

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>

#include "gui/live_options.h"
#include "gui/live_window.h"
#include "softsight/config/config.h"
#include "softsight/io/frame_source.h"
#include "web/web_server.h"

namespace softsight {

class RigPanel;

struct ServeOptions {
  WebServerOptions server;
  // The window's settings that a page shares (record_prefix: in `folder`; the picker, the box
  // cut around a marker for a template, the sinks of the program).
  LiveOptions live;
  // The folder pages save configs in (a plain name, never a path: ValidConfigName).
  std::filesystem::path folder = ".";
  // The config the server was started with: a page may not save over it.
  std::string config_path;
  bool pace_files = true;  // A file plays at its frame rate (false: as fast as it decodes).
  int jpeg_quality = 80;   // 1..100. 80: ~40 KB a 640x480 frame, no visible blocks at 1x.
  // The rig's control panel (serve --simulate / --board-port), or none. Its loop steps on every
  // tracked frame (it becomes a sink of the run); pages run it, and any page's STOP vents it.
  RigPanel* rig = nullptr;
  // A second video shown beside the served one, frame by frame at the same position (a file
  // served: two runs side by side in sync), or none: opens it from its first frame.
  FrameSourceOpener compare;
};

// Serves until `stop_requested()` returns true (polled between frames, at least every 20 ms).
// Prints the page's URL on `out` once listening, and every message the run says ("serve: ...").
// Throws InputError (a bad config, an address it cannot listen on) before serving.
LiveRunResult RunServe(const TrackingConfig& config, std::unique_ptr<FrameSource> source,
                       ServeOptions options, FrameSourceOpener reopen,
                       const std::function<bool()>& stop_requested, std::ostream& out);

// The page's files, compiled in (page_assets.cc, generated from src/web/page/).
std::vector<PageAsset> PageAssets();

}  // namespace softsight
