// Colour-tracking kernels: the per-pixel marker test of the colour tracker (is this BGR pixel in
// the marker's HSV box?) and 3x3 binary morphology, each with a vector implementation (OpenCV
// universal intrinsics, 128-bit: SSE2 on any x86-64, NEON on ARM) and a scalar reference beside
// it that is obviously what OpenCV computes (cv::cvtColor + cv::inRange, cv::morphologyEx); tests
// check that they agree bit for bit (the HSV test over all 2^24 colours).
//
// Why: on the tracker's small windows OpenCV's 8-bit BGR->HSV conversion runs scalar (~36
// instructions a pixel), a wrapping hue needs a 3-channel LUT and inRange another pass, and each
// morphologyEx call builds a filter engine: together 5-10x the work of the whole rest of a frame.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/track/colour_tracker.h"

namespace softsight {

// A box in OpenCV's 8-bit HSV (H 0..179, S and V 0..255): every range inclusive; a hue range with
// lo > hi wraps around 0 ({170, 10}: 170..179 and 0..10).
struct HsvBox {
  HsvRange h{0, 179}, s{0, 255}, v{0, 255};

  static HsvBox Make(HsvRange h, HsvRange s, HsvRange v) { return HsvBox{h, s, v}; }
  bool ContainsHue(int hue) const;
  bool Contains(int hue, int sat, int val) const {
    return ContainsHue(hue) && sat >= s.lo && sat <= s.hi && val >= v.lo && val <= v.hi;
  }
};

// OpenCV's 8-bit BGR->HSV of one pixel, bit-exact with cv::cvtColor(COLOR_BGR2HSV) (its integer
// formula with the same division tables).
cv::Vec3b BgrToHsvExact(uchar b, uchar g, uchar r);

// The box prepared for the vector kernel: its hue ranges as intervals of the unrounded hue.
class HsvClassifier {
 public:
  HsvClassifier() : HsvClassifier(HsvBox{}) {}
  explicit HsvClassifier(const HsvBox& box);
  const HsvBox& box() const { return box_; }

  // mask = 255 where the BGR pixel of `bgr` (CV_8UC3) is in the box, else 0; `mask` is CV_8UC1 of
  // the same size (allocated by the caller: no allocation here). Any strides (ROI views).
  void Classify(const cv::Mat& bgr, cv::Mat& mask) const;
  // The scalar reference: BgrToHsvExact and Contains, pixel by pixel.
  void ClassifyScalar(const cv::Mat& bgr, cv::Mat& mask) const;
  // The same of a gray image (CV_8UC1) whose every pixel stands for the BGR pixel (v, v, v): a
  // flat pixel's hue and saturation are 0, so it is in when the box holds them and v is in the
  // box's value range. A gray recording handed over as BGR is classified from one of its planes
  // (ExtractFlatPlane), not from three interleaved ones (issue 45).
  void ClassifyFlat(const cv::Mat& gray, cv::Mat& mask) const;
  // The scalar reference: BgrToHsvExact(v, v, v) and Contains, pixel by pixel.
  void ClassifyFlatScalar(const cv::Mat& gray, cv::Mat& mask) const;

 private:
  void ClassifyRows(const cv::Mat& bgr, cv::Mat& mask) const;

