#include "softsight/sim/stereo_scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/camera.h"
#include "softsight/core/error.h"
#include "softsight/geometry/shape3d.h"

namespace softsight {
namespace {

constexpr double kStereoDegToRad = std::numbers::pi / 180.0;

cv::Mat DistortionOf(const CameraModel& camera) {
  if (camera.distortion.empty()) return cv::Mat();
  return cv::Mat(camera.distortion, /*copyData=*/true).reshape(1, 1);
}

cv::Point2d Project(const CameraModel& camera, const cv::Matx33d& rotation,
                    const cv::Vec3d& translation, const cv::Point3d& point_mm) {
  cv::Vec3d rvec;
  cv::Rodrigues(rotation, rvec);
  std::vector<cv::Point2d> out;
  cv::projectPoints(std::vector<cv::Point3d>{point_mm}, rvec, translation, camera.camera_matrix,
                    DistortionOf(camera), out);
  return out.front();
}

cv::Point3d ToPoint(const cv::Vec3d& v) { return cv::Point3d(v[0], v[1], v[2]); }
cv::Vec3d ToVec(const cv::Point3d& p) { return cv::Vec3d(p.x, p.y, p.z); }

// The body: its centre line as a thick anti-aliased polyline (not part of the truth).
void DrawBody(const StereoSceneOptions& o, const CameraModel& camera, const cv::Mat& distortion,
              const cv::Matx33d& rotation, const cv::Vec3d& rvec, const cv::Vec3d& translation,
              const StereoSceneTruth& truth, cv::Mat& image) {
  const double curvature = truth.bend_deg * kStereoDegToRad / o.length_mm;
  const cv::Vec3d d0 = cv::normalize(o.straight_direction);
  const cv::Vec3d bend_direction = truth.plane_normal.cross(d0);
  std::vector<cv::Point3d> line;
  for (int i = 0; i <= 48; ++i) {
    const double s = o.length_mm * i / 48.0;
    const cv::Vec3d p = curvature > 0
                            ? ToVec(o.base_mm) + (std::sin(curvature * s) / curvature) * d0 +
                                  ((1.0 - std::cos(curvature * s)) / curvature) * bend_direction
                            : ToVec(o.base_mm) + s * d0;
    line.push_back(ToPoint(p));
  }
  std::vector<cv::Point2d> projected;
  cv::projectPoints(line, rvec, translation, camera.camera_matrix, distortion, projected);
  std::vector<cv::Point> polyline;
  constexpr int kShift = 4;  // Sub-pixel vertices for the anti-aliased line.
  for (const cv::Point2d& p : projected) {
    polyline.emplace_back(cv::saturate_cast<int>(p.x * (1 << kShift)),
                          cv::saturate_cast<int>(p.y * (1 << kShift)));
  }
  const double depth = (rotation * ToVec(o.base_mm) + translation)[2];
  const int thickness = std::max(
      1, static_cast<int>(std::lround(o.body_width_mm * camera.camera_matrix(0, 0) / depth)));
  cv::polylines(image, polyline, false, cv::Scalar(o.body_bgr[0], o.body_bgr[1], o.body_bgr[2]),
                thickness, cv::LINE_AA, kShift);
}

// The pixels a marker's disc (centre and normal in the camera's frame) may cover: its projected
// rim's bounds, with a margin, within the image.
cv::Rect DiscBox(const CameraModel& camera, const cv::Mat& distortion, const cv::Vec3d& centre,
                 const cv::Vec3d& normal, double radius_mm, const cv::Size& image_size) {
  cv::Vec3d u = normal.cross(cv::Vec3d(0, 0, 1));
  if (cv::norm(u) < 1e-9) u = cv::Vec3d(1, 0, 0);
  u = cv::normalize(u);
  const cv::Vec3d v = normal.cross(u);
  std::vector<cv::Point3d> rim;
  for (int k = 0; k < 32; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 32.0;
    rim.push_back(ToPoint(centre + radius_mm * (std::cos(a) * u + std::sin(a) * v)));
  }
  std::vector<cv::Point2d> rim_px;
  cv::projectPoints(rim, cv::Vec3d(), cv::Vec3d(), camera.camera_matrix, distortion, rim_px);
  const cv::Rect2d bounds =
      cv::boundingRect(std::vector<cv::Point2f>(rim_px.begin(), rim_px.end()));
  return cv::Rect(static_cast<int>(std::floor(bounds.x)) - 2,
                  static_cast<int>(std::floor(bounds.y)) - 2,
                  static_cast<int>(std::ceil(bounds.width)) + 5,
                  static_cast<int>(std::ceil(bounds.height)) + 5) &
         cv::Rect(0, 0, image_size.width, image_size.height);
}

// A pixel takes the marker's colour in proportion to its s x s sub-samples whose rays (through
// the lens model, undistorted) meet the disc's plane inside the disc.
void FillMarkerDisc(const CameraModel& camera, const cv::Mat& distortion, const cv::Vec3d& centre,
                    const cv::Vec3d& normal, double radius_mm, const cv::Vec3b& colour, int s,
                    const cv::Rect& box, cv::Mat& image) {
  std::vector<cv::Point2d> samples;
  samples.reserve(static_cast<size_t>(box.area() * s * s));
  for (int y = box.y; y < box.y + box.height; ++y) {
    for (int x = box.x; x < box.x + box.width; ++x) {
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) {
          samples.emplace_back(x - 0.5 + (j + 0.5) / s, y - 0.5 + (i + 0.5) / s);
        }
      }
    }
  }
  std::vector<cv::Point2d> rays;
  cv::undistortPoints(
      samples, rays, camera.camera_matrix, distortion, cv::noArray(), cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
  const double plane_offset = normal.dot(centre);
  const double r2 = radius_mm * radius_mm;
  size_t k = 0;
  for (int y = box.y; y < box.y + box.height; ++y) {
    cv::Vec3b* row = image.ptr<cv::Vec3b>(y);
    for (int x = box.x; x < box.x + box.width; ++x) {
      int inside = 0;
      for (int q = 0; q < s * s; ++q, ++k) {
        const cv::Vec3d ray(rays[k].x, rays[k].y, 1.0);
        const double along = normal.dot(ray);
        if (std::abs(along) < 1e-12) continue;
        const cv::Vec3d hit = (plane_offset / along) * ray - centre;
        if (hit.dot(hit) <= r2) ++inside;
      }
      if (inside == 0) continue;
      const double a = static_cast<double>(inside) / (s * s);
      for (int c = 0; c < 3; ++c) {
        row[x][c] = cv::saturate_cast<uint8_t>((1.0 - a) * row[x][c] + a * colour[c]);
      }
    }
  }
}

// The flash (a frame range brightened) and the sensor's noise, seeded per frame and view.
void AddFlashAndNoise(const StereoSceneOptions& o, int index, int view, cv::Mat& image) {
  if (o.flash_frame && index >= *o.flash_frame &&
      (o.flash_length_frames == 0 || index < *o.flash_frame + o.flash_length_frames)) {
    image += cv::Scalar::all(o.flash_gray);  // Saturating.
  }

  if (o.noise_sigma > 0) {
    cv::Mat noise(image.size(), CV_32FC3);
    cv::RNG rng(sim::Mix(o.seed, static_cast<uint64_t>(index) * 2 + static_cast<uint64_t>(view)));
    rng.fill(noise, cv::RNG::NORMAL, 0.0, o.noise_sigma);
    cv::Mat as_float;
    image.convertTo(as_float, CV_32FC3);
    as_float += noise;
    as_float.convertTo(image, CV_8UC3);
  }
}

}  // namespace

