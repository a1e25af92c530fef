#include "softsight/pipeline/tracking_session.h"

#include <chrono>

#include <opencv2/core/utility.hpp>

#include <algorithm>

#include "pipeline/frame_change.h"
#include "pipeline/arrangement_check.h"
#include "pipeline/marker_tracks.h"
#include "softsight/core/error.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {
namespace {

// About the marker's radius, from what the config says of its size (its kind knows: a template or
// roi rectangle drawn around it, a search window): the unit of how far it may move beyond its
// predicted position in one frame.
double MarkerSizePx(const MarkerSpec& spec) {
  const double size = spec.params.kind().size_hint_px(spec.params);
  return std::clamp(size > 0.0 ? size : 16.0, 4.0, 64.0);
}

// The markers along one body, base to tip, by index: the chain, else the triple.
std::vector<size_t> BodyOrder(const TrackingConfig& config) {
  std::vector<std::string> names = config.measure.chain;
  if (names.empty() && config.measure.has_triple()) {
    names = {config.measure.base, config.measure.middle, config.measure.tip};
  }
  std::vector<size_t> body;
  for (const std::string& name : names) {
    for (size_t i = 0; i < config.markers.size(); ++i) {
      if (config.markers[i].name == name) body.push_back(i);
    }
  }
  return body.size() == names.size() ? body : std::vector<size_t>();
}

// Frames missing from the source predicted over at most (two seconds at 30 fps): longer, a
// track is lost anyway and its gate needs to grow no further.
constexpr int64_t kMaxMissingFramesPredicted = 60;

// A marker's report on a frame its tracker tracks afresh, once a person chose its place or asked
// it to look again: not started when the tracker could not start, implausible when the whole
// frame changed, else the tracker's own. A new track: it starts on this report at the next
// frame's association.
void TrackAfresh(MarkerObservation& marker, bool started, bool whole_frame_changed,
                 Tracker& tracker, const cv::Mat& image) {
  if (!started) {
    marker.observation = Observation::NotFound(MarkerStatus::kNotStarted);
  } else if (whole_frame_changed) {
    marker.observation = Observation::NotFound(MarkerStatus::kImplausible);
  } else {
    marker.observation = tracker.update(image);
  }
  marker.track = marker.observation.found() ? TrackState::kTentative : TrackState::kLost;
}

}  // namespace

TrackingSession::TrackingSession(const TrackingConfig& config)
    : config_(config), measurer_(config.measure) {
  std::vector<double> sizes;
  for (const MarkerSpec& spec : config_.markers) {
    trackers_.push_back(CreateTracker(spec));
    initialised_.push_back(false);
    result_.markers.push_back({spec.name, {}});
    sizes.push_back(MarkerSizePx(spec));
  }
  frame_change_ = std::make_unique<FrameChangeDetector>();
  arrangement_ = std::make_unique<ArrangementCheck>(sizes.size(), BodyOrder(config_));
  motion_support_.assign(sizes.size(), std::nullopt);
  tracks_ = std::make_unique<MarkerTracks>(sizes);
  candidate_lists_.resize(trackers_.size());
  if (config_.camera) {
    undistorter_.emplace(*config_.camera);
    undistorted_ = result_.markers;
  }
}

TrackingSession::~TrackingSession() = default;
TrackingSession::TrackingSession(TrackingSession&&) noexcept = default;
TrackingSession& TrackingSession::operator=(TrackingSession&&) noexcept = default;

void TrackingSession::restart(const TrackingConfig& config) {
  TrackingSession fresh(config);  // Throws before anything here changes.
  fresh.edit_listener_ = std::move(edit_listener_);
  *this = std::move(fresh);
}

