// The body order of marker_finder.h on points with a known order, and the finder on footage of
// its own renderer.
#include "softsight/track/marker_finder.h"

#include <cmath>

#include <gtest/gtest.h>

#include "sim/dot_scene_test_util.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {
namespace {

TEST(OrderAlongBody, ShuffledPointsOnABentArcComeOutInBodyOrderFromTheGivenBase) {
  // Six points along a 200-degree arc, listed out of order.
  std::vector<cv::Point2d> arc;
  for (int i = 0; i < 6; ++i) {
    const double a = CV_PI * 200.0 / 180.0 * i / 5.0;
    arc.emplace_back(320 + 100 * std::cos(a), 240 + 100 * std::sin(a));
  }
  const std::vector<size_t> shuffled = {3, 0, 5, 1, 4, 2};
  std::vector<cv::Point2d> points;
  for (size_t i : shuffled) points.push_back(arc[i]);
  bool ambiguous = true;
  const std::vector<size_t> order =
      OrderAlongBody(points, cv::Size(640, 480), arc[5] + cv::Point2d(3, 0), &ambiguous);
  EXPECT_FALSE(ambiguous);
  ASSERT_EQ(order.size(), 6u);
  for (size_t k = 0; k < 6; ++k) EXPECT_EQ(shuffled[order[k]], 5 - k) << "position " << k;
}

TEST(OrderAlongBody, FourCornersOfASquareHaveNoClearOrder) {
  const std::vector<cv::Point2d> square = {{100, 100}, {200, 100}, {200, 200}, {100, 200}};
  bool ambiguous = false;
  OrderAlongBody(square, cv::Size(640, 480), std::nullopt, &ambiguous);
  EXPECT_TRUE(ambiguous);
}

TEST(OrderAlongBody, WithoutAHintTheBaseIsTheEndNearerTheBorder) {
  const std::vector<cv::Point2d> line = {{320, 200}, {320, 300}, {320, 460}};
  const std::vector<size_t> order = OrderAlongBody(line, cv::Size(640, 480), std::nullopt);
  EXPECT_EQ(order.front(), 2u);
  EXPECT_EQ(order.back(), 0u);
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

// White discs (radius 7 px) standing still at `layout`'s places.
template <size_t N>
std::vector<testing::DotShape> WhiteDotsAt(const cv::Point2d (&layout)[N], uchar level) {
  std::vector<testing::DotShape> shapes;
  for (const cv::Point2d& p : layout) {
    shapes.push_back({{7, 7}, {level, level, level}, {}, 0, {}, [p](double) { return testing::DotPose{p}; }});
  }
  return shapes;
}

// Every marker found lies within 0.5 px of one of `layout`'s places.
template <size_t N>
void ExpectEachAtOneOf(const MarkerFinding& finding, const cv::Point2d (&layout)[N]) {
  for (const FoundMarker& m : finding.markers) {
    double nearest = 1e9;
    for (const cv::Point2d& p : layout) nearest = std::min(nearest, cv::norm(m.position_px - p));
    EXPECT_LT(nearest, 0.5) << m.spec.name;
  }
}

// White dots on a gray bench, filmed by a gray camera and stored in colour (each channel with a
// level or two of its own noise: the frame is not exactly gray), laid out as a plate (two rows of two and one in the middle: no order along a
// body). The finder finds them by gray level, each with its roi, and writes them without a body.
TEST(MarkerFinder, WhiteDotsOnColourFootageOfAGrayBenchAreFoundAndWrittenWithoutABody) {
  testing::DotSceneOptions options;
  options.noise_sigma = 1.5;
  options.tint_sigma = 0.0;
  const cv::Point2d layout[5] = {{260, 200}, {380, 200}, {320, 240}, {260, 280}, {380, 280}};
  const testing::DotScene scene(options, WhiteDotsAt(layout, 240));
  const cv::Mat frame = scene.render(0);
  const MarkerFinding finding = FindMarkers(frame, MarkerFinderOptions{});
  ASSERT_TRUE(finding.ok()) << finding.problem;
  EXPECT_TRUE(finding.intensity);
  ASSERT_EQ(finding.markers.size(), 5u);
  ExpectEachAtOneOf(finding, layout);
  for (const FoundMarker& m : finding.markers) {
    const ColourParams& colour = m.spec.params.get<ColourParams>();
    EXPECT_TRUE(colour.gray && colour.roi) << m.spec.name;
  }
  EXPECT_FALSE(finding.measure.has_triple());
  EXPECT_TRUE(finding.measure.chain.empty());
  bool said = false;
  for (const std::string& note : finding.notes) said = said || note.find("without a body") != std::string::npos;
  EXPECT_TRUE(said);
}

// White dots on a colourful bench (strongly tinted blotches): no coloured blob could be a
// marker, so the dots are found by gray level. A lone white blob there (a lamp, a glint) is not
// taken for a set of markers: init refuses.
TEST(MarkerFinder, WhiteDotsOnAColourfulBenchAreFoundButALoneBrightBlobIsNot) {
  testing::DotSceneOptions options;
  options.tint_sigma = 30.0;
  const cv::Point2d layout[3] = {{200, 300}, {320, 240}, {440, 200}};
  std::vector<testing::DotShape> shapes = WhiteDotsAt(layout, 245);
  const MarkerFinding finding = FindMarkers(testing::DotScene(options, shapes).render(0), {});
  ASSERT_TRUE(finding.ok()) << finding.problem;
  EXPECT_TRUE(finding.intensity);
  ASSERT_EQ(finding.markers.size(), 3u);
  ExpectEachAtOneOf(finding, layout);
  bool said = false;  // The colourful frame's path, not the one for frames with hardly any colour.
  for (const std::string& note : finding.notes) {
    said = said || note == "no coloured marker: white or black dots, by gray level";
  }
  EXPECT_TRUE(said);
  shapes.resize(1);
  const MarkerFinding lone = FindMarkers(testing::DotScene(options, shapes).render(0), {});
  EXPECT_FALSE(lone.ok());
  EXPECT_TRUE(lone.markers.empty());
}


// Three domes on a wooden bench under warm light: red, green, and a blue one whose value (its
// largest channel) runs from 60 on its lit side down to 26 on its shaded side, as a blue dome
// does under a warm side lamp: a person sees three markers. The blue one lies mostly below the
// finder's value floor (40), which cut it into a sliver; it is found whole, at its centre.
TEST(MarkerFinder, ADimBlueDomeUnderWarmLightIsFoundWhole) {
  cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(70, 110, 150));  // Warm wood, BGR.
  cv::Mat noise(frame.size(), CV_16SC3);
  cv::theRNG().state = 7;
  cv::randn(noise, 0, 4);
  const cv::Point2d centres[3] = {{240, 260}, {320, 262}, {400, 258}};
  const double radius = 9.0;
  for (int y = 0; y < frame.rows; ++y) {
    for (int x = 0; x < frame.cols; ++x) {
      cv::Vec3d bgr = cv::Vec3d(frame.at<cv::Vec3b>(y, x)[0], frame.at<cv::Vec3b>(y, x)[1],
                                frame.at<cv::Vec3b>(y, x)[2]);
      for (int k = 0; k < 3; ++k) {
        if (std::hypot(x - centres[k].x, y - centres[k].y) > radius) continue;
        if (k == 0) bgr = {40, 45, 190};
        if (k == 2) bgr = {60, 160, 50};
        if (k == 1) {  // Lit from the top: value 60 at the top edge, 26 at the bottom.
          const double v = 60 - 34 * (y - (centres[1].y - radius)) / (2 * radius);
          bgr = {v, 0.35 * v, 0.25 * v};
        }
      }
      for (int c = 0; c < 3; ++c) {
        frame.at<cv::Vec3b>(y, x)[c] =
            cv::saturate_cast<uchar>(bgr[c] + noise.at<cv::Vec3s>(y, x)[c]);
      }
    }
  }
  const MarkerFinding finding = FindMarkers(frame, MarkerFinderOptions{});
  ASSERT_TRUE(finding.ok()) << finding.problem;
  ASSERT_EQ(finding.markers.size(), 3u);
  ExpectEachAtOneOf(finding, centres);
}

}  // namespace
}  // namespace softsight