StereoRig MakeStereoRig(double baseline_mm, double convergence_mm) {
  StereoRig rig;
  rig.left.image_size = rig.right.image_size = cv::Size(640, 480);
  rig.left.camera_matrix = cv::Matx33d(600, 0, 320, 0, 600, 240, 0, 0, 1);
  rig.left.distortion = {-0.08, 0.02, 0.0, 0.0, 0.0};
  rig.right.camera_matrix = cv::Matx33d(610, 0, 316, 0, 608, 244, 0, 0, 1);
  rig.right.distortion = {-0.1, 0.03, 0.0005, -0.0003, 0.0};
  // The right camera's centre is at (baseline, 0, 0); it turns about y so its axis passes
  // through (0, 0, convergence): X_right = R (X_left - centre), so T = -R centre.
  const double toe_in = std::atan2(baseline_mm, convergence_mm);
  const double c = std::cos(toe_in), s = std::sin(toe_in);
  rig.R = cv::Matx33d(c, 0, s, 0, 1, 0, -s, 0, c);
  rig.T = -(rig.R * cv::Vec3d(baseline_mm, 0, 0));
  return rig;
}

BoardPose RightBoardPose(const StereoRig& rig, const BoardPose& left_pose) {
  cv::Matx33d left_from_board;
  cv::Rodrigues(left_pose.rvec, left_from_board);
  BoardPose right;
  cv::Rodrigues(rig.R * left_from_board, right.rvec);
  right.tvec = rig.R * left_pose.tvec + rig.T;
  return right;
}

