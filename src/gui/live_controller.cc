#include "gui/live_controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "gui/live_layout.h"
#include "gui/live_pointer.h"
#include "gui/live_recording.h"  // SaveLiveConfig
#include "gui/live_view.h"
#include "gui/range_edit.h"
#include "softsight/calib/camera_calibration.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {
namespace {

// The playing speeds `{` and `}` step through (times the file's own rate).
constexpr double kSpeeds[] = {0.1, 0.25, 0.5, 1.0, 2.0, 4.0};
constexpr int kSpeedCount = static_cast<int>(std::size(kSpeeds));
constexpr size_t kMaxQueuedRequests = 32;
constexpr size_t kMaxUndo = 32;
constexpr double kZoomStep = 1.25;  // Per + / - press.
// Puts `params` in `aside` in place of the set of its kind there.
void SetAside(std::vector<MarkerParams>& aside, const MarkerParams& params) {
  for (MarkerParams& kept : aside) {
    if (&kept.kind() == &params.kind()) {
      kept = params;
      return;
    }
  }
  aside.push_back(params);
}

// Removes the set of `kind` from `aside` (it is the marker's own now).
void TakeFromAside(std::vector<MarkerParams>& aside, const TrackerKind& kind) {
  std::erase_if(aside, [&kind](const MarkerParams& kept) { return &kept.kind() == &kind; });
}

// The playback a key asks for: a step ('.', ','), a second either way (']', '[' and the arrows),
// the start ('<', Home) or the end ('>', End); the seconds for a seek.
std::pair<PlaybackRequest::Kind, double> PlaybackKey(int key) {
  using Kind = PlaybackRequest::Kind;
  switch (key) {
    case '.':
      return {Kind::kStepForward, 0.0};
    case ',':
      return {Kind::kStepBack, 0.0};
    case ']':
    case kKeyRight:
      return {Kind::kSeekSeconds, 1.0};
    case '[':
    case kKeyLeft:
      return {Kind::kSeekSeconds, -1.0};
    case '<':
    case kKeyHome:
      return {Kind::kStart, 0.0};
    default:  // '>', End.
      return {Kind::kEnd, 0.0};
  }
}

}  // namespace

LiveController::LiveController(const TrackingConfig& config, LiveOptions options,
                               std::function<void(int64_t index)> before_encode)
    : options_(std::move(options)),
      chart_(options_.chart),
      pointer_(std::make_unique<LivePointer>(options_.click_slop_px)),
      scale_(options_.scale_distance_mm) {
  std::string error;
  if (!options_.Check(&error)) throw InputError("live options: " + error);
  if (config.markers.empty()) throw InputError(config.source_file + ": no markers to track");
  options_.overlay.base = config.measure.base;
  options_.overlay.middle = config.measure.middle;
  options_.overlay.tip = config.measure.tip;
  // The session holds the only copy of the config: every live edit goes through it, and `s`
  // and recordings save what it holds; the pipeline feeds it and its sinks (the recording).
  pipeline_ = std::make_unique<LivePipeline>(
      config,
      LiveRecordingSettings{options_.record_prefix, std::move(before_encode), options_.extra_columns},
      options_.sinks);
  for (const MarkerSpec& spec : config.markers) {
    // Its keys of other kinds in the file (a template marker's colour keys) are those methods'
    // parameters.
    const auto aside = config.params_aside.find(spec.name);
    aside_.push_back(aside != config.params_aside.end() ? aside->second
                                                        : std::vector<MarkerParams>{});
  }
  say("press h for help");
}

LiveController::~LiveController() = default;

const TrackingConfig& LiveController::config() const { return pipeline_->config(); }

TrackingSession& LiveController::session() { return pipeline_->session(); }

bool LiveController::recording() const { return pipeline_->recording(); }

const std::string& LiveController::last_recording() const { return pipeline_->last_recording(); }

LiveRunSummary LiveController::run_summary() const { return pipeline_->summary(dropped_); }

void LiveController::describe_source(const FrameSource& source) {
  pipeline_->describe_source(source);
}

void LiveController::report_recording_failure() {
  if (auto failure = pipeline_->take_recording_failure()) say(*failure);
}

void LiveController::say(const std::string& message) {
  message_ = message;
  // Bounded: a window that never takes them (a test) keeps only the latest.
  if (unlogged_.size() >= 64) unlogged_.erase(unlogged_.begin());
  unlogged_.push_back(message);
  dirty_ = true;
}

