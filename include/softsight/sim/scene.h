// Synthetic scenes with exact ground truth: a planar soft actuator with coloured disc markers on
// a textured background, rendered anti-aliased (supersampled), with optional sensor noise, blur,
// illumination gain and occluders. Scene, noise and rendering options are kept apart.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/geometry/measurement.h"

namespace softsight {

enum class SceneKind {
  kBending,  // A silicone band whose centre line is a constant-curvature arc, fixed at its base.
  kWedge1,   // The paper's 1-segment triangle (wedge) actuator, opening to 20 degrees.
  kWedge4,   // The paper's 4-segment triangle actuator, opening to 80 degrees.
};

// The backdrop behind the actuator.
enum class BackgroundKind {
  kDefault,  // A grey lab bench: lighting gradient, soft blobs, grain, a cable, screws. Nothing
             // in it has a marker's saturation.
  kBench,    // A blotchy wood-like bench: grain, dark, reddish, greenish and bluish patches (some
             // as saturated as a marker), tape strips and a cable. Made to tempt colour trackers.
};

// A filled, anti-aliased ellipse of one colour drawn on the backdrop, behind the actuator: a
// blob a tracker must not take for a marker. Positions in output pixels (pixel-centre
// convention); `radii_px` are the semi-axes, the first along `angle_deg` (clockwise in the
// image, from the x axis).
struct Distractor {
  cv::Point2d centre_px{};
  cv::Size2d radii_px{};
  double angle_deg = 0.0;
  cv::Vec3b bgr{};
};

struct SceneMarker {
  std::string name{};
  cv::Vec3b bgr{};          // Marker colour (saturated, so HSV thresholds separate it).
  double body_fraction{};   // Position along the body, 0 = base, 1 = tip.
};

struct SceneOptions {
  SceneKind kind = SceneKind::kBending;
  cv::Size size{640, 480};
  int frame_count = 300;
  double fps = 30.0;
  // Bending over time, from straight (0) to `max_bend_deg` total turning of the centre line
  // (> 180: well past a half circle; at most 330, beyond that the band would touch itself).
  // The profile is smooth (a raised cosine) and monotonic unless `oscillate`.
  // The wedge scenes ignore it: they open to their design angle (20 / 80 degrees in total).
  double max_bend_deg = 240.0;
  bool oscillate = false;   // Bend and unbend (a sine) instead of one monotonic sweep.
  int oscillate_cycles = 1; // With `oscillate`: bend-unbend cycles over the whole sequence.
  double length_px = 300.0; // Centre-line length of the body.
  double width_px = 40.0;
  double marker_radius_px = 9.0;
  // Default markers: red at the base, blue in the middle, green at the tip (the paper's R, B, G),
  // placed symmetrically so the middle marker sits mid-arc between the end markers.
  std::vector<SceneMarker> markers = {{"red", {40, 40, 220}, 0.1},
                                      {"blue", {220, 90, 40}, 0.5},
                                      {"green", {60, 200, 60}, 0.9}};
  uint64_t seed = 1;        // Background texture.
  BackgroundKind background = BackgroundKind::kDefault;
  // Drawn on the backdrop in order (later ones over earlier ones); see MakeMarkerDistractors.
  std::vector<Distractor> distractors{};

  // False with a one-line message naming the bad field.
  bool Check(std::string* error) const;
};

struct NoiseOptions {
  double sigma = 0.0;         // Gaussian sensor noise, in 8-bit grey levels.
  double blur_sigma_px = 0.0; // Optical blur (Gaussian), applied before noise.
  double gain_start = 1.0;    // Illumination gain at the first frame ...
  double gain_end = 1.0;      // ... ramping linearly to this at the last frame.
  uint64_t seed = 7;         // Noise is a function of (seed, frame index): any order, same frames.

  bool Check(std::string* error) const;
};

struct RenderOptions {
  int supersample = 4;        // Sub-samples per pixel side; the truth is exact at this resolution.
                              // 1..16; cost grows with its square (4 keeps 640x480 near 5 ms).

