#include "sim/raster.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace softsight::sim {
namespace {

constexpr int kShiftBits = 8;  // Sub-pixel vertex precision for cv::fillPoly.

// Paints `bgr` over the pixel `p` in proportion to the shape's coverage `c` of it (0, 1].
void BlendPixel(const cv::Vec3b& bgr, double c, cv::Vec3b& p) {
  if (c >= 1) {
    p = bgr;
  } else {
    for (int k = 0; k < 3; ++k) p[k] = cv::saturate_cast<uchar>(p[k] + c * (bgr[k] - p[k]));
  }
}

}  // namespace

bool DiscSpan(const cv::Point2d& c, double r, int y, int* x0, int* x1) {
  const double dy = y - c.y;
  const double outer = r + 0.5;
  const double h2 = outer * outer - dy * dy;
  if (h2 < 0) return false;
  const double h = std::sqrt(h2);
  *x0 = static_cast<int>(std::ceil(c.x - h));
  *x1 = static_cast<int>(std::floor(c.x + h));
  return *x0 <= *x1;
}

cv::Rect SupersampledRect(const cv::Rect2d& rect_px, int s) {
  // The rectangle spans [x - 0.5, x + w - 0.5) in output positions (whole pixels x .. x+w-1
  // for integers). Sub-pixel xs, at output position (xs + 0.5) / s - 0.5, is inside when
  // ceil(x s - 0.5) <= xs < ceil((x + w) s - 0.5).
  auto first = [s](double v) { return static_cast<int>(std::ceil(v * s - 0.5)); };
  const int x0 = first(rect_px.x), x1 = first(rect_px.x + rect_px.width);
  const int y0 = first(rect_px.y), y1 = first(rect_px.y + rect_px.height);
  if (x1 <= x0 || y1 <= y0) return cv::Rect();
  return cv::Rect(x0, y0, x1 - x0, y1 - y0);
}

void FillPolygon(const std::vector<cv::Point2d>& outline_px, int s, const cv::Point& origin,
                 const cv::Vec3b& bgr, double alpha, cv::Mat& canvas, cv::Mat& mask,
                 std::vector<cv::Point>* scratch) {
  CV_DbgAssert(canvas.type() == CV_8UC3 && mask.type() == CV_8U && mask.size() == canvas.size());
  if (outline_px.size() < 3) return;
  scratch->clear();
  constexpr double kOne = 1 << kShiftBits;
  int x0 = INT32_MAX, y0 = INT32_MAX, x1 = INT32_MIN, y1 = INT32_MIN;
  for (const cv::Point2d& p : outline_px) {
    const cv::Point2d q = ToSupersampled(p, s) - cv::Point2d(origin);
    const cv::Point fixed(cvRound(q.x * kOne), cvRound(q.y * kOne));
    scratch->push_back(fixed);
    x0 = std::min(x0, fixed.x >> kShiftBits);
    y0 = std::min(y0, fixed.y >> kShiftBits);
    x1 = std::max(x1, (fixed.x >> kShiftBits) + 1);
    y1 = std::max(y1, (fixed.y >> kShiftBits) + 1);
  }
  const cv::Rect box =
      cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1) & cv::Rect(0, 0, canvas.cols, canvas.rows);
  if (box.empty()) return;
  cv::Mat mask_box = mask(box);
  mask_box.setTo(0);
  // fillPoly works in the box's coordinates. (Its `offset` argument is added to the fixed-point
  // coordinates unscaled, so the vertices are moved here instead.)
  for (cv::Point& p : *scratch) p -= cv::Point(box.x << kShiftBits, box.y << kShiftBits);
  const cv::Point* points = scratch->data();
  const int count = static_cast<int>(scratch->size());
  cv::fillPoly(mask_box, &points, &count, 1, cv::Scalar(255), cv::LINE_8, kShiftBits);
  const int a = cvRound(alpha * 256);
  const int b0 = bgr[0] * a, b1 = bgr[1] * a, b2 = bgr[2] * a;
  const int keep = 256 - a;
  for (int y = 0; y < box.height; ++y) {
    const uchar* m = mask_box.ptr<uchar>(y);
    uchar* c = canvas.ptr<uchar>(box.y + y) + 3 * box.x;
    for (int x = 0; x < box.width; ++x, c += 3) {
      if (m[x] == 0) continue;
      c[0] = static_cast<uchar>((c[0] * keep + b0 + 128) >> 8);
      c[1] = static_cast<uchar>((c[1] * keep + b1 + 128) >> 8);
      c[2] = static_cast<uchar>((c[2] * keep + b2 + 128) >> 8);
    }
  }
}