void LiveController::on_frame(const Frame& frame, SteadyClock::time_point captured,
                              FrameOrder order) {
  if (paused_ && order == FrameOrder::kNext) return;
  CV_Assert(frame.image.type() == CV_8UC3);
  bool recording_stopped = false;
  if (order == FrameOrder::kJump) {
    if (recording()) {
      // Said on screen until the next message (not replaced by the frame's), and logged.
      say(stop_recording() + " (stopped: " +
          (loop_ ? "the loop went back to the first frame)" : "the playback jumped)"));
      recording_stopped = true;
    }
    session().jump();
    chart_.clear();  // Its time axis cannot run backwards.
    meter_.restart();  // Nor the source's speed.
  }
  frame.image.copyTo(frame_);
  frame_index_ = frame.index;
  ended_ = false;
  frame_time_s_ = frame.time_s;
  // Tracked, counted and (while recording) recorded by the pipeline.
  const FrameResult& result = pipeline_->process(frame);
  seeking_ = false;
  if (has_timeline_) {
    if (recording()) timeline_.mark(position_, Timeline::kRecorded);
  }
  show(result);
  report_recording_failure();
  if (order != FrameOrder::kNext) {
    // A frame the user stepped or seeked to: no figure of the playing rate; say which it is
    // (stdout too, for the terminal and for scripts driving the window).
    if (!recording_stopped) {
      say("frame " + std::to_string(frame.index) + " (" + FixedNumber(frame.time_s, 3) + " s)");
    }
    return;
  }

  // Frame rate over the last frames that produced a result, latency from capture to result.
  meter_.result_at(SteadyClock::now(), frame.time_s);
  // Latency: from capture to the annotated (and recorded) result, as the window is about to show
  // it. The overlay shows the smoothed value up to the previous frame.
  meter_.latency(std::chrono::duration<double, std::milli>(SteadyClock::now() - captured).count());
  dirty_ = true;
}

void LiveController::redraw_annotated() {
  if (frame_.empty()) return;
  frame_.copyTo(annotated_);
  if (last_result_) draw_overlay(annotated_, *last_result_);
}

void LiveController::draw_overlay(cv::Mat& image, const FrameResult& result) const {
  OverlayStatus& status = overlay_status_;  // Reused: its vectors keep their storage.
  status.fps = meter_.fps();
  // Slower than the video is said when the file plays slower than asked (`{` asks for less).
  status.speed = meter_.speed();
  if (status.speed && *status.speed >= speed() * 0.9) status.speed = *status.speed / speed();
  status.latency_ms = meter_.latency_ms();
  const std::vector<MarkerSpec>& markers = config().markers;
  status.template_boxes.resize(markers.size());
  for (size_t i = 0; i < markers.size(); ++i) {
    // The box its kind draws around it (a template's size).
    const std::optional<cv::Size> size = markers[i].params.kind().drawn_box(markers[i].params);
    if (size) {
      status.template_boxes[i] =
          OverlayStatus::TemplateBox{*size, TrackerMethodName(markers[i].params)};
    } else {
      status.template_boxes[i].reset();
    }
  }
  DrawOverlay(image, result, options_.overlay, status);
}

void LiveController::on_end_of_input() {
  ended_ = true;
  say("end of input: the last frame stays; space plays from the start, q quits");
}

std::optional<PlaybackRequest> LiveController::take_playback_request() {
  if (playback_requests_.empty()) return std::nullopt;
  const PlaybackRequest request = playback_requests_.front();
  playback_requests_.pop_front();
  return request;
}

bool LiveController::jump_pending() const {
  return !playback_requests_.empty() &&
         playback_requests_.front().kind != PlaybackRequest::Kind::kStepForward;
}

void LiveController::show_seeking() {
  seeking_ = true;
  dirty_ = true;
}

void LiveController::set_source_position(int64_t position, std::optional<int64_t> length) {
  has_timeline_ = true;
  position_ = position;
  if (length && length != timeline_.length()) timeline_.set_length(*length);
  timeline_.set_position(position);
}

double LiveController::speed() const { return kSpeeds[speed_step_]; }

void LiveController::change_speed(int steps) {
  speed_step_ = std::clamp(speed_step_ + steps, 0, kSpeedCount - 1);
  meter_.restart();  // The rate measured at the old speed says nothing of the new one.
  say("speed " + FixedNumber(speed(), speed() < 1 ? 2 : 0) + "x");
}

void LiveController::zoom_at(const cv::Point2d& image_px, double factor) {
  if (frame_.empty()) return;
  zoom_ = zoom_.about(image_px, factor, frame_.size());
  dirty_ = true;
}

bool LiveController::scrub(const UiEvent& event, const LiveLayout& view) {
  using Type = UiEvent::Type;
  const cv::Point at(cvFloor(event.position_px.x), cvFloor(event.position_px.y));
  if (event.type == Type::kMouseDown) scrubbing_ = view.timeline.contains(at);
  if (!scrubbing_) return false;
  if (event.type == Type::kMouseUp) scrubbing_ = false;
  const int64_t target =
      timeline_.position_at(event.position_px.x - view.timeline.x, view.timeline.width);
  if (target == position_ && event.type != Type::kMouseDown) return true;
  if (!queue_seek(target)) scrubbing_ = false;
  return true;
}

bool LiveController::queue_seek(int64_t position) {
  // A drag asks for many frames; only the newest one still matters.
  if (!playback_requests_.empty() && playback_requests_.back().kind == PlaybackRequest::Kind::kSeekTo) {
    playback_requests_.pop_back();
  }
  if (recording()) {
    say("stop the recording first (r): a recording holds consecutive frames");
    return false;
  }
  PlaybackRequest request;
  request.kind = PlaybackRequest::Kind::kSeekTo;
  request.position = position;
  playback_requests_.push_back(request);
  dirty_ = true;
  return true;
}

