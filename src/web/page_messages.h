// Internal to web (and its tests). What a page may ask of the run, checked like a config value
// before anything changes: a message is one JSON object {"type": ..., fields} of at most
// kMaxPageMessageBytes; an unknown type, a missing, unknown or mistyped field, a number out of
// range (a point outside the frame, a seek past the end, a speed outside 0.1x..4x), or a file
// name that is not a plain name in the server's folder is refused with one line saying which,
// and the run goes on unchanged.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "softsight/control/profile.h"

namespace softsight {

// Larger messages are refused unread (a page never needs more than a few hundred bytes).
inline constexpr size_t kMaxPageMessageBytes = 4096;

// What the run is now, against which a message's numbers are checked.
struct PageLimits {
  cv::Size frame_size;                 // Of the frame on screen; empty before the first.
  std::optional<int64_t> length;       // Frames in the file, when known.
  bool seekable = false;               // A file (a camera cannot step or seek).
  int markers = 0;                     // In the config.
  bool rig = false;                    // A rig to control (serve --simulate / --board-port).
};

struct PageCommand {
  enum class Kind {
    kPlay, kPause, kStep, kSeek, kSpeed,           // Playback.
    kPick, kSelect, kMethod, kUndo, kMarker,       // Tuning.
    kSave, kRecord, kResetReference,               // Files and the bending reference.
    kPing, kTakeControl,                           // Any page, controlling or not.
    kRigRun, kRigProfile,                          // The rig: the controlling page only.
    kRigStop,                                      // The rig: any page, always.
    kHsv, kMaskView,                               // Tuning: a range, the mask view.
    kLoad, kListConfigs,                           // Named configs in the server's folder.
    kRange,                                        // The mask view's click: grow / shrink.
    kScale,                                        // The mm scale from two points.
  };
  Kind kind = Kind::kPing;
  cv::Point2d point_px;   // kPick, kRange: the image pixel clicked; kScale: the first point.
  cv::Point2d point_b_px;  // kScale: the second point (image pixels).
  double distance_mm = 0.0;  // kScale: the points' true distance, (0, 1e6] mm.
  bool grow = true;          // kRange: add the colours there (false: take them out).
  cv::Rect box_px;        // kSelect: the box dragged, image pixels.
  int64_t position = 0;   // kSeek: the frame's position in the file (0-based).
  int delta = 0;          // kStep: +1 or -1.
  double speed = 1.0;     // kSpeed: 0.1 .. 4.
  int marker = 0;         // kMarker: index in the config.
  std::string name;       // kSave, kLoad: a file name in the server's folder (ValidConfigName).
  double page_time_ms = 0.0;  // kPing: the page's clock, echoed back (latency, clock offset).
  double target_deg = 180.0;  // kRigRun: 0 .. 180 (180 straight).
  int hsv_index = 0;          // kHsv: 0..5, H lo, H hi, S lo, S hi, V lo, V hi (kHsvTrackbars).
  int hsv_value = 0;          // kHsv: 0..179 for hue, 0..255 for S and V.
  bool on = false;            // kMaskView.
  TargetProfile profile = TargetProfile::Constant(180.0);  // kRigProfile: parsed, in bounds.
};

// True for commands only the controlling page may send (a STOP of the rig is not one of them:
// any page may vent the actuator, whoever controls the run).
bool ChangesTheRun(PageCommand::Kind kind);

// The command in `text`, or nullopt with `*error` saying what is wrong ("seek: position 9000 is
// past the last frame (299)").
std::optional<PageCommand> ParsePageCommand(std::string_view text, const PageLimits& limits,
                                            std::string* error);

// A config name a page may save to: letters, digits, '_', '-' and '.', 1-64 characters, ending
// in ".yaml", not starting with '.': a plain name in the server's folder, never a path.
bool ValidConfigName(std::string_view name, std::string* error);

}  // namespace softsight