cv::Point2d ProjectLeft(const StereoRig& rig, const cv::Point3d& point_mm) {
  return Project(rig.left, cv::Matx33d::eye(), cv::Vec3d(0, 0, 0), point_mm);
}

cv::Point2d ProjectRight(const StereoRig& rig, const cv::Point3d& point_mm) {
  return Project(rig.right, rig.R, rig.T, point_mm);
}

bool StereoSceneOptions::Check(std::string* error) const {
  if (frame_count < 1) {
    *error = "frame_count: must be >= 1, got " + std::to_string(frame_count);
    return false;
  }
  if (!(cv::norm(straight_direction) > 0)) {
    *error = "straight_direction: must not be zero";
    return false;
  }
  if (!(length_mm > 0) || !(marker_radius_mm > 0) || !(body_width_mm >= 0)) {
    *error = "length_mm, marker_radius_mm: must be > 0 (body_width_mm >= 0)";
    return false;
  }
  if (!(max_bend_deg >= 0 && max_bend_deg <= 300)) {
    *error = "max_bend_deg: must be in [0, 300], got " + std::to_string(max_bend_deg);
    return false;
  }
  if (markers.empty()) {
    *error = "markers: at least one";
    return false;
  }
  for (const StereoMarker& m : markers) {
    if (!(m.body_fraction >= 0 && m.body_fraction <= 1)) {
      *error = "markers: " + m.name + ": body_fraction must be in [0, 1]";
      return false;
    }
  }
  if (!bend_deg_per_frame.empty()) {
    if (bend_deg_per_frame.size() != static_cast<size_t>(frame_count)) {
      *error = "bend_deg_per_frame: " + std::to_string(bend_deg_per_frame.size()) +
               " values for " + std::to_string(frame_count) + " frames";
      return false;
    }
    for (double bend : bend_deg_per_frame) {
      if (!(bend >= 0 && bend <= 300)) {
        *error = "bend_deg_per_frame: each must be in [0, 300], got " + std::to_string(bend);
        return false;
      }
    }
  }
  for (const StereoHiddenMarker& h : hidden) {
    const bool known = std::any_of(markers.begin(), markers.end(),
                                   [&](const StereoMarker& m) { return m.name == h.name; });
    if (!known || (h.view != 0 && h.view != 1) || h.frames < 1) {
      *error = "hidden: " + h.name + ": must name a marker, view 0 or 1, frames >= 1";
      return false;
    }
  }
  if (flash_length_frames < 0 || !(flash_gray >= 0 && flash_gray <= 255)) {
    *error = "flash_length_frames: must be >= 0, flash_gray in [0, 255]";
    return false;
  }
  if (supersample < 1 || supersample > 16) {
    *error = "supersample: must be 1..16, got " + std::to_string(supersample);
    return false;
  }
  if (!(noise_sigma >= 0)) {
    *error = "noise_sigma: must be >= 0";
    return false;
  }
  return true;
}

StereoScene::StereoScene(StereoRig rig, StereoSceneOptions options)
    : rig_(std::move(rig)), options_(std::move(options)) {
  std::string error;
  if (!options_.Check(&error)) throw InputError("stereo scene: " + error);
}

StereoSceneTruth StereoScene::truth(int index) const {
  const StereoSceneOptions& o = options_;
  const double t = o.frame_count > 1 ? static_cast<double>(index) / (o.frame_count - 1) : 0.0;
  return truth_at_bend(o.bend_deg_per_frame.empty()
                           ? o.max_bend_deg * t
                           : o.bend_deg_per_frame[static_cast<size_t>(std::clamp(
                                 index, 0, static_cast<int>(o.bend_deg_per_frame.size()) - 1))],
                       index);
}