void LiveController::seek_to(int64_t position) { queue_seek(position); }

void LiveController::set_speed(double speed) {
  int nearest = 0;
  for (int i = 1; i < kSpeedCount; ++i) {
    if (std::abs(kSpeeds[i] - speed) < std::abs(kSpeeds[nearest] - speed)) nearest = i;
  }
  change_speed(nearest - speed_step_);
}

void LiveController::request_playback(PlaybackRequest::Kind kind, double seconds) {
  if (recording() && kind != PlaybackRequest::Kind::kStepForward) {
    // The recording's raw video must be re-trackable: its frames follow each other.
    say("stop the recording first (r): a recording holds consecutive frames");
    return;
  }
  if (kind == PlaybackRequest::Kind::kStepForward || kind == PlaybackRequest::Kind::kStepBack) {
    paused_ = true;
  }
  if (playback_requests_.size() >= kMaxQueuedRequests) {
    say("still seeking: key ignored");
    return;
  }
  playback_requests_.push_back(PlaybackRequest{kind, seconds});
  dirty_ = true;
}

void LiveController::restart() {
  if (recording()) toggle_recording();
  request_playback(PlaybackRequest::Kind::kStart);
  session().reset_tip_reference();
  paused_ = false;
  say("restart: from the first frame, trackers afresh");
}

std::optional<cv::Point2d> LiveController::position_of(int marker) const {
  if (!last_result_ || marker < 0 || marker >= static_cast<int>(last_result_->markers.size())) {
    return std::nullopt;
  }
  return last_result_->markers[marker].observation.position_px;
}

std::optional<int> LiveController::marker_at(const cv::Point2d& p, double max_distance) const {
  std::optional<int> best;
  double best_distance = max_distance;
  for (int i = 0; i < static_cast<int>(config().markers.size()); ++i) {
    const auto position = position_of(i);
    if (!position) continue;
    const double d = std::hypot(position->x - p.x, position->y - p.y);
    if (d <= best_distance) {
      best_distance = d;
      best = i;
    }
  }
  return best;
}

cv::Rect LiveController::box_around(const cv::Point2d& p) const {
  const int side = options_.select_box_px;
  const cv::Rect box(cvRound(p.x) - side / 2, cvRound(p.y) - side / 2, side, side);
  return box & cv::Rect(0, 0, frame_.cols, frame_.rows);
}

void LiveController::select_marker(int index) {
  if (index < 0 || index >= static_cast<int>(config().markers.size())) {
    say("no marker " + std::to_string(index + 1) + " (the config has " +
        std::to_string(config().markers.size()) + ")");
    return;
  }
  active_ = index;
  ++hsv_revision_;
  say("active marker: " + config().markers[index].name);
}

void LiveController::apply_spec(int marker, const MarkerSpec& spec,
                                const std::optional<cv::Rect>& hint) {
  try {
    // A running recording keeps each edit: the session tells it (LivePipeline).
    session().respec(spec);
    if (hint && !hint->empty() && !frame_.empty()) {
      show(session().reselect(spec.name, on_screen(), *hint));
    } else if ((paused_ || ended_) && !frame_.empty()) {
      // No new frame is coming: track the one on screen again, so the change shows at once.
      show(session().retrack(spec.name, on_screen()));
    }
  } catch (const InputError& e) {
    // A live edit that cannot be used is reported on screen; the session keeps running.
    say(e.what());
    return;
  }
  if (has_timeline_) timeline_.mark(position_, Timeline::kEdit);
  if (marker == active_) ++hsv_revision_;
}

void LiveController::click(const cv::Point2d& p) {
  if (frame_.empty()) return;
  const int marker = marker_at(p, 2.0 * options_.overlay.marker_ring_px).value_or(active_);
  std::string why;
  // The one colour pick `softsight pick` shares: ranges from the pixels around the click, and
  // the search box around it.
  const auto pick = PickMarkerColourAt(frame_, p, options_.picker, options_.select_box_px, &why);
  if (!pick) {
    say("colour pick for " + config().markers[marker].name + ": " + why);
    return;
  }
  remember_for_undo(marker, "colour pick");
  active_ = marker;
  MarkerSpec spec = config().markers[marker];
  auto* colour = spec.params.get_if<ColourParams>();
  if (colour) {
    // The colour tracker looks for the marker around the click first.
    ApplyColourPick(*pick, colour);
    apply_spec(marker, spec, pick->roi);
  } else {
    // A template marker keeps its template; the ranges are kept for the colour method.
    ApplyColourPick(*pick, &colour_set_aside(marker));
  }
  ++hsv_revision_;
  const std::string ranges = pick->ranges.gray
                                 ? "gray " + RangeText(*pick->ranges.gray)
                                 : "h " + RangeText(pick->ranges.h) + " s " +
                                       RangeText(pick->ranges.s) + " v " + RangeText(pick->ranges.v);
  say(spec.name + ": " + ranges + (colour ? "" : " (used by the colour method)"));
}

