// Drawing tracking results on a frame: each marker's centroid and name, the base-middle-tip
// triangle, the fitted arc, the measurements (mm when calibrated), frame rate, processing time
// and latency, lost markers flagged in red. Used by the live window and by annotated video
// output (`track --annotated`, live recording). Drawing only: no state, no windows, no I/O.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "softsight/geometry/measurement.h"
#include "softsight/pipeline/tracking_session.h"

namespace softsight {

// Colours of the overlay (BGR), fixed so that tests and people can find them.
namespace overlay_colour {
inline const cv::Scalar kMarker(0, 255, 255);      // Found marker: ring and cross (yellow).
inline const cv::Scalar kTriangle(255, 255, 255);  // Base-middle-tip triangle (white).
inline const cv::Scalar kArc(255, 0, 255);         // Fitted arc (magenta).
inline const cv::Scalar kLost(0, 0, 255);          // Lost-marker flags (red).
inline const cv::Scalar kText(255, 255, 255);
inline const cv::Scalar kTemplate(255, 200, 0);    // A template marker's box and score (sky blue).
}  // namespace overlay_colour

// How the gui draws: one font for every text, and sub-pixel coordinates in 1/16 px
// (cv::circle / cv::polylines `shift`), so a marker's ring sits where its centroid is.
inline constexpr int kGuiFont = 0;  // cv::FONT_HERSHEY_SIMPLEX (imgproc.hpp is not needed here).
inline constexpr int kSubPixelShift = 4;

struct OverlayOptions {
  // The triple (and optional chain) by marker name, as in MeasureOptions: which markers the
  // triangle and the arc join.
  std::string base, middle, tip;
  // Radius of the ring drawn around each found centroid, px. Default 12: visible around a
  // typical 10-20 px marker without hiding it.
  int marker_ring_px = 12;
  // Text size multiplier; 1 suits 640x480 frames. Default 0 picks it from the frame width.
  double text_scale = 0.0;
  bool show_measurements = true;  // The text block in the top-left corner.

  // Returns true when every field is usable; otherwise false with `error` naming the field.
  bool Check(std::string* error) const;
};

// The triangle's markers from a measurement configuration.
OverlayOptions OverlayOptionsFor(const MeasureOptions& measure);

// Figures only a live run knows; absent ones are not shown.
struct OverlayStatus {
  std::optional<double> fps;         // Processed frames per second.
  std::optional<double> latency_ms;  // Capture to the result on screen.
  std::optional<double> speed;       // Source seconds per second (below 0.9: said).
  std::vector<std::string> notes;    // Extra lines (e.g. "REC live-001", "PAUSED").
  // Template markers (by index in result.markers; empty entries for colour markers): the
  // template's box is drawn around each one found, with its method and match score.
  struct TemplateBox {
    cv::Size size_px;
    std::string method;  // "sad", "ssd", "zncc".
  };
  std::vector<std::optional<TemplateBox>> template_boxes;
  // Markers this view found but that are not believed (by index in result.markers; empty
  // entries and missing ones: believed), with why: the stereo window's markers not found in 3D
  // ("epipolar", "right_lost", ...). Each is drawn in the lost colour with a slanted cross and
  // its reason instead of the found marker's ring, and listed as not believed in the text block.
  std::vector<std::string> refused;
};

// True when the radius is too large against the arc length to be told from a straight
// actuator's (radius >= 25 arc lengths: see overlay.cc); the overlay then reads "straight".
bool ReadsStraight(const Measurement& m);

// Draws the overlay for `result` onto `frame_bgr` (CV_8UC3) in place.
void DrawOverlay(cv::Mat& frame_bgr, const FrameResult& result, const OverlayOptions& options,
                 const OverlayStatus& status = {});

// Points along the arc from base to tip through the middle marker's side, `radius_px` being the
// measured radius (eq. 8 or the circle fit). Empty when the arc cannot be drawn (a marker lost,
// the radius absent or shorter than half the chord). The major arc when the middle marker is
// farther from the chord than the radius.
std::vector<cv::Point2d> ArcPoints(const cv::Point2d& base, const cv::Point2d& middle,
                                   const cv::Point2d& tip, double radius_px, int count = 64);

}  // namespace softsight