void FillDisc(const cv::Point2d& centre, double radius, const cv::Point& origin,
              const cv::Vec3b& bgr, cv::Mat& canvas) {
  const int first = std::max(origin.y, DiscFirstRow(centre, radius));
  const int last = std::min(origin.y + canvas.rows - 1, DiscLastRow(centre, radius));
  for (int y = first; y <= last; ++y) {
    int x0, x1;
    if (!DiscSpan(centre, radius, y, &x0, &x1)) continue;
    x0 = std::max(x0, origin.x);
    x1 = std::min(x1, origin.x + canvas.cols - 1);
    cv::Vec3b* row = canvas.ptr<cv::Vec3b>(y - origin.y);
    for (int x = x0; x <= x1; ++x) {
      const double c = DiscCoverage(centre, radius, x, y);
      if (c <= 0) continue;
      BlendPixel(bgr, c, row[x - origin.x]);
    }
  }
}

Conic::Conic(double a, double b, double c, double d, double e, double g)
    : a_(a), b_(b), c_(c), d_(d), e_(e), g_(g) {
  if (a_ < 0) {  // Bounded region negative.
    a_ = -a_, b_ = -b_, c_ = -c_, d_ = -d_, e_ = -e_, g_ = -g_;
  }
  a = a_, b = b_, c = c_, d = d_, e = e_;
  // Centre: where the gradient vanishes; the ellipse is (p - p0)^T Q (p - p0) = -f(p0) with
  // Q = [a b/2; b/2 c], and its extent along x is sqrt(-f(p0) (Q^-1)_xx) (same for y).
  const double det = a * c - b * b / 4;
  if (!(det > 0)) return;
  const double x0 = (b * e / 2 - c * d) / (2 * det), y0 = (b * d / 2 - a * e) / (2 * det);
  centre_ = cv::Point2d(x0, y0);
  const double f0 = value(x0, y0);
  if (!(f0 < 0)) return;
  const double half_w = std::sqrt(-f0 * c / det);
  const double half_h = std::sqrt(-f0 * a / det);
  // One sub-pixel beyond the edge covers the ramp (and the first-order distance estimate).
  const int bx0 = static_cast<int>(std::floor(x0 - half_w - 1.5));
  const int by0 = static_cast<int>(std::floor(y0 - half_h - 1.5));
  const int bx1 = static_cast<int>(std::ceil(x0 + half_w + 1.5));
  const int by1 = static_cast<int>(std::ceil(y0 + half_h + 1.5));
  bounds_ = cv::Rect(bx0, by0, bx1 - bx0 + 1, by1 - by0 + 1);
}

Conic Conic::Ellipse(const cv::Point2d& centre, const cv::Size2d& radii, double angle_deg) {
  const double t = angle_deg * CV_PI / 180.0;
  const double ct = std::cos(t), st = std::sin(t);
  const double ia = 1.0 / (radii.width * radii.width), ib = 1.0 / (radii.height * radii.height);
  // (u/ra)^2 + (v/rb)^2 - 1 with u = ct dx + st dy, v = -st dx + ct dy. Scaled by the mean radius
  // squared only to keep the numbers near 1; the coverage does not depend on the scale.
  const double k = radii.width * radii.height;
  const double a = k * (ct * ct * ia + st * st * ib);
  const double b = k * 2 * ct * st * (ia - ib);
  const double c = k * (st * st * ia + ct * ct * ib);
  const double x = centre.x, y = centre.y;
  return Conic(a, b, c, -2 * a * x - b * y, -2 * c * y - b * x,
               a * x * x + b * x * y + c * y * y - k);
}

Conic Conic::CircleThrough(const cv::Matx33d& image_from_plane, const cv::Point2d& centre,
                           double radius) {
  // The circle's matrix C (q^T C q = 0 for plane points q = (u, v, 1)); the image conic is
  // H^-T C H^-1. Its sign is kept: for p = lambda H q, p^T C' p = lambda^2 q^T C q.
  const cv::Matx33d circle(1, 0, -centre.x, 0, 1, -centre.y, -centre.x, -centre.y,
                           centre.x * centre.x + centre.y * centre.y - radius * radius);
  const cv::Matx33d inv = image_from_plane.inv();
  cv::Matx33d m = inv.t() * circle * inv;
  const double scale = 1.0 / std::max(std::abs(m(0, 0)), std::abs(m(1, 1)));
  m *= scale;
  return Conic(m(0, 0), m(0, 1) + m(1, 0), m(1, 1), m(0, 2) + m(2, 0), m(1, 2) + m(2, 1), m(2, 2));
}

void FillConic(const Conic& conic, const cv::Point& origin, const cv::Vec3b& bgr,
               cv::Mat& canvas) {
  const cv::Rect box = conic.bounds() & cv::Rect(origin, canvas.size());
  for (int y = box.y; y < box.y + box.height; ++y) {
    cv::Vec3b* row = canvas.ptr<cv::Vec3b>(y - origin.y);
    for (int x = box.x; x < box.x + box.width; ++x) {
      const double c = conic.coverage(x, y);
      if (c <= 0) continue;
      BlendPixel(bgr, c, row[x - origin.x]);
    }
  }
}

}  // namespace softsight::sim