const FrameResult& TrackingSession::process(const Frame& frame) {
  const int64_t start = cv::getTickCount();
  // Frames the source skipped (a camera that dropped them, an image sequence with numbers
  // missing, frames a reader could not decode) passed for the markers too: their motion is
  // predicted over each, as over a frame in which nothing was believed, so the gate reaches as
  // far as they could have moved meanwhile. (A source that hides its drops cannot be helped.)
  if (last_frame_ >= 0 && frame.index > last_frame_ + 1) {
    const int64_t missing = std::min<int64_t>(frame.index - last_frame_ - 1, kMaxMissingFramesPredicted);
    for (int64_t k = 0; k < missing; ++k) tracks_->skip();
  }
  last_frame_ = frame.index;
  // A live recording's raw video names the live source's frames (config.recording).
  result_.frame_index = frame.index;
  result_.time_s = frame.time_s;
  if (config_.recording) {
    result_.frame_index += config_.recording->first_frame;
    result_.time_s += config_.recording->first_time_s;
  }
  for (size_t i = 0; i < trackers_.size(); ++i) {
    // Each tracker knows from its parameters when and how it can start. One that cannot yet (a
    // template not selected, or its reference frame still ahead) has nothing to look for.
    if (!initialised_[i]) initialised_[i] = trackers_[i]->start(frame);
    if (!initialised_[i]) result_.markers[i].observation = Observation::NotFound(MarkerStatus::kNotStarted);
  }
  if (frame.repeated) {
    // The live source handed out its last picture again: nothing in it is a new measurement.
    // The trackers do not see it; the tracks are predicted over it, as over a lost frame.
    for (size_t i = 0; i < trackers_.size(); ++i) {
      if (initialised_[i]) result_.markers[i].observation = Observation::NotFound(MarkerStatus::kStale);
    }
    tracks_->skip();
    return finish(frame, start);
  }
  frame_change_->observe(frame.image, frame.key_frame);
  if (frame_change_->whole_frame_changed()) {
    // Nothing in this frame is believed, and the trackers do not see it: their windows, motion
    // and learned models stay as they were in the last believable frame.
    for (size_t i = 0; i < trackers_.size(); ++i) {
      if (initialised_[i]) {
        result_.markers[i].observation = Observation::NotFound(MarkerStatus::kImplausible);
      }
    }
    tracks_->skip();
  } else {
    for (size_t i = 0; i < trackers_.size(); ++i) {
      if (initialised_[i]) result_.markers[i].observation = trackers_[i]->update(frame.image);
      candidate_lists_[i] = initialised_[i] ? &trackers_[i]->candidates() : nullptr;
    }
    // Which candidate is which marker, for all markers at once with their motion: a report no
    // motion explains, or that another marker's track explains better, is not believed; a
    // candidate the tracker weighed but did not choose may be its marker.
    // A marker believed a frame ago that now has no report where its motion puts it: if the
    // whole picture moved (a bumped camera), the tracks move with it first.
    if (tracks_->AnyJustLost(result_.markers)) {
      std::optional<cv::Point2d> shift = frame_change_->camera_shift_px();
      if (!shift) shift = tracks_->CommonShift(result_.markers);
      if (shift) tracks_->FollowCamera(result_.markers, *shift);
    }
    const FrameChangeDetector& change = *frame_change_;
    const std::vector<MarkerTracks::Decision>& decisions = tracks_->associate(
        result_.markers, candidate_lists_,
        [&change](const cv::Point2d& p) { return change.garbage_near(p); });
    for (size_t i = 0; i < trackers_.size(); ++i) {
      // Where the other markers' arrangement puts it: its own motion before (a jump with its
      // body, or a stretch lost) is no evidence against it; the arrangement still judges it.
      if (decisions[i].vouched_by_body) arrangement_->forget(i);
      switch (decisions[i].action) {
        case MarkerTracks::Decision::Action::kKeep:
          // A track restarted on its tracker's own run of reports: that run is the evidence,
          // not a suspicion from before it; the arrangement still judges it.
          if (tracks_->restarting(i)) arrangement_->forget(i);
          break;
        case MarkerTracks::Decision::Action::kReject:
          trackers_[i]->reset();
          break;
        case MarkerTracks::Decision::Action::kAdopt:
          if (std::optional<Observation> o = trackers_[i]->adopt(decisions[i].candidate)) {
            result_.markers[i].observation = *o;
          } else {
            result_.markers[i].observation = Observation::NotFound(MarkerStatus::kImplausible);
            trackers_[i]->reset();
          }
          break;
      }
    }
  }
  // The body's arrangement judges what is left, each report weighed by how well it continues its
  // own track (the one motion model's verdict).
  for (size_t i = 0; i < result_.markers.size(); ++i) {
    const Observation& o = result_.markers[i].observation;
    motion_support_[i] = o.found() ? tracks_->MotionSupport(i, *o.position_px) : std::nullopt;
  }
  for (size_t i : arrangement_->check(result_.markers, motion_support_)) trackers_[i]->reset();
  if (!frame_change_->whole_frame_changed()) tracks_->commit(result_.markers);
  return finish(frame, start);
}

