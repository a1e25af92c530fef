// Drawing at the supersampled resolution. With S sub-samples per pixel side, the supersampled
// pixel xs has its centre at output position x = (xs + 0.5) / S - 0.5, so an output position x
// lies at xs = (x + 0.5) * S - 0.5. Discs and rectangles are rasterised here by one exact rule
// (a sub-pixel belongs to a shape when its centre does) shared by the drawing and the truth,
// so the truth is the centroid of exactly the pixels drawn.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight::sim {

inline cv::Point2d ToSupersampled(const cv::Point2d& p, int s) {
  return cv::Point2d((p.x + 0.5) * s - 0.5, (p.y + 0.5) * s - 0.5);
}
inline double FromSupersampled(double xs, int s) { return (xs + 0.5) / s - 0.5; }

// Discs are drawn with exact-in-the-mean edge coverage: a sub-pixel at distance d from the
// centre is covered by clamp(r - d + 0.5, 0, 1). A binary inside/outside test would move the
// centroid of a 9 px disc by up to ~0.02 px at 4x supersampling; the linear ramp is symmetric
// and keeps it orders of magnitude below that.
inline double DiscCoverage(const cv::Point2d& c, double r, int x, int y) {
  const double d = std::sqrt((x - c.x) * (x - c.x) + (y - c.y) * (y - c.y));
  return std::min(1.0, std::max(0.0, r - d + 0.5));
}
// The rows and, on row y, the columns [*x0, *x1] that may have non-zero coverage.
inline int DiscFirstRow(const cv::Point2d& c, double r) {
  return static_cast<int>(std::ceil(c.y - r - 0.5));
}
inline int DiscLastRow(const cv::Point2d& c, double r) {
  return static_cast<int>(std::floor(c.y + r + 0.5));
}
bool DiscSpan(const cv::Point2d& c, double r, int y, int* x0, int* x1);

// The supersampled pixels covered by a rectangle given in output pixels (see Occluder): those
// whose centres lie in [x - 0.5, x + w - 0.5) x [y - 0.5, y + h - 0.5). May be empty.
cv::Rect SupersampledRect(const cv::Rect2d& rect_px, int s);

// Fills a polygon given in output pixels into `canvas` (CV_8UC3, the supersampled region whose
// top-left sub-pixel is `origin`), blending its colour with opacity alpha. `mask` is a CV_8U
// scratch image of the canvas' size; `scratch` keeps its capacity between calls.
void FillPolygon(const std::vector<cv::Point2d>& outline_px, int s, const cv::Point& origin,
                 const cv::Vec3b& bgr, double alpha, cv::Mat& canvas, cv::Mat& mask,
                 std::vector<cv::Point>* scratch);

// Draws an opaque disc (supersampled centre and radius) into `canvas` (see FillPolygon),
// blending its edge sub-pixels by their coverage.
void FillDisc(const cv::Point2d& centre, double radius, const cv::Point& origin,
              const cv::Vec3b& bgr, cv::Mat& canvas);

// A filled ellipse given as the conic f(x, y) = a x^2 + b xy + c y^2 + d x + e y + g, negative
// inside, in supersampled coordinates. Every ellipse the renderer draws is one: an ellipse
// drawn directly, or a circle on a plane seen through a homography (a conic stays a conic).
// Its edge is drawn like a disc's: a sub-pixel at signed distance t from the boundary
// (estimated to first order as f / |grad f|) is covered by clamp(0.5 - t, 0, 1). That field is
// point-symmetric about the ellipse's centre, so the coverage centroid is the centre.
class Conic {
 public:
  // An ellipse with centre, semi-axes (the first along angle_deg, clockwise in the image) in
  // supersampled pixels.
  static Conic Ellipse(const cv::Point2d& centre, const cv::Size2d& radii, double angle_deg);
  // The image of the circle (centre, radius) of a plane under the homography `image_from_plane`
  // (image = supersampled pixels). The circle must lie in front of the camera.
  static Conic CircleThrough(const cv::Matx33d& image_from_plane, const cv::Point2d& centre,
                             double radius);

  double value(double x, double y) const {
    return (a_ * x + b_ * y + d_) * x + (c_ * y + e_) * y + g_;
  }
  double coverage(int x, int y) const {
    const double f = value(x, y);
    const double gx = 2 * a_ * x + b_ * y + d_, gy = b_ * x + 2 * c_ * y + e_;
    const double g2 = gx * gx + gy * gy;
    // Deep inside (f < 0, far from the edge) the gradient may vanish at the centre.
    if (f <= 0 && f * f >= 2.25 * g2) return 1.0;
    if (f > 0 && f * f >= 0.25 * g2) return 0.0;
    return std::min(1.0, std::max(0.0, 0.5 - f / std::sqrt(g2)));
  }
  // The ellipse's centre and the whole sub-pixels that may have non-zero coverage; empty when
  // the conic is not a real ellipse.
  cv::Point2d centre() const { return centre_; }
  cv::Rect bounds() const { return bounds_; }

 private:
  Conic(double a, double b, double c, double d, double e, double g);
  double a_, b_, c_, d_, e_, g_;
  cv::Point2d centre_;
  cv::Rect bounds_;
};

// Draws the filled ellipse into `canvas` (see FillPolygon), blending its edge by coverage.
void FillConic(const Conic& conic, const cv::Point& origin, const cv::Vec3b& bgr, cv::Mat& canvas);

}  // namespace softsight::sim
