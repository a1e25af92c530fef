// The template tracker's parts, reached without the tracker: the similarity peak's sub-pixel
// offset and the template's centre of symmetry, against exact truth.
#include "track/template_parts.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace softsight::template_internal {
namespace {

TEST(TemplateParts, PeakOffsetRecoversTheVertexOfAParabolaAndOfAV) {
  for (const double vertex : {-0.4, -0.1, 0.0, 0.25, 0.45}) {
    const auto parabola = [vertex](double x) { return 10.0 - 3.0 * (x - vertex) * (x - vertex); };
    EXPECT_NEAR(PeakOffset(parabola(-1), parabola(0), parabola(1), false), vertex, 1e-12);
    const auto v = [vertex](double x) { return 10.0 - 2.0 * std::abs(x - vertex); };
    EXPECT_NEAR(PeakOffset(v(-1), v(0), v(1), true), vertex, 1e-12);
  }
}

TEST(TemplateParts, SymmetryCentreOfAnOffCentreDiscIsTheDiscsCentre) {
  // A bright disc drawn at 1/256 px in a 31x31 template, away from its geometric centre (15, 15).
  cv::Mat templ(31, 31, CV_8UC1, cv::Scalar(40));
  const cv::Point2d centre(16.5, 14.25);
  cv::circle(templ, cv::Point(cvRound(centre.x * 256), cvRound(centre.y * 256)), 7 * 256,
             cv::Scalar(220), cv::FILLED, cv::LINE_AA, 8);
  double strength = 0.0;
  const cv::Point2d found = SymmetryCentre(templ, &strength);
  EXPECT_GT(strength, kMinSymmetry);
  EXPECT_NEAR(found.x, centre.x, 0.1);
  EXPECT_NEAR(found.y, centre.y, 0.1);
}

}  // namespace
}  // namespace softsight::template_internal