void LiveController::edit_range(const cv::Point2d& p, bool grow) {
  if (frame_.empty()) return;
  MarkerSpec spec = config().markers[active_];
  auto* colour = spec.params.get_if<ColourParams>();
  if (!colour || colour->gray) {
    say(spec.name + ": ranges are edited for colour markers (m switches the method)");
    return;
  }
  // The pixels within the picker's radius of the click (a 5 px radius: an 11 x 11 patch).
  const int r = options_.picker.radius_px;
  const cv::Rect patch = cv::Rect(cvRound(p.x) - r, cvRound(p.y) - r, 2 * r + 1, 2 * r + 1) &
                         cv::Rect(0, 0, frame_.cols, frame_.rows);
  if (patch.empty()) return;
  cv::cvtColor(frame_(patch), hsv_patch_, cv::COLOR_BGR2HSV);
  HsvRanges ranges{colour->h, colour->s, colour->v};
  if (grow) {
    ranges = GrowRanges(ranges, hsv_patch_);
  } else if (std::string why; !ShrinkRanges(ranges, hsv_patch_, &why)) {
    say(spec.name + ": " + why);
    return;
  }
  remember_for_undo(active_, grow ? "added colours" : "removed colours");
  colour->h = ranges.h;
  colour->s = ranges.s;
  colour->v = ranges.v;
  colour->auto_bgr.reset();
  const std::string text = "h " + RangeText(colour->h) + " s " + RangeText(colour->s) + " v " +
                           RangeText(colour->v);
  apply_spec(active_, spec, std::nullopt);
  ++hsv_revision_;
  say(spec.name + (grow ? ": added, " : ": removed, ") + text);
}

void LiveController::drag(const cv::Rect& dragged) {
  const cv::Rect rect = dragged & cv::Rect(0, 0, frame_.cols, frame_.rows);
  if (rect.width < 3 || rect.height < 3) {
    say("box too small");
    return;
  }
  // The marker inside the box, if exactly one is; else the active marker.
  std::optional<int> inside;
  int count = 0;
  for (int i = 0; i < static_cast<int>(config().markers.size()); ++i) {
    const auto position = position_of(i);
    if (position && rect.contains(cv::Point(cvRound(position->x), cvRound(position->y)))) {
      inside = i;
      ++count;
    }
  }
  const int marker = count == 1 ? *inside : active_;
  const MarkerSpec& spec = config().markers[marker];
  // A box in which the marker's own tracker finds nothing (empty background, or a colour the
  // marker's range does not take) would leave the marker lost: it is refused and the marker
  // stays as it was. (A template box with no marker in it is refused by its tracker's init.)
  try {
    const Frame frame = on_screen();
    std::unique_ptr<Tracker> trial = CreateTracker(spec);
    trial->init(frame.image, rect);
    if (!trial->update(frame.image).found()) {
      say(spec.name + ": the box [" + std::to_string(rect.x) + ", " + std::to_string(rect.y) +
          ", " + std::to_string(rect.width) + ", " + std::to_string(rect.height) +
          "] holds nothing its tracker takes for the marker; drag it around the marker (or "
          "click the marker first to pick its colour)");
      return;
    }
  } catch (const InputError& e) {
    say(e.what());
    return;
  }
  remember_for_undo(marker, "reselection");
  try {
    // The session remembers the selection in its config (the template's pixels, or the colour
    // search box), so that `s` saves it.
    show(session().reselect(spec.name, on_screen(), rect));
  } catch (const InputError& e) {
    undo_.pop_back();  // Refused: nothing changed.
    say(e.what());
    return;
  }
  if (has_timeline_) timeline_.mark(position_, Timeline::kEdit);
  if (active_ != marker) ++hsv_revision_;
  active_ = marker;
  say(spec.name + ": reselected in [" + std::to_string(rect.x) + ", " + std::to_string(rect.y) +
      ", " + std::to_string(rect.width) + ", " + std::to_string(rect.height) + "]");
}

void LiveController::remember_for_undo(int marker, const std::string& what, bool coalesce) {
  if (coalesce && !undo_.empty() && undo_.back().coalescing && undo_.back().marker == marker) {
    return;  // The same trackbar drag: undo goes back to before it began.
  }
  if (undo_.size() >= kMaxUndo) undo_.erase(undo_.begin());
  UndoEntry entry{marker, config().markers[marker], aside_[marker], what, coalesce};
  auto* templ = entry.spec.params.get_if<TemplateParams>();
  if (templ && templ->image.empty() && templ->rect && marker < static_cast<int>(recording_cuts_.size()) &&
      recording_cuts_[marker].first == *templ->rect) {
    templ->image = recording_cuts_[marker].second;  // Cut when the recording started.
  }
  undo_.push_back(std::move(entry));
}

