#include "softsight/pipeline/stereo_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>

#include "softsight/core/error.h"
#include "softsight/pipeline/tracking_session.h"

namespace softsight {
namespace {

std::string SizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

// The markers measured in 3D, base to tip: the chain, else the triple, else none.
std::vector<std::string> ChainOf(const MeasureOptions& measure) {
  if (!measure.chain.empty()) return measure.chain;
  if (measure.has_triple()) return {measure.base, measure.middle, measure.tip};
  return {};
}

const Observation* FindObservation(const FrameResult& result, const std::string& name) {
  for (const MarkerObservation& m : result.markers) {
    if (m.name == name) return &m.observation;
  }
  return nullptr;
}

}  // namespace

// Whether the two views' frames of a pair are of one moment, from the markers' own motion. The
// epipolar check cannot see a wrong pairing of a marker moving along its epipolar line: the
// right view's point stays on the line and only the depth comes out wrong (a wrong
// --frame-offset: up to 38 mm, and out-of-plane angles of 80-90 deg where the truth is 0).
// But when the right frames are `lag` frames later than the left ones' moments, the right point
// of right frame j lies where the marker was at right frame j - lag, and its signed distance from
// the epipolar line is the motion across the line between the two: d_j ~= n_j . (R_j - R_{j-lag}).
// Every lag within kMaxLagFrames is fitted so to the last pairs of every marker (each marker with
// its own constant: a calibration's offset from the line is not motion); a lag other than 0 that
// explains the distances far better than 0 does, beyond the points' noise, says the pairs are not
// of one moment. From then on (until 0 fits again) only a marker at rest is believed: one whose
// point moved in either view over the last frames by more than a quarter of the epipolar limit is
// not (kTiming): the views show it at two places of its path, its depth off by as much as it moved
// along the line. The first pairs of a run, before any marker has moved across its line, cannot
// be judged.
class StereoPairingCheck {
 public:
  explicit StereoPairingCheck(size_t markers) : markers_(markers) {}

  // Marker `i`'s pair (raw pixels; both views found it), the right one from right frame
  // `right_frame`: adds its evidence; returns how far the marker moved in either view over the
  // last frames (px, the largest of the spans back to each of them), when it was found there.
  std::optional<double> add(const Triangulator& triangulator, size_t i, const cv::Point2d& left_px,
                            const cv::Point2d& right_px, int64_t right_frame) {
    Marker& m = markers_[i];
    if (!m.history.empty() && m.last_right_frame + 1 != right_frame) {
      // A repeated right frame (paired by time) adds nothing; a gap starts the history again.
      if (m.last_right_frame == right_frame) return m.last_motion;
      m.history.clear();
    }
    Entry entry;
    entry.left_px = left_px;
    entry.right_px = right_px;
    entry.distance = triangulator.signed_epipolar_distance_px(left_px, right_px, &entry.normal);
    std::optional<double> motion;
    if (!m.history.empty()) {
      motion = 0.0;
      const size_t first = m.history.size() > kRecentFrames ? m.history.size() - kRecentFrames : 0;
      for (size_t k = first; k < m.history.size(); ++k) {
        motion = std::max({*motion, cv::norm(right_px - m.history[k].right_px),
                           cv::norm(left_px - m.history[k].left_px)});
      }
    }
    m.history.push_back(entry);
    if (m.history.size() > kWindowPairs + 2 * kMaxLagFrames) m.history.pop_front();
    m.last_right_frame = right_frame;
    m.last_motion = motion;
    return motion;
  }
  // The marker was not seen in both views: its motion is unknown until it is again.
  void lose(size_t i) { markers_[i].history.clear(); }

