// Golden real data for the colour tracker: a real photograph, OpenCV's sample smarties.png
// (413x356, coloured sugar-coated candies on white paper, with specular highlights, shadows and
// JPEG-like softness; shipped by Debian's opencv-doc), where nothing was rendered by softsight.
// Known answers, checked by hand on an 8x enlargement: four red candies (centres near (33, 228),
// (99, 260), (219, 306) and (288, 213)), two orange, three blue, three green, two brown; no
// magenta or yellow candy, and the paper is white.
#include <optional>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/opencv_samples.h"
#include "softsight/track/tracker.h"
#include "track/colour_tracker_impl.h"

namespace softsight {
namespace {

class GoldenSmarties : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::optional<std::string> path = samples::OpenCvSample("smarties.png");
    if (path) image_ = cv::imread(*path, cv::IMREAD_COLOR);
    if (image_.empty()) GTEST_SKIP() << samples::MissingSampleMessage("smarties.png");
  }
  static ColourParams Auto(cv::Vec3b bgr) {
    ColourParams p;
    p.auto_bgr = bgr;
    return p;
  }
  cv::Mat image_;
};

std::string Describe(const ColourTracker& tracker) {
  std::string text;
  for (const MarkerCandidate& c : tracker.candidates()) {
    text += " (" + std::to_string(c.position_px.x) + ", " + std::to_string(c.position_px.y) +
            ") area " + std::to_string(c.area_px) + " " + CandidateVerdictName(c.verdict) + ";";
  }
  return text;
}

TEST_F(GoldenSmarties, ColoursThatAreNotThereAreNotFound) {
  // Default settings (no size range, no roi), as a first user would write them. The yellow
  // nominal meets the yellowish rims of the orange candies' highlights (a few pixels where red
  // clips first): too small to have pixels of their own colour, so never a marker.
  struct Case {
    const char* what;
    ColourParams params;
  };
  ColourParams magenta_hsv;
  magenta_hsv.h = {140, 165};
  magenta_hsv.s = {80, 255};
  magenta_hsv.v = {60, 255};
  ColourParams white_dot;
  white_dot.gray = HsvRange{200, 255};  // The paper itself: one huge blob, never a dot.
  const Case cases[] = {{"magenta auto_colour", Auto({200, 40, 200})},
                        {"yellow auto_colour", Auto({30, 220, 230})},
                        {"purple auto_colour", Auto({140, 30, 110})},
                        {"magenta hsv", magenta_hsv},
                        {"white gray-level dot", white_dot}};
  for (const Case& c : cases) {
    ColourTracker tracker(c.params);
    const Observation obs = tracker.update(image_);
    EXPECT_FALSE(obs.found()) << c.what << " found at (" << obs.position_px->x << ", "
                              << obs.position_px->y << "):" << Describe(tracker);
  }
}

TEST_F(GoldenSmarties, FourRedCandiesAreAmbiguousNotAGuess) {
  // The nominal colour is a red candy's own core colour; without a roi several candidates fit
  // about equally: not found, with the reason.
  ColourTracker tracker(Auto({10, 5, 230}));
  const Observation obs = tracker.update(image_);
  EXPECT_EQ(obs.status(), MarkerStatus::kAmbiguous) << Describe(tracker);
  int fits = 0;
  for (const MarkerCandidate& c : tracker.candidates()) {
    fits += c.verdict == CandidateVerdict::kFits;
  }
  EXPECT_GE(fits, 3) << Describe(tracker);
}

TEST_F(GoldenSmarties, RedCandyInARoiIsFoundAtItsCentreAndFollowed) {
  ColourParams params = Auto({10, 5, 230});
  params.roi = cv::Rect(262, 188, 52, 52);
  ColourTracker tracker(params);
  const Observation first = tracker.update(image_);
  ASSERT_TRUE(first.found()) << Describe(tracker);
  // Hand-checked: the candy's outline spans x 261.5..314.9, y 187.5..239 (edges read to about
  // 1 px); its highlight and shadow move the colour centroid a little.
  EXPECT_NEAR(first.position_px->x, 288.2, 2.0);
  EXPECT_NEAR(first.position_px->y, 213.3, 2.0);
  // The same real pixels moved by known whole-pixel steps (the paper beyond the border
  // replicated): tracking follows by exactly the shift.
  cv::Mat moved;
  for (int k = 1; k <= 6; ++k) {
    const cv::Point shift(3 * k, -2 * k);
    const cv::Matx23d translate(1, 0, shift.x, 0, 1, shift.y);
    cv::warpAffine(image_, moved, translate, image_.size(), cv::INTER_NEAREST,
                   cv::BORDER_REPLICATE);
    const Observation obs = tracker.update(moved);
    ASSERT_TRUE(obs.found()) << "step " << k << Describe(tracker);
    EXPECT_NEAR(obs.position_px->x - first.position_px->x, shift.x, 0.01) << "step " << k;
    EXPECT_NEAR(obs.position_px->y - first.position_px->y, shift.y, 0.01) << "step " << k;
  }
}

}  // namespace
}  // namespace softsight