const FrameResult& TrackingSession::finish(const Frame& frame, int64_t start_ticks) {
  for (size_t i = 0; i < result_.markers.size(); ++i) result_.markers[i].track = tracks_->state(i);
  measure(frame);
  result_.proc_ms = 1000.0 * static_cast<double>(cv::getTickCount() - start_ticks) /
                    cv::getTickFrequency();
  result_.captured = frame.captured;
  result_.latency_result_ms =
      frame.captured == std::chrono::steady_clock::time_point{}
          ? 0.0
          : std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                      frame.captured)
                .count();
  if (next_change_ < config_.changes.size() &&
      config_.changes[next_change_].after_frame <= frame.index) {
    apply_changes(frame);
  }
  return result_;
}

void TrackingSession::apply_changes(const Frame& frame) {
  // The live window made these edits after showing (and recording) this frame's row: the row
  // stays as it was, and the trackers, checks and measurer continue from the edits, as live.
  const FrameResult row = result_;
  while (next_change_ < config_.changes.size() &&
         config_.changes[next_change_].after_frame <= frame.index) {
    const ConfigChange change = config_.changes[next_change_++];  // A copy: respec edits config_.
    switch (change.kind) {
      case ConfigChange::Kind::kRespec:
        respec(change.spec);
        break;
      case ConfigChange::Kind::kReselect:
        reselect(change.marker, frame, change.rect);
        break;
      case ConfigChange::Kind::kRetrack:
        retrack(change.marker, frame);
        break;
      case ConfigChange::Kind::kResetTipReference:
        reset_tip_reference();
        break;
    }
  }
  result_ = row;
}

void TrackingSession::measure(const Frame& frame) {
  if (undistorter_) {
    if (frame.image.size() != undistorter_->camera().image_size) {
      const cv::Size calibrated = undistorter_->camera().image_size;
      throw InputError(config_.camera_file.value_or("camera") + ": calibrated for " +
                       std::to_string(calibrated.width) + "x" + std::to_string(calibrated.height) +
                       " images, but frame " + std::to_string(frame.index) + " is " +
                       std::to_string(frame.image.cols) + "x" + std::to_string(frame.image.rows));
    }
    for (size_t i = 0; i < result_.markers.size(); ++i) {
      undistorted_[i].observation = result_.markers[i].observation;
      if (undistorted_[i].observation.found()) {
        undistorted_[i].observation.position_px =
            undistorter_->undistort_point(*result_.markers[i].observation.position_px);
      }
    }
    measurer_.measure(undistorted_, result_.measurement);
  } else {
    measurer_.measure(result_.markers, result_.measurement);
  }
}