  // Updates the verdict with the evidence so far and returns it: the lag of the right frames (in
  // the right view's frames; positive: the right frame is later than the left one's moment)
  // while the pairs are judged not of one moment, else none.
  std::optional<double> update(double sigma_px) {
    // Per candidate lag: the squared residuals (about each marker's own mean) and their count,
    // over the pairs whose partner frame is in the history.
    std::vector<double> sse(2 * kMaxLagFrames + 1, 0.0), count(sse.size(), 0.0);
    for (const Marker& m : markers_) {
      const int size = static_cast<int>(m.history.size());
      for (int lag = -kMaxLagFrames; lag <= kMaxLagFrames; ++lag) {
        const int first = std::max(0, lag), last = std::min(size, size + lag);
        if (last - first < 3) continue;
        double sum = 0.0, sum_sq = 0.0;
        for (int j = first; j < last; ++j) {
          const Entry& e = m.history[static_cast<size_t>(j)];
          const cv::Point2d step = e.right_px - m.history[static_cast<size_t>(j - lag)].right_px;
          const double residual = e.distance - (step.x * e.normal[0] + step.y * e.normal[1]);
          sum += residual;
          sum_sq += residual * residual;
        }
        const size_t k = static_cast<size_t>(lag + kMaxLagFrames);
        sse[k] += sum_sq - sum * sum / (last - first);
        count[k] += last - first - 1;  // One degree of freedom for the marker's mean.
      }
    }
    std::optional<int> best;
    double best_mean = 0.0;
    for (int lag = -kMaxLagFrames; lag <= kMaxLagFrames; ++lag) {
      const size_t k = static_cast<size_t>(lag + kMaxLagFrames);
      if (count[k] < 3.0) continue;
      if (!best || sse[k] / count[k] < best_mean) {
        best = lag;
        best_mean = sse[k] / count[k];
      }
    }
    const size_t zero = kMaxLagFrames;
    if (!best || count[zero] < 3.0) return lag_;
    const double at_zero = sse[zero] / count[zero], noise = sigma_px * sigma_px;
    if (*best != 0 && at_zero > 9.0 * noise && best_mean < 0.25 * at_zero) {
      lag_ = *best;
    } else if (*best == 0 || at_zero <= 4.0 * noise) {
      lag_.reset();  // Of one moment (again).
    }
    return lag_;
  }

 private:
  static constexpr int kMaxLagFrames = 8;
  static constexpr size_t kWindowPairs = 30;
  static constexpr size_t kRecentFrames = 8;
  struct Entry {
    cv::Point2d left_px, right_px;
    double distance = 0.0;  // Signed distance of the right point from its epipolar line (px).
    cv::Vec2d normal;       // That line's unit normal.
  };
  struct Marker {
    std::deque<Entry> history;  // Contiguous right frames, oldest first.
    int64_t last_right_frame = 0;
    std::optional<double> last_motion;
  };
  std::vector<Marker> markers_;
  std::optional<double> lag_;
};

bool StereoOptions::Check(std::string* error) const {
  if (reference_plane == ReferencePlane::kBoard) {
    if (!board_normal) {
      *error = "reference_plane: board needs board_normal (a bench board's plane)";
      return false;
    }
    const double length = cv::norm(*board_normal);
    if (!(std::isfinite(length) && length > 0.0)) {
      *error = "board_normal: must be a finite, non-zero vector";
      return false;
    }
  }
  return triangulation.Check(error);
}

StereoOptions::ReferencePlane ParseReferencePlane(const std::string& text,
                                                  const std::string& what) {
  if (text == "image") return StereoOptions::ReferencePlane::kImage;
  if (text == "first") return StereoOptions::ReferencePlane::kFirstFrame;
  if (text == "board") return StereoOptions::ReferencePlane::kBoard;
  throw InputError(what +
                   ": expected image (the first camera's image plane), first (the first "
                   "frame's bending plane) or board (the bench board's plane), got '" +
                   text + "'");
}

struct StereoSession::Impl {
  Impl(const TrackingConfig& left_config, const TrackingConfig& right_config,
       const StereoCalibration& stereo, const StereoOptions& options)
      : left(left_config),
        right(right_config),
        triangulator(stereo, options.triangulation),
        options(options),
        pairing(left_config.markers.size()) {
    for (const MarkerSpec& spec : left_config.markers) {
      bool in_right = false;
      for (const MarkerSpec& other : right_config.markers)
        in_right = in_right || other.name == spec.name;
      if (!in_right) {
        throw InputError("marker '" + spec.name +
                         "' is in the left view's config but not in the right view's: the "
                         "views' markers are matched by name");
      }
      names.push_back(spec.name);
    }
    for (const std::string& name : ChainOf(left_config.measure)) {
      for (size_t i = 0; i < names.size(); ++i) {
        if (names[i] == name) chain_index.push_back(i);
      }
    }
    result.markers.resize(names.size());
    for (size_t i = 0; i < names.size(); ++i) result.markers[i].name = names[i];
    chain.resize(chain_index.size());
    if (chain_index.size() > 3) {
      for (size_t k = 1; k + 1 < chain_index.size(); ++k) segment_names.push_back(names[chain_index[k]]);
    }
  }