StereoSceneTruth StereoScene::truth_at_bend(double bend_deg, int index) const {
  const StereoSceneOptions& o = options_;
  const double t =
      o.frame_count > 1 ? std::clamp(static_cast<double>(index) / (o.frame_count - 1), 0.0, 1.0)
                        : 0.0;
  StereoSceneTruth truth;
  truth.index = index;
  truth.bend_deg = std::clamp(bend_deg, 0.0, 300.0);
  const double tilt_deg =
      o.plane_tilt_start_deg + (o.plane_tilt_end_deg - o.plane_tilt_start_deg) * t;

  // The bending direction: perpendicular to the straight direction, turned `tilt` from the
  // image-parallel direction towards the camera's axis.
  const cv::Vec3d d0 = cv::normalize(o.straight_direction);
  cv::Vec3d across = cv::Vec3d(1, 0, 0) - d0[0] * d0;
  if (cv::norm(across) < 1e-9) across = cv::Vec3d(0, 1, 0) - d0[1] * d0;
  across = cv::normalize(across);
  cv::Vec3d depth = across.cross(d0);
  if (depth[2] < 0) depth = -depth;
  const double tilt = tilt_deg * kStereoDegToRad;
  const cv::Vec3d bend_direction = std::cos(tilt) * across + std::sin(tilt) * depth;
  truth.plane_normal = cv::normalize(d0.cross(bend_direction));
  truth.plane_tilt_deg = *AngleBetweenPlanesDeg(truth.plane_normal, cv::Vec3d(0, 0, 1));

  const double curvature = truth.bend_deg * kStereoDegToRad / o.length_mm;
  if (curvature > 0) truth.radius_mm = 1.0 / curvature;
  const cv::Vec3d base = ToVec(o.base_mm);
  for (const StereoMarker& marker : o.markers) {
    const double s = marker.body_fraction * o.length_mm;
    const cv::Vec3d p = curvature > 0
                            ? base + (std::sin(curvature * s) / curvature) * d0 +
                                  ((1.0 - std::cos(curvature * s)) / curvature) * bend_direction
                            : base + s * d0;
    StereoMarkerTruth m;
    m.name = marker.name;
    m.position_mm = ToPoint(p);
    m.left_px = ProjectLeft(rig_, m.position_mm);
    m.right_px = ProjectRight(rig_, m.position_mm);
    truth.markers.push_back(std::move(m));
  }
  if (truth.markers.size() >= 3) {
    truth.angle_deg = AngleAtMiddle3dDeg(truth.markers.front().position_mm,
                                         truth.markers[truth.markers.size() / 2].position_mm,
                                         truth.markers.back().position_mm)
                          .value_or(0.0);
  }
  return truth;
}

StereoSceneTruth StereoScene::render(int index, cv::Mat& left, cv::Mat& right) const {
  return render_at_bend(truth(index).bend_deg, index, left, right);
}

StereoSceneTruth StereoScene::render_at_bend(double bend_deg, int index, cv::Mat& left,
                                             cv::Mat& right) const {
  const StereoSceneTruth t = truth_at_bend(bend_deg, index);
  draw(rig_.left, cv::Matx33d::eye(), cv::Vec3d(0, 0, 0), t, index, 0, left);
  draw(rig_.right, rig_.R, rig_.T, t, index, 1, right);
  return t;
}

void StereoScene::draw(const CameraModel& camera, const cv::Matx33d& rotation,
                       const cv::Vec3d& translation, const StereoSceneTruth& truth, int index,
                       int view, cv::Mat& image) const {
  const StereoSceneOptions& o = options_;
  image.create(camera.image_size, CV_8UC3);
  image.setTo(cv::Scalar(o.background_bgr[0], o.background_bgr[1], o.background_bgr[2]));
  const cv::Mat distortion = DistortionOf(camera);
  cv::Vec3d rvec;
  cv::Rodrigues(rotation, rvec);

  if (o.body_width_mm > 0) {
    DrawBody(o, camera, distortion, rotation, rvec, translation, truth, image);
  }

  // The markers: flat discs in the bending plane's orientation. Each sub-sample's ray (through
  // the lens model, undistorted) is intersected with the disc's plane; a pixel takes the
  // marker's colour in proportion to its sub-samples inside the disc.
  const int s = o.supersample;
  const cv::Vec3d normal = rotation * truth.plane_normal;
  for (size_t m = 0; m < truth.markers.size(); ++m) {
    const auto covers = [&](const StereoHiddenMarker& h) {
      return h.name == truth.markers[m].name && h.view == view && index >= h.first_frame &&
             index < h.first_frame + h.frames;
    };
    const bool hidden = std::any_of(o.hidden.begin(), o.hidden.end(), covers);
    if (hidden) continue;
    const cv::Vec3d centre = rotation * ToVec(truth.markers[m].position_mm) + translation;
    const cv::Rect box =
        DiscBox(camera, distortion, centre, normal, o.marker_radius_mm, image.size());
    if (box.empty()) continue;
    FillMarkerDisc(camera, distortion, centre, normal, o.marker_radius_mm, o.markers[m].bgr, s,
                   box, image);
  }

  AddFlashAndNoise(o, index, view, image);
}

}  // namespace softsight