void LiveController::undo() {
  if (undo_.empty()) {
    say("nothing to undo (u undoes reselections and range changes)");
    return;
  }
  UndoEntry entry = std::move(undo_.back());
  undo_.pop_back();
  if (auto* templ = entry.spec.params.get_if<TemplateParams>()) {
    if (templ->image.empty()) {
      // A rectangle to cut on a frame that is no longer on screen: cutting it here would take
      // whatever is there now, not the template.
      say("cannot undo the " + entry.what + " of " + entry.spec.name + ": its template was cut " +
          "from frame " + std::to_string(templ->template_frame) + " of the config, not live");
      return;
    }
    // The old template, started where the marker is now (not where it was cut): the tracker
    // then follows it from here, live and in `track` alike.
    if (const auto position = position_of(entry.marker); position && !frame_.empty()) {
      const cv::Size size = templ->image.size();
      const cv::Rect here(cvRound(position->x - size.width / 2.0),
                          cvRound(position->y - size.height / 2.0), size.width, size.height);
      if ((here & cv::Rect(0, 0, frame_.cols, frame_.rows)) == here) {
        templ->rect = here;
        templ->template_frame = static_cast<int>(std::max<int64_t>(0, frame_index_));
      }
    }
  }
  aside_[entry.marker] = entry.aside;
  // The marker as it was, through the same respec every edit uses: a running recording logs it
  // like any other edit, so `track` replays the undo too.
  apply_spec(entry.marker, entry.spec, std::nullopt);
  ++hsv_revision_;
  say("undone: " + entry.what + " of " + entry.spec.name);
}

void LiveController::switch_method() {
  const std::vector<std::string> methods = TrackerMethods();
  const auto current =
      std::find(methods.begin(), methods.end(), TrackerMethodName(config().markers[active_].params));
  const std::string next =
      current == methods.end() || current + 1 == methods.end() ? methods.front() : *(current + 1);
  for (int i = 0; i < static_cast<int>(config().markers.size()); ++i) {
    MarkerSpec spec = config().markers[i];
    // The set in use now is set aside, to come back to; the next method's kind's set comes back
    // (the same set when the method is of the same kind: sad -> ssd).
    SetAside(aside_[i], spec.params);
    spec.params = ParamsForMethod(next, aside_[i]);
    TakeFromAside(aside_[i], spec.params.kind());
    std::optional<cv::Rect> hint;
    if (const auto position = position_of(i); position && !frame_.empty()) {
      hint = box_around(*position);
      // The hint cuts a new template from the frame on screen, where the marker is now (the
      // session keeps its pixels for `s`), or is the colour tracker's first search box.
    }
    apply_spec(i, spec, hint);
  }
  say("method: " + next);
}

void LiveController::set_hsv(int trackbar, int value) {
  if (trackbar < 0 || trackbar >= static_cast<int>(kHsvTrackbars.size())) return;
  value = std::clamp(value, 0, kHsvTrackbars[trackbar].max);
  MarkerSpec spec = config().markers[active_];
  // A template marker's ranges are the ones set aside for its colour method.
  auto* own = spec.params.get_if<ColourParams>();
  ColourParams& colour = own ? *own : colour_set_aside(active_);
  HsvRange* ranges[3] = {&colour.h, &colour.s, &colour.v};
  int& field = trackbar % 2 == 0 ? ranges[trackbar / 2]->lo : ranges[trackbar / 2]->hi;
  if (field == value) return;  // The adapter moving its own trackbar: nothing changed.
  remember_for_undo(active_, "range change", /*coalesce=*/true);
  field = value;
  colour.auto_bgr.reset();
  const std::string text = spec.name + ": h " + RangeText(colour.h) + " s " +
                           RangeText(colour.s) + " v " + RangeText(colour.v);
  if (own) apply_spec(active_, spec, std::nullopt);
  say(text);
}

ColourParams LiveController::colour_of(int marker) const {
  if (const auto* own = config().markers[marker].params.get_if<ColourParams>()) return *own;
  for (const MarkerParams& params : aside_[marker]) {
    if (const auto* colour = params.get_if<ColourParams>()) return *colour;
  }
  return ColourParams{};
}

ColourParams& LiveController::colour_set_aside(int marker) {
  for (MarkerParams& params : aside_[marker]) {
    if (auto* colour = params.get_if<ColourParams>()) return *colour;
  }
  return aside_[marker].emplace_back(ColourParams{}).get<ColourParams>();
}

std::array<int, 6> LiveController::active_hsv() const {
  const ColourParams c = colour_of(active_);
  return {c.h.lo, c.h.hi, c.s.lo, c.s.hi, c.v.lo, c.v.hi};
}

void LiveController::save_config() {
  save_config_to(options_.save_config_path.empty() ? "live.yaml" : options_.save_config_path);
}

void LiveController::save_config_to(const std::string& path) {
  try {
    // The session's config, and each marker's parameters of its other kinds as the window
    // keeps them (ranges picked or moved while it matched templates), so that loading the file
    // and switching method finds them again.
    TrackingConfig saved = config();
    saved.params_aside.clear();
    for (size_t i = 0; i < saved.markers.size(); ++i) {
      if (!aside_[i].empty()) saved.params_aside[saved.markers[i].name] = aside_[i];
    }
    SaveLiveConfig(saved, path);
    say("saved " + path);
  } catch (const InputError& e) {
    say(e.what());
  }
}