  TrackingSession left, right;
  Triangulator triangulator;
  StereoOptions options;
  StereoPairingCheck pairing;
  std::vector<std::optional<double>> recent_motion_px;  // Per marker, reused per frame.
  std::vector<std::string> names;
  std::vector<size_t> chain_index;  // The chain's markers' indices in `names`, base to tip.
  std::vector<std::string> segment_names;  // Inner markers, with more than 3 in the chain.
  std::vector<std::optional<cv::Point3d>> chain;  // Reused per frame.
  std::optional<cv::Vec3d> reference_normal;
  std::optional<cv::Point3d> tip_reference;
  StereoFrameResult result;
  FrameResult no_result;  // The views' results before the first pair.
  const FrameResult* left_result = &no_result;
  const FrameResult* right_result = &no_result;
};

StereoSession::StereoSession(const TrackingConfig& left, const TrackingConfig& right,
                             const StereoCalibration& stereo, const StereoOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw InputError("stereo: " + error);
  impl_ = std::make_unique<Impl>(left, right, stereo, options);
  if (options.reference_plane == StereoOptions::ReferencePlane::kImage) {
    impl_->reference_normal = cv::Vec3d(0, 0, 1);
  } else if (options.reference_plane == StereoOptions::ReferencePlane::kBoard) {
    impl_->reference_normal = cv::normalize(*options.board_normal);
  }
}

StereoSession::~StereoSession() = default;
StereoSession::StereoSession(StereoSession&&) noexcept = default;
StereoSession& StereoSession::operator=(StereoSession&&) noexcept = default;

std::vector<std::string> StereoSession::marker_names() const { return impl_->names; }
std::vector<std::string> StereoSession::segment_names() const { return impl_->segment_names; }

const StereoFrameResult& StereoSession::process(const FramePair& pair) {
  process(pair.left, pair.right);
  impl_->result.pair_dt_ms = pair.pair_dt_ms;
  return impl_->result;
}
const Triangulator& StereoSession::triangulator() const { return impl_->triangulator; }
const TrackingConfig& StereoSession::left_config() const { return impl_->left.config(); }
const TrackingConfig& StereoSession::right_config() const { return impl_->right.config(); }
const FrameResult& StereoSession::left_result() const { return *impl_->left_result; }
const FrameResult& StereoSession::right_result() const { return *impl_->right_result; }

const StereoFrameResult& StereoSession::process(const Frame& left_frame, const Frame& right_frame) {
  Impl& s = *impl_;
  const cv::Size calibrated = s.triangulator.stereo().left.image_size;
  if (left_frame.image.size() != calibrated || right_frame.image.size() != calibrated) {
    const bool left_bad = left_frame.image.size() != calibrated;
    throw InputError(std::string(left_bad ? "left" : "right") + " frame " +
                     std::to_string(left_bad ? left_frame.index : right_frame.index) + " is " +
                     SizeText(left_bad ? left_frame.image.size() : right_frame.image.size()) +
                     " but the stereo calibration is for " + SizeText(calibrated) + " images");
  }
  const auto start = std::chrono::steady_clock::now();
  const FrameResult& left = s.left.process(left_frame);
  const FrameResult& right = s.right.process(right_frame);
  s.left_result = &left;
  s.right_result = &right;
  StereoFrameResult& out = s.result;
  out.frame_index = left.frame_index;
  out.right_frame_index = right.frame_index;
  out.time_s = left.time_s;
  out.pair_dt_ms.reset();
  out.left_angle_deg = left.measurement.angle_deg;
  out.right_angle_deg = right.measurement.angle_deg;
  for (size_t i = 0; i < s.names.size(); ++i) {
    StereoMarkerResult& m = out.markers[i];
    const Observation* l = FindObservation(left, m.name);
    const Observation* r = FindObservation(right, m.name);
    m.left = l != nullptr ? *l : Observation::NotFound(MarkerStatus::kLost);
    m.right = r != nullptr ? *r : Observation::NotFound(MarkerStatus::kLost);
    m.point = s.triangulator.triangulate(m.left.position_px, m.right.position_px,
                                         m.left.sigma_px, m.right.sigma_px);
    s.recent_motion_px.resize(s.names.size());
    s.recent_motion_px[i].reset();
    if (m.point.epipolar_px) {
      s.recent_motion_px[i] = s.pairing.add(s.triangulator, i, *m.left.position_px,
                                             *m.right.position_px, right.frame_index);
    } else {
      s.pairing.lose(i);
    }
  }
  // Noise of a point's distance from its line: both views' centroids.
  const double sigma_px = std::sqrt(2.0) * s.triangulator.options().position_sigma_px;
  out.lag_frames = s.pairing.update(sigma_px);
  for (size_t i = 0; i < s.names.size(); ++i) {
    StereoMarkerResult& m = out.markers[i];
    if (out.lag_frames && m.point.found() && s.recent_motion_px[i] &&
        *s.recent_motion_px[i] > 0.25 * s.triangulator.options().max_epipolar_px) {
      m.point = StereoPoint{};
      m.point.status = StereoStatus::kTiming;
      m.point.epipolar_px = s.triangulator.epipolar_distance_px(*m.left.position_px,
                                                                *m.right.position_px);
    }
    if (m.point.status != StereoStatus::kMissing) {
      m.status = StereoStatusName(m.point.status);
    } else if (!m.left.found()) {
      m.status = std::string("left_") + MarkerStatusName(m.left.status());
    } else {
      m.status = std::string("right_") + MarkerStatusName(m.right.status());
    }
  }
  for (size_t k = 0; k < s.chain_index.size(); ++k) {
    s.chain[k] = out.markers[s.chain_index[k]].point.position_mm;
  }
  if (!s.tip_reference && !s.chain.empty() && s.chain.back()) s.tip_reference = s.chain.back();
  out.shape = MeasureShape3d(s.chain, s.reference_normal, s.tip_reference);
  if (!s.segment_names.empty()) MeasureSegments3d(s.chain, &out.segments);
  if (!s.reference_normal && out.shape.plane_normal) {
    // The first frame with a bending plane is the reference from now on (its own angle: 0).
    s.reference_normal = out.shape.plane_normal;
    out.shape.out_of_plane_deg = 0.0;
  }
  const auto now = std::chrono::steady_clock::now();
  out.proc_ms = std::chrono::duration<double, std::milli>(now - start).count();
  out.left_view = &left;
  out.right_view = &right;
  if (s.options.results_in_board) ExpressInBoardFrame(*s.options.results_in_board, out);
  out.captured = left_frame.captured;
  out.latency_result_ms =
      out.captured == std::chrono::steady_clock::time_point{}
          ? 0.0
          : std::chrono::duration<double, std::milli>(now - out.captured).count();
  return out;
}

std::vector<std::string> StereoMarkerSuffixes() {
  return {"_X", "_Y", "_Z", "_sigma_mm", "_epipolar_px", "_status"};
}

void StereoFiguresSink::begin(const RunInfo& info) {
  figures_ = StereoRunFigures{};
  figures_.epipolar.assign(info.marker_names.size(), 0);
  figures_.timing.assign(info.marker_names.size(), 0);
}

void StereoFiguresSink::consume(const FramePair& pair, const StereoFrameResult& result) {
  (void)pair;
  if (result.pair_dt_ms) {
    figures_.paired_by_time = true;
    figures_.max_abs_pair_dt_ms =
        std::max(figures_.max_abs_pair_dt_ms.value_or(0.0), std::abs(*result.pair_dt_ms));
  }
  if (result.lag_frames) figures_.lag_frames.push_back(*result.lag_frames);
  for (size_t i = 0; i < result.markers.size() && i < figures_.epipolar.size(); ++i) {
    const StereoPoint& p = result.markers[i].point;
    if (p.status == StereoStatus::kTiming) ++figures_.timing[i];
    if (p.status == StereoStatus::kEpipolar) ++figures_.epipolar[i];
    if (p.found()) figures_.sigma_mm.push_back(*p.sigma_mm);
    if (p.epipolar_px) figures_.epipolar_px.push_back(*p.epipolar_px);
  }
}

void ExpressInBoardFrame(const BoardFrame& frame, StereoFrameResult& result) {
  for (StereoMarkerResult& marker : result.markers) {
    StereoPoint& point = marker.point;
    if (point.position_mm) point.position_mm = frame.to_board(*point.position_mm);
    if (point.covariance_mm2) {
      point.covariance_mm2 = frame.covariance_to_board(*point.covariance_mm2);
    }
  }
  if (result.shape.plane_normal) {
    result.shape.plane_normal = frame.direction_to_board(*result.shape.plane_normal);
  }
}

BasicCsvColumnTable<StereoFrameResult> StereoColumns(const std::vector<std::string>& marker_names,
                                                     const std::vector<std::string>& segment_names) {
  using Row = StereoFrameResult;
  using Column = BasicCsvColumn<Row>;
  BasicCsvColumnTable<Row> table;
  table.add(Column{"frame",
                   [](const Row& r, std::string& row) { row += std::to_string(r.frame_index); }});
  table.add(Column{"right_frame", [](const Row& r, std::string& row) {
                     row += std::to_string(r.right_frame_index);
                   }});
  table.add(NumberColumn<Row>(
      "time_s", [](const Row& r) { return r.time_s; }, "%.6f"));
  table.add(NumberColumn<Row>(
      "pair_dt_ms", [](const Row& r) { return r.pair_dt_ms; }, "%.3f"));
  for (size_t i = 0; i < marker_names.size(); ++i) {
    const std::string& name = marker_names[i];
    const auto coordinate = [i](int axis) {
      return [i, axis](const Row& r) -> std::optional<double> {
        const std::optional<cv::Point3d>& p = r.markers[i].point.position_mm;
        if (!p) return std::nullopt;
        return axis == 0 ? p->x : axis == 1 ? p->y : p->z;
      };
    };
    table.add(NumberColumn<Row>(name + "_X", coordinate(0), "%.4f"));
    table.add(NumberColumn<Row>(name + "_Y", coordinate(1), "%.4f"));
    table.add(NumberColumn<Row>(name + "_Z", coordinate(2), "%.4f"));
    table.add(NumberColumn<Row>(
        name + "_sigma_mm", [i](const Row& r) { return r.markers[i].point.sigma_mm; }, "%.4f"));
    table.add(NumberColumn<Row>(
        name + "_epipolar_px", [i](const Row& r) { return r.markers[i].point.epipolar_px; },
        "%.3f"));
    table.add(Column{name + "_status",
                     [i](const Row& r, std::string& row) { row += r.markers[i].status; }});
  }
  table.add(NumberColumn<Row>(
      "angle_deg", [](const Row& r) { return r.shape.angle_deg; }, "%.4f"));
  table.add(NumberColumn<Row>(
      "out_of_plane_deg", [](const Row& r) { return r.shape.out_of_plane_deg; }, "%.4f"));
  for (int axis = 0; axis < 3; ++axis) {
    table.add(NumberColumn<Row>(
        std::string("plane_n") + "xyz"[axis],
        [axis](const Row& r) -> std::optional<double> {
          if (!r.shape.plane_normal) return std::nullopt;
          return (*r.shape.plane_normal)[axis];
        },
        "%.6f"));
  }
  table.add(NumberColumn<Row>(
      "radius_mm", [](const Row& r) { return r.shape.radius; }, "%.4f"));
  table.add(NumberColumn<Row>(
      "arc_length_mm", [](const Row& r) { return r.shape.arc_length; }, "%.4f"));
  table.add(NumberColumn<Row>(
      "tip_disp_mm", [](const Row& r) { return r.shape.tip_disp; }, "%.4f"));
  for (size_t k = 0; k < segment_names.size(); ++k) {
    const auto segment = [k](const Row& r) -> const Segment3d* {
      return k < r.segments.size() ? &r.segments[k] : nullptr;
    };
    table.add(NumberColumn<Row>(
        "angle_" + segment_names[k] + "_deg",
        [segment](const Row& r) -> std::optional<double> {
          const Segment3d* s = segment(r);
          return s != nullptr ? s->angle_deg : std::nullopt;
        },
        "%.4f"));
    table.add(NumberColumn<Row>(
        "radius_" + segment_names[k] + "_mm",
        [segment](const Row& r) -> std::optional<double> {
          const Segment3d* s = segment(r);
          return s != nullptr ? s->radius : std::nullopt;
        },
        "%.4f"));
    table.add(NumberColumn<Row>(
        "arc_length_" + segment_names[k] + "_mm",
        [segment](const Row& r) -> std::optional<double> {
          const Segment3d* s = segment(r);
          return s != nullptr ? s->arc_length : std::nullopt;
        },
        "%.4f"));
  }
  table.add(NumberColumn<Row>(
      "angle_left_deg", [](const Row& r) { return r.left_angle_deg; }, "%.4f"));
  table.add(NumberColumn<Row>(
      "angle_right_deg", [](const Row& r) { return r.right_angle_deg; }, "%.4f"));
  table.add(NumberColumn<Row>(
      "proc_ms", [](const Row& r) { return r.proc_ms; }, "%.3f"));
  return table;
}

}  // namespace softsight
