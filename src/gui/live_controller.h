// Internal to gui (and the tests). The live window's logic as a state machine, free of any window
// system: it is fed frames and user events (mouse, keys, trackbars) and produces the image to
// show. The highgui loop (live_window.cc) only forwards events and shows canvas(); tests drive
// the controller directly.
//
// Mouse: drag a rectangle over a marker to (re)select it (template / colour ROI, the paper's
// real-time recalibration); click a marker to calibrate its HSV ranges from the pixels around
// the click. Trackbars adjust the active marker's ranges. Keys: see kLiveKeys.
#pragma once

#include <array>
#include <deque>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gui/live_options.h"
#include "gui/live_pipeline.h"
#include "gui/live_view.h"
#include "gui/overlay.h"
#include "gui/rate_meter.h"
#include "gui/scale_clicks.h"
#include "gui/strip_chart.h"
#include "gui/timeline.h"
#include "io/frame_grabber.h"
#include "softsight/config/config.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/hsv_picker.h"

namespace softsight {

class LivePointer;    // gui/live_pointer.h: the mouse as clicks and drags.

struct UiEvent {
  // kPanDown / kPanMove: the right button pressed / moved with it held (pans a zoomed view).
  enum class Type { kMouseDown, kMouseMove, kMouseUp, kKey, kTrackbar, kPanDown, kPanMove };
  Type type = Type::kKey;
  cv::Point2d position_px;  // Mouse events: canvas pixel (the scaled image is top left).
  int key = 0;              // kKey: the character ('q', ' ', '1') or 27 for Escape.
  int trackbar = 0;         // kTrackbar: index into kHsvTrackbars.
  int value = 0;            // kTrackbar: new position.
  bool shift = false;       // Mouse events: the shift key was held.

  static UiEvent Mouse(Type type, double x, double y, bool shift = false) {
    return {type, {x, y}, 0, 0, 0, shift};
  }
  static UiEvent Key(int key) { return {Type::kKey, {}, key, 0, 0, false}; }
  static UiEvent Trackbar(int index, int value) {
    return {Type::kTrackbar, {}, 0, index, value, false};
  }
};

// The six trackbars of the active marker's HSV ranges: name and maximum.
struct TrackbarSpec {
  const char* name;
  int max;
};
inline constexpr std::array<TrackbarSpec, 6> kHsvTrackbars = {
    {{"H lo", 179}, {"H hi", 179}, {"S lo", 255}, {"S hi", 255}, {"V lo", 255}, {"V hi", 255}}};

struct LiveKey {
  int key;
  const char* what;
};
// Keys beyond ASCII, as the window adapter passes them (X keysyms of the arrow, Home and End
// keys); each has an ASCII twin in kLiveKeys for keyboards and scripts without them.
inline constexpr int kKeyLeft = 0xFF51, kKeyRight = 0xFF53, kKeyHome = 0xFF50, kKeyEnd = 0xFF57;
// The keys, as the on-screen help (`h`) lists them (key 0: a line about the mouse).
inline constexpr std::array<LiveKey, 24> kLiveKeys = {{
    {'h', "help on / off"},
    {' ', "pause / resume (at the end: play from the start)"},
    {'.', "step 1 frame forward (pauses)"},
    {',', "step 1 frame back (pauses)"},
    {']', "+1 s (also Right)"},
    {'[', "-1 s (also Left)"},
    {'<', "first frame (also Home)"},
    {'>', "last frame (also End)"},
    {'}', "faster: 0.1x .. 4x ({ slower)"},
    {'+', "zoom in at the pointer (- out, z whole image)"},
    {'l', "loop on / off"},
    {'0', "restart: first frame, trackers afresh, playing"},
    {'r', "record on / off (CSV, videos, config)"},
    {'s', "save the config"},
    {'b', "reset the bending-distance reference"},
    {'m', "switch method (colour, sad, ssd, zncc)"},
    {'c', "mm scale: click 2 points (Esc cancels)"},
    {'u', "undo the last reselection or range change"},
    {'v', "mask view: active marker's pixels, blobs, window"},
    {'1', "1..9 active marker;  q / Esc quit"},
    {0, "drag a box: reselect; click: pick colour"},
    {0, "mask view: click adds colours, shift-click removes"},
    {0, "right-drag: pan a zoomed view"},
    {0, "timeline (under the image): click / drag seeks"},
}};

// What a transport key asks of the source; LiveFeed carries it out (a camera cannot).
struct PlaybackRequest {
  enum class Kind { kStepForward, kStepBack, kSeekSeconds, kSeekTo, kStart, kEnd };
  Kind kind = Kind::kStepForward;
  double seconds = 0.0;   // kSeekSeconds: how far, negative backwards.
  int64_t position = 0;   // kSeekTo: the frame's position in the file (a timeline click).
};

// How a frame handed to the controller relates to the one before it.
enum class FrameOrder {
  kNext,  // The source's next frame, as it plays (ignored while paused).
  kStep,  // The next frame, stepped to with `.`: shown also while paused.
  kJump,  // Not the next frame (seek, step back, loop, restart): trackers search afresh.
};


class LiveController {
 public:
  // Builds the tracking session. Throws InputError on a bad config. `before_encode` (tests):
  // the recordings' encoder hook (AsyncFrameWriter), to make an encoder fall behind.
  LiveController(const TrackingConfig& config, LiveOptions options,
                 std::function<void(int64_t index)> before_encode = {});
  ~LiveController();