const FrameResult& TrackingSession::reselect(const std::string& marker, const Frame& frame,
                                             const cv::Rect& rect) {
  for (size_t i = 0; i < trackers_.size(); ++i) {
    if (config_.markers[i].name != marker) continue;
    trackers_[i]->init(frame.image, rect);
    initialised_[i] = true;
    arrangement_->forget(i);  // A person said where it is: nothing to suspect.
    tracks_->forget(i);
    // ... nor another marker's last place there (the person may have swapped two markers).
    tracks_->forget_places();
    // Saved configs must reproduce what the mouse did (the marker's kind says how: a template's
    // own pixels, cut here, or a colour marker's roi from this frame), so that `track` starts it
    // there and then, as here. A template file held the old template.
    MarkerParams& params = config_.markers[i].params;
    params.kind().remember_selection(params, frame, rect);
    config_.template_files.erase(marker);
    // The selection's frame is tracked by the new tracker at once, as `track` tracks a template's
    // reference frame: the window shows the new result now, and the tracker has seen the frames
    // it would have seen in `track`. The other markers already saw this frame; the joint checks
    // are not repeated (the person chose this place).
    TrackAfresh(result_.markers[i], initialised_[i], frame_change_->whole_frame_changed(),
                *trackers_[i], frame.image);
    measure(frame);
    edited(ConfigChange::Reselect(marker, rect));
    return result_;
  }
  throw InputError("no marker named '" + marker + "'");
}

const FrameResult& TrackingSession::retrack(const std::string& marker, const Frame& frame) {
  for (size_t i = 0; i < trackers_.size(); ++i) {
    if (config_.markers[i].name != marker) continue;
    if (!initialised_[i]) initialised_[i] = trackers_[i]->start(frame);
    arrangement_->forget(i);
    tracks_->forget(i);
    TrackAfresh(result_.markers[i], initialised_[i], frame_change_->whole_frame_changed(),
                *trackers_[i], frame.image);
    measure(frame);
    edited(ConfigChange::Retrack(marker));
    return result_;
  }
  throw InputError("no marker named '" + marker + "'");
}

void TrackingSession::respec(const MarkerSpec& spec) {
  for (size_t i = 0; i < trackers_.size(); ++i) {
    if (config_.markers[i].name != spec.name) continue;
    trackers_[i] = CreateTracker(spec);
    // An image file names the pixels it was read into; a spec without them is no longer it.
    const MarkerParams& before = config_.markers[i].params;
    const cv::Mat* image_before = before.kind().image(before);
    const cv::Mat* image_after = spec.params.kind().image(spec.params);
    if (!image_before || !image_after || image_before->data != image_after->data) {
      config_.template_files.erase(spec.name);
    }
    config_.markers[i] = spec;
    initialised_[i] = false;
    arrangement_->forget(i);
    tracks_->forget(i);
    edited(ConfigChange::Respec(spec));
    return;
  }
  throw InputError("no marker named '" + spec.name + "'");
}

void TrackingSession::reset_tip_reference() {
  measurer_.reset_tip_reference();
  edited(ConfigChange::ResetTipReference());
}

void TrackingSession::edited(ConfigChange change) const {
  if (!edit_listener_) return;
  change.after_frame = std::max<int64_t>(0, last_frame_);
  edit_listener_(change);
}

void TrackingSession::jump() {
  for (size_t i = 0; i < trackers_.size(); ++i) {
    if (initialised_[i]) trackers_[i]->reset();
    arrangement_->forget(i);
    tracks_->forget(i);
  }
  frame_change_ = std::make_unique<FrameChangeDetector>();
  last_frame_ = -1;  // The frame sought is no later frame of the same run: nothing went missing.
}

void TrackingSession::set_metric(const MetricModel& metric) {
  measurer_.set_metric(metric);  // Checks first: throws before anything changes.
  config_.measure.metric = metric;
}

cv::Point2d TrackingSession::measurement_point(const cv::Point2d& image_px) const {
  return undistorter_ ? undistorter_->undistort_point(image_px) : image_px;
}

}  // namespace softsight