void LiveController::load_markers_from(const std::string& path) {
  TrackingConfig loaded;
  try {
    loaded = LoadTrackingConfig(path);
  } catch (const InputError& e) {
    say(std::string("load: ") + e.what());
    return;
  }
  // Every marker must be there by name, and no other: the run's markers (its CSV's columns,
  // its base-middle-tip triple) stay what they are.
  const std::vector<MarkerSpec>& markers = config().markers;
  std::vector<const MarkerSpec*> specs;
  for (const MarkerSpec& marker : markers) {
    const auto found = std::find_if(loaded.markers.begin(), loaded.markers.end(),
                                    [&](const MarkerSpec& m) { return m.name == marker.name; });
    if (found == loaded.markers.end() || loaded.markers.size() != markers.size()) {
      say("load: " + path + " has other markers than this run (" + std::to_string(loaded.markers.size()) +
          ", " + (found == loaded.markers.end() ? "no " + marker.name : std::string("not the same names")) +
          "); nothing changed");
      return;
    }
    specs.push_back(&*found);
  }
  for (size_t i = 0; i < specs.size(); ++i) {
    const int marker = static_cast<int>(i);
    remember_for_undo(marker, "load of " + path);
    const auto aside = loaded.params_aside.find(specs[i]->name);
    aside_[i] = aside != loaded.params_aside.end() ? aside->second : std::vector<MarkerParams>{};
    apply_spec(marker, *specs[i], std::nullopt);
  }
  ++hsv_revision_;
  say("loaded " + path + ": " + std::to_string(specs.size()) + " markers (u undoes them one by one)");
}

void LiveController::start_scale() {
  if (recording() && options_.scale_distance_mm) {
    // The CSV's columns (with or without _mm) are fixed when a recording starts.
    say("scale: stop the recording first (r)");
    return;
  }
  say(scale_.start());
}

void LiveController::cancel_scale() {
  scale_.stop();
  pointer_->forget_pointer();
  say("scale: cancelled, unchanged");
}

void LiveController::scale_point(const cv::Point2d& p) {
  // The scale is in the pixels the measurements use (undistorted with a camera model), and
  // those are the points a saved config holds as scale_from_points.
  std::string message;
  const std::optional<MetricModel> metric = scale_.add(p, session().measurement_point(p), &message);
  if (!metric) {
    say(message);
    return;
  }
  if (std::string refused; !apply_scale(*metric, scale_.span_px(), *options_.scale_distance_mm, &refused)) {
    scale_.restart();
    say(refused + "; click the first point again");
    return;
  }
  scale_.stop();
  pointer_->forget_pointer();
}

void LiveController::set_scale_from_points(const cv::Point2d& a_px, const cv::Point2d& b_px,
                                           double distance_mm) {
  if (recording()) {
    // The CSV's columns (with or without _mm) are fixed when a recording starts.
    say("scale: stop the recording first (r)");
    return;
  }
  ScaleClicks clicks(distance_mm);
  clicks.start();
  std::string message;
  clicks.add(a_px, session().measurement_point(a_px), &message);
  const std::optional<MetricModel> metric =
      clicks.add(b_px, session().measurement_point(b_px), &message);
  if (!metric) {
    // ScaleClicks speaks of clicking again: the page's two points are placed again there.
    say(message.substr(0, message.find("; click")));
    return;
  }
  if (std::string refused; !apply_scale(*metric, clicks.span_px(), distance_mm, &refused)) say(refused);
}

bool LiveController::apply_scale(const MetricModel& metric, double span_px, double distance_mm,
                                 std::string* refused) {
  const bool replaced_plane = config().measure.metric.plane_mm_from_image.has_value();
  try {
    session().set_metric(metric);
  } catch (const InputError& e) {
    *refused = e.what();
    return false;
  }
  // Measure the frame on screen again, so the mm values appear now, also while paused. The
  // strip chart restarts in mm: its px history cannot share the new axis.
  if (!frame_.empty()) {
    const Frame again{frame_, frame_index_, frame_time_s_};
    show(pipeline_->measure_again(again));
    chart_.clear();
    chart_.add(*last_result_);
  }
  say("scale " + FixedNumber(*metric.scale_mm_per_px, 4) + " mm/px (" + DistanceText(distance_mm) +
      " mm over " + FixedNumber(span_px, 1) + " px" +
      (replaced_plane ? ", replaces the plane homography" : "") + "); s saves it");
  return true;
}

std::string LiveController::stop_recording() {
  const int64_t frames = pipeline_->stop_recording();
  return "recorded " + std::to_string(frames) + " frames to " + last_recording() + ".*";
}