  // A new frame (kNext: ignored while paused). Tracks, measures, records, redraws. A jump stops
  // a running recording first (a recording holds consecutive frames) and clears the strip chart.
  void on_frame(const Frame& frame, SteadyClock::time_point captured,
                FrameOrder order = FrameOrder::kNext);
  void on_event(const UiEvent& event);
  // The source has ended: the last frame stays on screen, and every key still works.
  void on_end_of_input();
  // The oldest transport request not yet carried out, taken by the feed (once). Keys pressed
  // while a seek runs queue up behind it, in order (a timeline drag keeps only its newest seek).
  std::optional<PlaybackRequest> take_playback_request();
  // A request that jumps (not a step forward) is waiting: the window shows the seeking hint
  // (show_seeking) before the feed carries it out.
  bool jump_pending() const;
  void show_seeking();
  // Where the frame about to be handed over is in a file (SeekableSource's position) and the
  // file's length when known: the timeline. Cameras never call it (no timeline).
  void set_source_position(int64_t position, std::optional<int64_t> length);
  const Timeline& timeline() const { return timeline_; }
  // The playing speed the window asks of a paced file (`{` / `}`: 0.1x .. 4x).
  double speed() const;
  // The zoom and pan of the view (+ / -, z, right-drag).
  const ViewZoom& zoom() const { return zoom_; }
  // Edits `u` can undo.
  size_t undo_depth() const { return undo_.size(); }
  // The edits of the mouse and the timeline for an adapter that speaks image pixels and file
  // positions instead of canvas pixels (the web page, src/web): the same calls a click, a drag
  // and a timeline click make, so both front ends edit the session alike.
  void pick_colour_at(const cv::Point2d& image_px) { click(image_px); }
  void reselect(const cv::Rect& image_px) { drag(image_px); }
  // The mask view's click (image pixels): `grow` adds the colours around it to the active
  // marker's ranges, else takes them out (shift-click); one undo step each.
  void edit_range_at(const cv::Point2d& image_px, bool grow) { edit_range(image_px, grow); }
  // The mm scale from two image points `distance_mm` apart, as the window's `c` and two clicks
  // make it (points less than ScaleClicks::kMinSpanPx apart, or a recording running: refused,
  // with a message, nothing changed). The frame on screen is measured again.
  void set_scale_from_points(const cv::Point2d& a_px, const cv::Point2d& b_px, double distance_mm);
  // Queues a seek to `position` in the file (refused, with a message, while recording).
  void seek_to(int64_t position);
  // The playing speed closest to `speed` among 0.1x .. 4x (the keys' steps).
  void set_speed(double speed);
  // Saves the config as `s` does, to `path` instead of the window's save path.
  void save_config_to(const std::string& path);
  // Loads the markers' parameters of the config at `path` (one saved by save_config_to, or any
  // config of the same markers): each marker takes the loaded marker of its name, its other
  // kinds' parameters too; `u` undoes it marker by marker. Refused, with a message and nothing
  // changed, when the file does not load or its markers are not these (by name).
  void load_markers_from(const std::string& path);
  // The frame on screen as captured (empty before the first), and its position in the file
  // (-1 for a camera).
  const cv::Mat& frame_on_screen() const { return frame_; }
  int64_t position() const { return position_; }
  // A message from outside (the feed: "a camera cannot seek"), shown like the controller's own.
  void report(const std::string& message) { say(message); }

