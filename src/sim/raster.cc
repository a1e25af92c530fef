#include "sim/raster.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace softsight::sim {
namespace {

constexpr int kShiftBits = 8;  // Sub-pixel vertex precision for cv::fillPoly.

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
      cv::Vec3b& p = row[x - origin.x];
      if (c >= 1) {
        p = bgr;
      } else {
        for (int k = 0; k < 3; ++k) p[k] = cv::saturate_cast<uchar>(p[k] + c * (bgr[k] - p[k]));
      }
    }
  }
}

}  // namespace softsight::sim