void LiveController::toggle_recording() {
  if (recording()) {
    say(stop_recording());
    return;
  }
  if (frame_.empty()) {
    say("nothing to record yet");
    return;
  }
  try {
    // The recording must be reproducible: `softsight track --config <prefix>.yaml --input
    // <prefix>.raw.avi` has to give the same rows. So the recording starts with the frame on
    // screen as its frame 0, and every tracker is rebuilt from the saved config exactly as
    // `track` builds it: a search box, or a template cut on frame 0, around where each marker is
    // now (LivePipeline::start_recording).
    std::vector<std::optional<cv::Rect>> boxes;
    for (int i = 0; i < static_cast<int>(config().markers.size()); ++i) {
      const auto position = position_of(i);
      boxes.push_back(position ? std::optional(box_around(*position)) : std::nullopt);
    }
    const Frame again{frame_.clone(), frame_index_, frame_time_s_};
    show(pipeline_->start_recording(
        again, boxes, options_.record_fps.value_or(meter_.fps().value_or(30.0)),
        [this](cv::Mat& canvas, const FrameResult& result) { draw_overlay(canvas, result); }));
    // The recording's templates are cut from this frame (their configs say "rect on frame 0"):
    // their pixels, for `u` to restore after the frame is gone.
    recording_cuts_.assign(boxes.size(), {});
    for (size_t i = 0; i < boxes.size(); ++i) {
      if (boxes[i]) recording_cuts_[i] = {*boxes[i], again.image(*boxes[i]).clone()};
    }
    ++hsv_revision_;
    say("recording to " + pipeline_->recording_prefix() + ".*");
    report_recording_failure();
  } catch (const InputError& e) {
    say(e.what());
  }
}

Frame LiveController::on_screen() const { return Frame{frame_, frame_index_, frame_time_s_}; }

void LiveController::show(const FrameResult& result) {
  last_result_ = result;
  if (has_timeline_) {
    // A frame tracked again (a reselection) may now find every marker: the mark follows.
    const bool lost = std::any_of(result.markers.begin(), result.markers.end(),
                                  [](const MarkerObservation& m) { return !m.observation.found(); });
    timeline_.mark(position_, Timeline::kLost, lost);
  }
  chart_.add(result);  // A frame measured again (re-tracked, reselected) replaces its sample.
  redraw_annotated();
  dirty_ = true;
}

void LiveController::set_screen(cv::Size screen_px) {
  max_canvas_ = screen_px.area() > 0 ? MaxCanvasForScreen(screen_px) : cv::Size();
  dirty_ = true;
}

LiveLayout LiveController::layout() const {
  const cv::Size image_size = frame_.empty() ? cv::Size(640, 480) : frame_.size();
  const int help_width = help_ ? HelpPanelWidth() : 0;
  return ComputeLiveLayout(image_size, options_.chart.height_px, help_width, max_canvas_,
                           StatusBandHeight(), has_timeline_, zoom_);
}

cv::Point2d LiveController::to_view(const cv::Point2d& image_px) const {
  return layout().to_view(image_px);
}

cv::Point2d LiveController::to_image(const cv::Point2d& view_px) const {
  return layout().to_image(view_px);
}

void LiveController::on_event(const UiEvent& event) {
  handle(event);
  // An edit the running recording could not keep stopped it: say so, over the edit's message.
  report_recording_failure();
}

void LiveController::handle(const UiEvent& event) {
  using Type = UiEvent::Type;
  // A trackbar drag is one edit for `u`; anything else in between starts a new one.
  if (event.type != Type::kTrackbar && !undo_.empty()) undo_.back().coalescing = false;
  // The pointer works in image pixels: the canvas may show the image scaled down.
  const LiveLayout view = layout();
  const cv::Point2d at = view.to_image(event.position_px);
  const bool in_image = view.image.contains(cv::Point(cvFloor(event.position_px.x),
                                                      cvFloor(event.position_px.y))) &&
                        at.x >= -0.5 && at.y >= -0.5 && at.x < frame_.cols - 0.5 &&
                        at.y < frame_.rows - 0.5;
  if (event.type == Type::kMouseDown || event.type == Type::kMouseMove ||
      event.type == Type::kMouseUp) {
    if (in_image) pointer_image_ = at;
    if (has_timeline_ && scrub(event, view)) return;
  }
  switch (event.type) {
    case Type::kPanDown:
      pan_from_ = at;
      break;
    case Type::kPanMove:
      // The image point under the pointer at the press stays under it.
      if (pan_from_ && !frame_.empty()) {
        zoom_ = zoom_.panned(*pan_from_ - at, frame_.size());
        dirty_ = true;
      }
      break;
    case Type::kMouseDown:
      if (pointer_->down(at, in_image)) dirty_ = true;
      break;
    case Type::kMouseMove:
      // In scale mode the pointer is followed without a button too: the line to the first point.
      if (pointer_->move(at, scale_.active())) dirty_ = true;
      break;
    case Type::kMouseUp:
      release_pointer(event, at, in_image);
      break;
    case Type::kTrackbar:
      set_hsv(event.trackbar, event.value);
      break;
    case Type::kKey:
      press_key(event);
      break;
  }
}