  // The image to show: the annotated frame (scaled down to fit the screen) with the UI on top,
  // the strip chart under it, the help panel (`h`) to the right. Mouse events are in its pixels.
  const cv::Mat& canvas();
  // The screen the window is on: the canvas is scaled to fit it (never up); mouse positions are
  // mapped back to image pixels. Default: no screen known, nothing scaled.
  void set_screen(cv::Size screen_px);
  // The canvas position of an image point, and back (the mapping canvas() and mouse events use).
  cv::Point2d to_view(const cv::Point2d& image_px) const;
  cv::Point2d to_image(const cv::Point2d& view_px) const;

  bool quit_requested() const { return quit_; }
  bool paused() const { return paused_; }
  bool ended() const { return ended_; }
  // Loop (`l`): at the end, play on from the first frame.
  bool loop() const { return loop_; }
  bool recording() const;
  bool help_shown() const { return help_; }
  // Mask view (`v`): the active marker's member pixels, its candidate blobs with the verdict on
  // each, and its search region, instead of the annotated frame.
  bool mask_view() const { return mask_view_; }
  // The active marker's tracker: what the mask view shows (its member pixels, its candidates
  // with their verdicts, its search region), for an adapter that draws it itself (src/web).
  const Tracker& active_tracker() const;
  // Scale mode (`c`): the next left clicks are the two scale points.
  bool scale_mode() const { return scale_.active(); }
  int active_marker() const { return active_; }
  // The config as edited live (what `s` saves): the session's, the only copy.
  const TrackingConfig& config() const;
  // Frames the source dropped so far (a camera, newest frame wins; files never drop): shown in
  // the status line.
  void set_dropped_frames(int64_t dropped) {
    if (dropped != dropped_) dirty_ = true;
    dropped_ = dropped;
  }
  int64_t dropped_frames() const { return dropped_; }
  const std::optional<FrameResult>& last_result() const { return last_result_; }
  const StripChart& chart() const { return chart_; }
  // The last message on screen, and every message said since the last call (oldest first), so
  // the window logs each one once, also those a later one replaced on screen within one frame
  // (the recording a loop's wrap stopped, then the wrap).
  const std::string& message() const { return message_; }
  std::vector<std::string> take_messages() {
    std::vector<std::string> said;
    said.swap(unlogged_);
    return said;
  }
  std::optional<double> latency_ms() const { return meter_.latency_ms(); }
  std::optional<double> fps() const { return meter_.fps(); }
  // The active marker's ranges in kHsvTrackbars order, and a counter that changes whenever they
  // or the active marker change, so the adapter knows when to move its trackbars.
  std::array<int, 6> active_hsv() const;
  int hsv_revision() const { return hsv_revision_; }
  // Where the previous recording's files went (prefix without extension); empty if none.
  const std::string& last_recording() const;
  // Before the first frame: where the frames come from, for the end summary; a camera's
  // recordings get a deeper queue, so an encoder's hiccup does not hold up the window (they
  // still keep every frame: LivePipeline).
  void describe_source(const FrameSource& source);
  // The run so far, for the end summary (a recording still open counted too).
  LiveRunSummary run_summary() const;

 private:

  void handle(const UiEvent& event);
  // The steps of handle(): a button released, a key pressed.
  void release_pointer(const UiEvent& event, const cv::Point2d& at, bool in_image);
  void press_key(const UiEvent& event);
  TrackingSession& session();
  // The recording stopped by itself (a full disk, an edit it could not keep): say why.
  void report_recording_failure();
  void click(const cv::Point2d& p);
  // Mask view: the pixels around `p` added to (grow) or removed from the active marker's ranges.
  void edit_range(const cv::Point2d& p, bool grow);
  void drag(const cv::Rect& rect);
  void switch_method();
  void set_hsv(int trackbar, int value);
  void toggle_recording();
  // Stops the running recording and says what it kept ("recorded N frames to P.*").
  std::string stop_recording();
  void save_config();
  // Queues a seek (a timeline click or drag, or seek_to); false when refused (recording).
  bool queue_seek(int64_t position);
  void start_scale();
  void cancel_scale();
  void scale_point(const cv::Point2d& p);
  // Hands `metric` (two points `span_px` apart, `distance_mm` in truth) to the session and
  // measures the frame on screen again; false, `*refused` saying why, when the session refuses it.
  bool apply_scale(const MetricModel& metric, double span_px, double distance_mm, std::string* refused);
  LiveLayout layout() const;
  // The state line (recording, pause, end, loop, drops, active marker, scale), the last message
  // and the scale hint.
  std::vector<std::string> status_lines() const;
  void select_marker(int index);
  // Before a reselection or range change of `marker`: what `u` restores. `coalesce`: a trackbar
  // drag is one edit however many steps the trackbar reports.
  void remember_for_undo(int marker, const std::string& what, bool coalesce = false);
  void undo();
  void zoom_at(const cv::Point2d& image_px, double factor);
  void change_speed(int steps);
  // Mouse events on the timeline (scrubbing): true when the event was the timeline's.
  bool scrub(const UiEvent& event, const LiveLayout& view);
  // A transport key: refused while recording (except a step forward), else queued for the feed.
  void request_playback(PlaybackRequest::Kind kind, double seconds = 0.0);
  void restart();
  std::optional<int> marker_at(const cv::Point2d& p, double max_distance) const;
  std::optional<cv::Point2d> position_of(int marker) const;
  cv::Rect box_around(const cv::Point2d& p) const;
  void apply_spec(int marker, const MarkerSpec& spec, const std::optional<cv::Rect>& hint);
  // Marker `marker`'s colour parameters (what the HSV trackbars and range edits show and change):
  // its own for a colour marker, else those set aside for the colour method.
  ColourParams colour_of(int marker) const;
  ColourParams& colour_set_aside(int marker);
  void redraw_annotated();
  void draw_overlay(cv::Mat& image, const FrameResult& result) const;
  // The frame on screen, as the session saw it (no copy of the pixels).
  Frame on_screen() const;
  // A new result for the frame on screen (a reselection): shown, not recorded again.
  void show(const FrameResult& result);
  void say(const std::string& message);

  LiveOptions options_;
  // The session (the only copy of the config) and the run's sinks: statistics, the recording.
  std::unique_ptr<LivePipeline> pipeline_;
  StripChart chart_;
  cv::Mat frame_;  // The frame on screen, as captured.
  int64_t frame_index_ = -1;
  double frame_time_s_ = 0.0;  // The source's timestamp of frame_.
  int64_t dropped_ = 0;
  cv::Mat annotated_;  // frame_ + overlay (what annotated video records).
  LiveView view_;  // Draws the canvas; dirty_ says when it must.
  cv::Size max_canvas_;  // Empty: no screen known.
  bool dirty_ = true;
  std::optional<FrameResult> last_result_;
  RateMeter meter_;

  bool paused_ = false, help_ = false, quit_ = false, ended_ = false, loop_ = false;
  bool mask_view_ = false;
  cv::Mat hsv_patch_;  // Range edits: a reused buffer.
  std::deque<PlaybackRequest> playback_requests_;
  bool seeking_ = false;  // The hint is on screen until the next frame.
  Timeline timeline_;
  bool has_timeline_ = false;  // A file: set_source_position was called.
  int64_t position_ = -1;      // In the file, of the frame on screen.
  bool scrubbing_ = false;     // The button went down on the timeline.
  ViewZoom zoom_;
  std::optional<cv::Point2d> pan_from_;      // Image pixel under the right button's press.
  std::optional<cv::Point2d> pointer_image_;  // The pointer, image pixels: where keys zoom.
  int speed_step_ = 3;  // Index into kSpeeds (1x).
  struct UndoEntry {
    int marker;
    MarkerSpec spec;       // The marker as it was.
    std::vector<MarkerParams> aside;  // Its other kinds' parameters set aside (a template
                                      // marker's colour picks).
    std::string what;
    bool coalescing;       // A trackbar's edit: later steps of it join this entry.
  };
  std::vector<UndoEntry> undo_;
  // Per marker, the box a recording's start cut its template from, and the pixels.
  std::vector<std::pair<cv::Rect, cv::Mat>> recording_cuts_;
  int active_ = 0;
  int hsv_revision_ = 0;
  // Per marker (config order), its parameters of the kinds it does not use now, at most one set
  // per kind: a marker is one kind's parameters (MarkerSpec), so a colour pick on a template
  // marker, and the template of a marker switched to colour, are kept here for `m` to switch
  // back to (and `s` saves them: TrackingConfig::params_aside).
  std::vector<std::vector<MarkerParams>> aside_;
  std::unique_ptr<LivePointer> pointer_;
  ScaleClicks scale_;
  std::string message_;
  std::vector<std::string> unlogged_;  // Said since the last take_messages().
  mutable OverlayStatus overlay_status_;  // draw_overlay's, reused per frame.
};

}  // namespace softsight