  bool Check(std::string* error) const;
};

// A rectangle drawn over everything else during frames [first_frame, last_frame] (inclusive).
// It covers the area [x - 0.5, x + width - 0.5) x [y - 0.5, y + height - 0.5) in the pixel-centre
// convention: integer values cover exactly the pixels of the cv::Rect (x, y, width, height),
// fractional ones give anti-aliased edges.
struct Occluder {
  cv::Rect2d rect_px{};
  int first_frame = 0;
  int last_frame = 0;
  cv::Vec3b bgr{128, 128, 128};
};

struct MarkerTruth {
  std::string name{};
  // Centroid of the marker's rendered visible area (pixel-centre convention); absent when the
  // marker is fully hidden.
  std::optional<cv::Point2d> centroid_px{};
  double visible_fraction = 1.0;  // Visible area / unoccluded area.
};

struct SceneTruth {
  int64_t frame_index = 0;
  double time_s = 0.0;
  double bend_deg = 0.0;                 // Total turning of the centre line (the actuator state).
  // Radius of the centre-line arc; absent when straight and for the wedge scenes (no arc).
  std::optional<double> centreline_radius_px{};
  std::vector<MarkerTruth> markers{};
  // The paper's measurements from the true centroids: base, middle and tip are the markers with
  // the smallest, median and largest body_fraction (all of them as a chain when more than 3);
  // the tip reference is the tip marker's centre when the actuator is straight. Default (empty)
  // with fewer than three markers and for the plate scene.
  Measurement measurement{};
};

class SyntheticScene {
 public:
  // Throws InputError naming the option when options are unusable.
  SyntheticScene(SceneOptions scene, NoiseOptions noise = {}, RenderOptions render = {},
                 std::vector<Occluder> occluders = {});
  ~SyntheticScene();
  SyntheticScene(SyntheticScene&&) noexcept;
  SyntheticScene& operator=(SyntheticScene&&) noexcept;

  const SceneOptions& options() const;
  int frame_count() const;
  // The largest bend this scene renders: max_bend_deg, or the wedge's design opening.
  double max_bend_deg() const;
  // The actuator state of frame `index` (the time profile).
  double bend_at(int index) const;

  // Renders frame `index` of the time profile into `image` (CV_8UC3, buffer reused).
  SceneTruth render(int index, cv::Mat& image);
  // Renders the actuator at an explicit bend (used by the simulated control rig). The bend is
  // clamped to the physical range [0, max_bend_deg()], and the truth reports the rendered bend.
  // `index` selects the occluders, the gain and the noise, as for frame `index`.
  SceneTruth render_at_bend(double bend_deg, double time_s, int index, cv::Mat& image);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The markers a scene's truth measures: base, middle and tip are those with the smallest, median
// and largest body_fraction, and the whole chain when there are more than three. Tools that track
// a rendered scene use it so they measure exactly what the truth does. Empty (no triple, no
// chain) with fewer than three markers: one or two markers give positions only.
MeasureOptions SceneMeasureOptions(const SceneOptions& scene);

// Distractors for every marker colour of `scene`, the look-alikes a colour tracker meets on a
// real bench: a larger blob (about 3 x 2.3 marker radii), an elongated one (2 x 0.75), a darker
// one of the same hue and size (half the brightness), and circles of the wrong size (0.5 and 2
// marker radii). Each lies inside the frame and at least a marker radius (and 6 px) away from
// everything the actuator covers over its whole motion, and from the other distractors, so the
// markers stay the only right answer. Deterministic in (scene, seed). Where the frame has no
// room left, the remaining ones are left out (the result may be shorter, never overlapping).
// Throws InputError when the actuator does not fit the image (as SyntheticScene does).
std::vector<Distractor> MakeMarkerDistractors(const SceneOptions& scene, uint64_t seed);

// Parses "bending", "wedge1", "wedge4"; throws InputError listing the choices.
SceneKind ParseSceneKind(const std::string& name);
const char* SceneKindName(SceneKind kind);

}  // namespace softsight