// A button released: the scale's point, a click (a marker, or colours in the mask view) or a
// dragged box.
void LiveController::release_pointer(const UiEvent& event, const cv::Point2d& at, bool in_image) {
  const PointerGesture gesture = pointer_->up(at, in_image);
  if (gesture.kind == PointerGesture::Kind::kNone) return;
  dirty_ = true;
  if (scale_.active()) {
    // Where the button is released, so a person can press, aim and let go.
    scale_point(gesture.release);
  } else if (gesture.kind == PointerGesture::Kind::kClick) {
    if (event.shift || mask_view_) {
      edit_range(gesture.press, !event.shift);
    } else {
      click(gesture.press);
    }
  } else {
    drag(gesture.box);
  }
}

// A key: the playback, the view, the edits, the recording, quitting.
void LiveController::press_key(const UiEvent& event) {
  switch (event.key) {
    case 'h':
      help_ = !help_;
      dirty_ = true;
      break;
    case ' ':
    case 'p':
      if (ended_ && !loop_) {
        request_playback(PlaybackRequest::Kind::kStart);
        paused_ = false;
        say("playing from the first frame");
        break;
      }
      paused_ = !paused_;
      meter_.restart();  // A pause is no slow playback: the rates start over.
      say(paused_ ? "paused" : "running");
      break;
    case '.':
    case ',':
    case ']':
    case kKeyRight:
    case '[':
    case kKeyLeft:
    case '<':
    case kKeyHome:
    case '>':
    case kKeyEnd: {
      const auto [kind, seconds] = PlaybackKey(event.key);
      request_playback(kind, seconds);
      break;
    }
    case 'v':
      mask_view_ = !mask_view_;
      say(mask_view_ ? "mask view of " + config().markers[active_].name +
                           ": click adds colours, shift-click removes them"
                     : "mask view off");
      break;
    case 'l':
      loop_ = !loop_;
      say(loop_ ? "loop on" : "loop off");
      break;
    case '0':
      restart();
      break;
    case 'r':
      toggle_recording();
      break;
    case 's':
      save_config();
      break;
    case 'b':
      session().reset_tip_reference();
      say("bending distance: the next tip position is the new reference");
      break;
    case 'm':
      switch_method();
      break;
    case 'u':
      undo();
      break;
    case '}':
      change_speed(+1);
      break;
    case '{':
      change_speed(-1);
      break;
    case '+':
    case '=':
    case '-': {
      // At the pointer when it is over the image, else at the middle of what is shown.
      const cv::Point2d middle =
          zoom_.origin_px + cv::Point2d(frame_.cols, frame_.rows) * (0.5 / zoom_.zoom) -
          cv::Point2d(0.5, 0.5);
      zoom_at(pointer_image_.value_or(middle), event.key == '-' ? 1 / kZoomStep : kZoomStep);
      break;
    }
    case 'z':
      zoom_ = {};
      dirty_ = true;
      break;
    case 'c':
      start_scale();
      break;
    case 27:
      if (scale_.active()) {
        cancel_scale();
        break;
      }
      [[fallthrough]];
    case 'q':
      if (recording()) toggle_recording();
      quit_ = true;
      break;
    default:
      if (event.key >= '1' && event.key <= '9') select_marker(event.key - '1');
  }
}

std::vector<std::string> LiveController::status_lines() const {
  std::vector<std::string> lines;
  std::string state;
  if (recording()) state += "REC " + pipeline_->recording_prefix() + "  ";
  if (paused_) state += "PAUSED  ";
  if (ended_) state += "END  ";
  if (loop_) state += "LOOP  ";
  if (speed() != 1.0) state += FixedNumber(speed(), speed() < 1 ? 2 : 0) + "x  ";
  if (dropped_ > 0) state += "dropped " + std::to_string(dropped_) + "  ";
  state +=
      "active: " + config().markers[active_].name + " (" +
      TrackerMethodName(config().markers[active_].params) + ")";
  if (const auto& scale = config().measure.metric.scale_mm_per_px) {
    state += "  " + FixedNumber(*scale, 4) + " mm/px";
  }
  lines.push_back(state);
  if (seeking_) {
    lines.push_back("seeking...");
  } else if (!message_.empty()) {
    lines.push_back(message_);
  }
  // The hint stays while picking, whatever other keys say meanwhile.
  if (scale_.active() && message_ != scale_.hint()) lines.push_back(scale_.hint());
  return lines;
}

const Tracker& LiveController::active_tracker() const {
  return pipeline_->session().tracker(active_);
}

const cv::Mat& LiveController::canvas() {
  if (!dirty_ && !view_.canvas().empty()) return view_.canvas();
  LiveViewState state;
  state.frame = &frame_;
  state.annotated = &annotated_;
  state.lines = status_lines();
  state.recording = recording();
  state.mask_view = mask_view_;
  state.tracker = &pipeline_->session().tracker(active_);
  state.active = &config().markers[active_];
  state.scale_mode = scale_.active();
  state.scale_points = scale_.points();
  state.press = pointer_->press();
  state.pointer = pointer_->pointer();
  state.chart = &chart_;
  state.timeline = has_timeline_ ? &timeline_ : nullptr;
  dirty_ = false;
  return view_.compose(layout(), state);
}

}  // namespace softsight
