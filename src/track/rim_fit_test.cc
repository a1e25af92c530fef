// The circle of known radius through a partly hidden disc's rim, against exact circles.
#include "track/rim_fit.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace softsight {
namespace {

// The edge pixels (4-neighbour boundary) of a disc of `radius` at `centre`, rasterised, with the
// pixels right of x = `cut` removed (a straight-edged cover), and the cut's own edge included.
std::vector<cv::Point2d> CutDiscEdge(const cv::Point2d& centre, double radius, double cut) {
  cv::Mat mask(80, 80, CV_8U, cv::Scalar(0));
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      if (std::hypot(x - centre.x, y - centre.y) <= radius && x <= cut) mask.at<uchar>(y, x) = 255;
    }
  }
  std::vector<cv::Point2d> edge;
  for (int y = 1; y + 1 < mask.rows; ++y) {
    for (int x = 1; x + 1 < mask.cols; ++x) {
      if (!mask.at<uchar>(y, x)) continue;
      if (!mask.at<uchar>(y, x - 1) || !mask.at<uchar>(y, x + 1) || !mask.at<uchar>(y - 1, x) ||
          !mask.at<uchar>(y + 1, x)) {
        edge.emplace_back(x, y);
      }
    }
  }
  return edge;
}

TEST(RimFit, AHalfCoveredDiscsRimGivesItsCentreWithinAFifthOfAPixel) {
  const cv::Point2d centre(40.3, 39.6);
  const double radius = 10;
  for (const double cut : {60.0, 45.0, 40.3, 38.0}) {  // Whole, a quarter, a half, 60 % cut.
    const std::optional<RimFit> fit = FitRimOfRadius(CutDiscEdge(centre, radius, cut), radius - 0.5);
    ASSERT_TRUE(fit) << "cut " << cut;
    EXPECT_LT(cv::norm(fit->centre_px - centre), 0.2) << "cut " << cut;
    EXPECT_LT(fit->rms_px, 0.5) << "cut " << cut;
    // The rim spans 360 degrees for the whole disc, else twice the angle from the centre to
    // where the cut meets the circle, measured on the uncut side.
    const double c = std::clamp((cut - centre.x) / radius, -1.0, 1.0);
    const double arc = cut >= centre.x + radius ? 360.0 : 2.0 * std::acos(-c) * 180.0 / CV_PI;
    EXPECT_NEAR(fit->arc_deg, arc, 15.0) << "cut " << cut;
  }
}

TEST(RimFit, TooFewPointsOrNoRadiusGiveNoFit) {
  EXPECT_FALSE(FitRimOfRadius({{0, 0}, {1, 0}, {2, 0}}, 5.0));
  EXPECT_FALSE(FitRimOfRadius(CutDiscEdge({40, 40}, 10, 60), 0.0));
}

// The edge pixels of a filled ellipse (semi-axes `a` across, `b` down) at `centre`.
std::vector<cv::Point2d> EllipseEdge(const cv::Point2d& centre, double a, double b) {
  cv::Mat mask(80, 80, CV_8U, cv::Scalar(0));
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      const double u = (x - centre.x) / a, v = (y - centre.y) / b;
      if (u * u + v * v <= 1.0) mask.at<uchar>(y, x) = 255;
    }
  }
  std::vector<cv::Point2d> edge;
  for (int y = 1; y + 1 < mask.rows; ++y) {
    for (int x = 1; x + 1 < mask.cols; ++x) {
      if (mask.at<uchar>(y, x) && (!mask.at<uchar>(y, x - 1) || !mask.at<uchar>(y, x + 1) ||
                                   !mask.at<uchar>(y - 1, x) || !mask.at<uchar>(y + 1, x))) {
        edge.emplace_back(x, y);
      }
    }
  }
  return edge;
}

TEST(RimFit, ACutLeavesAStraightEdgeOffTheCircleAndASlantedDiscABulgingOne) {
  std::vector<std::pair<double, cv::Point2d>> scratch;
  // A disc cut by a straight edge: what is off the circle is the chord.
  const cv::Point2d centre(40.3, 39.6);
  for (const double cut : {45.0, 40.3}) {
    const std::vector<cv::Point2d> edge = CutDiscEdge(centre, 10, cut);
    const std::optional<RimFit> fit = FitRimOfRadius(edge, 9.5);
    ASSERT_TRUE(fit);
    const std::optional<double> bulge = OffRimBulgePx(edge, *fit, 9.5, 0.75, &scratch);
    ASSERT_TRUE(bulge) << "cut " << cut;
    EXPECT_LT(*bulge, 1.0) << "cut " << cut;
  }
  // The same disc seen at a slant (ViSP's mire-2 dots: 17 x 12 px where the disc was 17 x 17): a
  // circle of the disc's radius fits its ends and one side, the other side bulges by pixels.
  const std::vector<cv::Point2d> slanted = EllipseEdge(centre, 8.5, 6.0);
  const std::optional<RimFit> fit = FitRimOfRadius(slanted, 8.4);
  if (fit) {
    const std::optional<double> bulge = OffRimBulgePx(slanted, *fit, 8.4, 0.75, &scratch);
    ASSERT_TRUE(bulge);
    EXPECT_GT(*bulge, 2.0);
  }
}

// The vector inlier count against its scalar reference: the same count whenever it beats `best`
// (and none above `best` when it does not), on rasterised rims whose distances fall exactly on
// the tolerance's edge as well as on random points, every length from 0 to 70 (odd tails, blocks).
TEST(RimFit, TheVectorInlierCountAgreesWithItsReference) {
  cv::RNG rng(45);
  for (int trial = 0; trial < 400; ++trial) {
    const int n = trial % 71;
    std::vector<cv::Point2d> pts;
    for (int i = 0; i < n; ++i) {
      if (trial % 2) {
        pts.emplace_back(rng.uniform(0, 40), rng.uniform(0, 40));  // Pixel centres: ties.
      } else {
        pts.emplace_back(rng.uniform(0.0, 40.0), rng.uniform(0.0, 40.0));
      }
    }
    const cv::Point2d c = trial % 3 ? cv::Point2d(rng.uniform(5, 35), rng.uniform(5, 35))
                                    : cv::Point2d(rng.uniform(5.0, 35.0), rng.uniform(5.0, 35.0));
    const double r = trial % 4 ? rng.uniform(1, 20) : rng.uniform(1.0, 20.0);
    const double tol = trial % 5 ? 0.75 : 1.0;
    const int exact = CountRimInliersReference(pts, c, r, tol);
    EXPECT_EQ(CountRimInliers(pts, c, r, tol, -1), exact) << "trial " << trial;
    EXPECT_EQ(CountRimInliers(pts, c, r, tol, 0), exact > 0 ? exact : 0) << "trial " << trial;
    for (const int best : {exact - 1, exact, exact + 1, n / 2, n}) {
      const int counted = CountRimInliers(pts, c, r, tol, best);
      if (exact > best) {
        EXPECT_EQ(counted, exact) << "trial " << trial << " best " << best;
      } else {
        EXPECT_LE(counted, best) << "trial " << trial << " best " << best;
      }
    }
  }
}

}  // namespace
}  // namespace softsight