  HsvBox box_;
  bool full_hue_ = false;
  // Hue intervals [lo, hi] of the unrounded hue t = 30 N / diff in [-30, 150) (OpenCV rounds t,
  // and adds 180 when negative), merged; at most three.
  int intervals_ = 0;
  std::array<int, 3> t_lo_{}, t_hi_{};
  bool gray_in_ = false;  // Whether a pixel with max == min (hue 0, saturation 0) is in (given V).
  // Bit k set: hues of pixels whose largest channel is red (k = 0), green (1) or blue (2) can be
  // in the box or within a unit of it; 16 pixels of none of those sectors are out at once.
  int hue_sectors_ = 7;
};

// Whether every pixel of `bgr` (CV_8UC3, any strides) has b == g == r (a gray recording handed
// over as BGR); if so, its one plane into `plane` (CV_8UC1 of its size, allocated by the caller).
// Stops at the first chunk of 16 that is not flat (a colour frame costs a few loads); `plane` is
// then left partly written. 16 pixels at a time; ExtractFlatPlaneReference is the obvious loop.
bool ExtractFlatPlane(const cv::Mat& bgr, cv::Mat& plane);
bool ExtractFlatPlaneReference(const cv::Mat& bgr, cv::Mat& plane);

// The OpenCV route the classifier replaces, for tests and benchmarks: cvtColor to HSV, a hue LUT
// for a wrapping range, inRange. `mask` is allocated when needed.
void ClassifyHsvOpenCv(const cv::Mat& bgr, const HsvBox& box, cv::Mat& mask);

// Opening then closing of a binary mask (0 / 255) by a 3x3 element, `cross` (MORPH_CROSS, which is
// also what getStructuringElement gives for a 3x3 MORPH_ELLIPSE) or a full 3x3 square, with
// cv::morphologyEx's default border (beyond the image: 255 for erosion, 0 for dilation). In place
// on `mask` (CV_8UC1, any strides); `scratch` is reused storage. Equals two cv::morphologyEx calls.
void OpenClose3x3(cv::Mat& mask, bool cross, cv::Mat& scratch);
void OpenClose3x3Reference(cv::Mat& mask, bool cross);

// The bounding box of the nonzero pixels of `mask` (CV_8UC1, any strides), empty when there are
// none, reading 16 pixels at a time (the tracker's replacement for cv::boundingRect(mask)).
cv::Rect NonZeroBounds(const cv::Mat& mask);

// The nonzero pixels of `mask` (CV_8UC1, any strides) in raster order into `points` (reused
// storage), reading 16 pixels at a time: cv::findNonZero, which counts them first and then
// visits every pixel again.
void NonZeroPoints(const cv::Mat& mask, std::vector<cv::Point>& points);

// Sets to `outside` (nonzero) every 0 pixel of `mask` (CV_8UC1, any strides) that a 4-connected
// path of 0 pixels joins to the mask's border, and leaves every other pixel: a 0 left afterwards
// is a hole. `stack` is reused storage: no allocation once warm. cv::floodFill from a border
// seed does this too, but allocates a mask of the image's size + 2 and clears it byte by byte on
// every call (issue 45: that clearing alone was 5 % of a session's frame with three colour
// markers, one call per marker and frame).
void MarkOutside(cv::Mat& mask, uchar outside, std::vector<cv::Point>& stack);
// The reference: cv::floodFill, from a corner of the mask padded by a ring of 0.
void MarkOutsideReference(cv::Mat& mask, uchar outside);

// Where each pixel of a blob's own mask lies against the blob's edge, as the colour tracker's
// measurement reads the chamfer (3-4) distance of ChamferToEdge (track/colour_tracker_parts.h):
// only whether it is more than 6 (two pixels, kSoftBand) and, for a pixel outside the blob, at most
// 12 (four pixels, kRingOuter). `own` (CV_8UC1) holds 255 for the blob and anything else (0, a
// filled hole's 128) for the rest; `zones` (CV_8UC1, its size) gets a stand-in for the distance
// that answers those questions as the chamfer distance d does: kZoneNear when d <= 6, kZoneReach
// when 6 < d <= 12, kZoneFar when d > 12 (a blob pixel: kZoneNear or kZoneFar, as d > 6 or not).
// The chamfer distance of a pixel is 3 max(|dx|, |dy|) + min(|dx|, |dy|) to the nearest pixel of
// the other kind in the mask, so d <= 6 is a pixel of the other kind in the 3x3 square or two
// pixels away along a row or column, and d <= 12 one in the 7x7 square or four away along a row
// or column: dilations, 16 pixels at a time, where the chamfer map is a serial recurrence of ~40
// instructions a pixel (issue 45). `scratch` is reused storage: no allocation once warm.
constexpr uchar kZoneNear = 6, kZoneReach = 12, kZoneFar = 13;
void EdgeZones(const cv::Mat& own, cv::Mat& zones, cv::Mat& scratch);
// The reference: the definition above, pixel by pixel over the neighbourhoods.
void EdgeZonesReference(const cv::Mat& own, cv::Mat& zones);

// 8-connected components of a binary mask (nonzero = in) from its runs: rows are scanned 16
// bytes at a time, so the cost is the mask's area / 16 plus its runs, where
// cv::connectedComponentsWithStats visits every pixel (which dominated whole-frame searches of
// textured scenes). Exact integer area, bounding box and moments per component; reused storage,
// no allocation once warm.
class RunLabeller {
 public:
  struct Run {
    int y, x0, x1;  // Row and columns [x0, x1) in the mask.
  };
  struct Component {
    int area = 0;
    cv::Rect box;                      // In the mask.
    int64_t m10 = 0, m01 = 0;          // Sums of x and y, relative to box.tl().
    int64_t m20 = 0, m02 = 0;          // Sums of x^2 and y^2, relative to box.tl().
    int first_run = 0, run_count = 0;  // Its runs: runs()[first_run .. first_run + run_count).
  };

  // Labels `mask` (CV_8UC1, any strides). Components are in raster order of their first pixel.
  void Label(const cv::Mat& mask);
  const std::vector<Component>& components() const { return components_; }
  const std::vector<Run>& runs() const { return sorted_; }
  // Sets the pixels of component `i` to 255 in `out`, whose origin is `origin` in the mask (only
  // the part inside `out` is drawn).
  void Draw(int i, cv::Mat& out, cv::Point origin) const;

 private:
  int Find(int i);
  std::vector<Run> runs_, sorted_;
  std::vector<int> parent_, run_component_, count_;
  std::vector<Component> components_;
};

// The reference: the same components from cv::connectedComponentsWithStats and per-label moments.
std::vector<RunLabeller::Component> LabelReference(const cv::Mat& mask);

}  // namespace softsight
