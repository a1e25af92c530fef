// The stereo window's drawing and keys, without a window: a rendered actuator seen by a rig of
// known pose, tracked by a StereoSession, composed by StereoView; the canvas is checked against
// the renderer's truth (each view where it belongs, each marker's ring at its true position)
// and the chart against the session's rows.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgproc.hpp>

#include "app/stereo_test_util.h"
#include "calib/stereo_test_util.h"
#include "core/test_util.h"
#include "gui/live_test_util.h"
#include "gui/live_view.h"  // StatusBandHeight
#include "gui/stereo_view.h"
#include "gui/stereo_window.h"
#include "softsight/config/config.h"
#include "softsight/pipeline/stereo_session.h"
#include "softsight/sim/stereo_scene.h"

namespace softsight {
namespace {

using testing::RingPoints;

// Red pixels of the "not found" cross within `radius` of `centre`.
int RedPixelsNear(const cv::Mat& image, const cv::Point2d& centre, int radius) {
  const cv::Rect box = cv::Rect(cvRound(centre.x) - radius, cvRound(centre.y) - radius,
                                2 * radius + 1, 2 * radius + 1) &
                       cv::Rect(0, 0, image.cols, image.rows);
  cv::Mat red;
  // The overlay's pure red, not the red marker's (40, 40, 220).
  cv::inRange(image(box), cv::Scalar(0, 0, 235), cv::Scalar(25, 25, 255), red);
  return cv::countNonZero(red);
}

// Of `view`'s pixels, the fraction equal to `frame`'s (where no overlay is drawn).
double SameFraction(const cv::Mat& view, const cv::Mat& frame) {
  cv::Mat diff;
  cv::absdiff(view, frame, diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  return 1.0 - static_cast<double>(cv::countNonZero(diff)) / static_cast<double>(diff.total());
}

class StereoViewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::ofstream(dir_.file("markers.yaml")) << testing::StereoMarkersYaml();
    config_ = LoadTrackingConfig(dir_.file("markers.yaml"));
  }
  FramePair Pair(int index, StereoSceneTruth* truth) {
    FramePair pair;
    *truth = scene_.render(index, pair.left.image, pair.right.image);
    pair.left.index = pair.right.index = index;
    pair.left.time_s = pair.right.time_s = index / 30.0;
    return pair;
  }

  testing::TempDir dir_;
  TrackingConfig config_;
  StereoScene scene_{MakeStereoRig(), [] {
                       StereoSceneOptions o;
                       o.frame_count = 6;
                       o.max_bend_deg = 90.0;
                       return o;
                     }()};
};

TEST_F(StereoViewTest, BothViewsSideBySideWithTheirOverlayAtTheMarkersAndTheAnglesCharted) {
  StereoSession session(config_, config_, testing::CalibrationOfRig(scene_.rig()));
  StereoView view;
  view.set_configs(config_, config_);
  StereoSceneTruth truth;
  FramePair pair;
  std::vector<std::optional<double>> angles;
  for (int i = 0; i < 6; ++i) {
    pair = Pair(i, &truth);
    const StereoFrameResult& result = session.process(pair);
    view.add(result);
    angles.push_back(result.shape.angle_deg);
    view.compose(pair, result, session.left_result(), session.right_result(), "");
  }
  const StereoFrameResult& result = session.process(pair);  // The last pair once more.
  const cv::Mat canvas = view.compose(pair, result, session.left_result(), session.right_result(),
                                      "").clone();
  // Both 640x480 views at full size side by side, the status band and the chart under them.
  EXPECT_EQ(view.view_rect(StereoView::kLeft), cv::Rect(0, 0, 640, 480));
  EXPECT_EQ(view.view_rect(StereoView::kRight), cv::Rect(640, 0, 640, 480));
  EXPECT_EQ(canvas.size(), cv::Size(1280, 480 + StatusBandHeight() + StripChartOptions{}.height_px));
  EXPECT_EQ(view.layout().chart, cv::Rect(0, 480 + StatusBandHeight(), 1280, 220));
  // Each view shows its own frame (the overlay covers a little of it) ...
  EXPECT_GT(SameFraction(canvas(cv::Rect(0, 0, 640, 480)), pair.left.image), 0.9);
  EXPECT_GT(SameFraction(canvas(cv::Rect(640, 0, 640, 480)), pair.right.image), 0.9);
  // ... and each marker's ring around its true position in each view, none in the frames.
  for (const StereoMarkerTruth& m : truth.markers) {
    EXPECT_EQ(RingPoints(pair.left.image, m.left_px), 0) << m.name;
    EXPECT_GE(RingPoints(canvas, m.left_px), 20) << m.name << " left at " << m.left_px;
    EXPECT_GE(RingPoints(canvas, m.right_px + cv::Point2d(640, 0)), 20)
        << m.name << " right at " << m.right_px;
    EXPECT_EQ(RedPixelsNear(canvas, m.left_px, 10), 0) << m.name << " crossed out";
  }
  // The chart has every pair's 3D angle (the last pair twice: its time replaced, not added),
  // each camera's own and the out-of-plane angle of the row.
  const StripChart& chart = view.chart();
  EXPECT_EQ(chart.size(), 6u);
  ASSERT_TRUE(result.shape.angle_deg);
  EXPECT_EQ(chart.newest(StereoView::kAngle3d), result.shape.angle_deg);
  EXPECT_EQ(chart.newest(StereoView::kAngle3d), angles.back());
  EXPECT_NEAR(*chart.newest(StereoView::kAngle3d), truth.angle_deg, 0.5);
  EXPECT_EQ(chart.newest(StereoView::kAngleLeft), result.left_angle_deg);
  EXPECT_EQ(chart.newest(StereoView::kAngleRight), result.right_angle_deg);
  ASSERT_TRUE(chart.newest(StereoView::kOutOfPlane));
  EXPECT_NEAR(*chart.newest(StereoView::kOutOfPlane), 30.0, 1.0);
  EXPECT_EQ(chart.lane(0).label, "angle [deg]");
  EXPECT_EQ(chart.lane(1).label, "out of plane [deg]");
  // Drawn: the 3D angle's curve through each pair's angle (a vertex of the curve).
  const cv::Mat chart_area = canvas(view.layout().chart);
  for (int k = 2; k < 6; ++k) {
    ASSERT_TRUE(angles[k]);
    const cv::Point p(cvRound(chart.x_of(k / 30.0)), cvRound(chart.y_of(0, *angles[k])));
    bool curve = false;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const cv::Vec3b px = chart_area.at<cv::Vec3b>(p + cv::Point(dx, dy));
        const cv::Scalar& colour = StripChart::kColours[0];
        curve |= std::abs(px[0] - colour[0]) < 40 && std::abs(px[1] - colour[1]) < 40 &&
                 std::abs(px[2] - colour[2]) < 40;
      }
    }
    EXPECT_TRUE(curve) << "no 3D angle curve at pair " << k << ", " << p;
  }
}

TEST_F(StereoViewTest, AMarkerNotFoundIn3dIsCrossedOutInBothViewsWithoutA3dAngle) {
  StereoSession session(config_, config_, testing::CalibrationOfRig(scene_.rig()));
  StereoView view;
  view.set_configs(config_, config_);
  StereoSceneTruth truth;
  FramePair pair = Pair(5, &truth);
  // The right view's blue marker moved 12 px down: off its epipolar line (near horizontal).
  const StereoMarkerTruth& blue = truth.markers[1];
  ASSERT_EQ(blue.name, "blue");
  const cv::Rect box(cvRound(blue.right_px.x) - 9, cvRound(blue.right_px.y) - 9, 19, 19);
  const cv::Mat patch = pair.right.image(box).clone();
  pair.right.image(box).setTo(cv::Scalar(200, 200, 205));  // The body's colour.
  patch.copyTo(pair.right.image(box + cv::Point(0, 12)));
  const StereoFrameResult& result = session.process(pair);
  ASSERT_EQ(result.markers[1].status, "epipolar");
  view.add(result);
  const cv::Mat canvas =
      view.compose(pair, result, session.left_result(), session.right_result(), "PAUSED");
  // Found in each view, not in 3D: no yellow ring, a red cross, in both views.
  EXPECT_LT(RingPoints(canvas, blue.left_px), 3);
  EXPECT_GT(RedPixelsNear(canvas, blue.left_px, 10), 20);
  const cv::Point2d moved = blue.right_px + cv::Point2d(640, 12);
  EXPECT_LT(RingPoints(canvas, moved), 3);
  EXPECT_GT(RedPixelsNear(canvas, moved, 10), 20);
  // The others keep their rings.
  for (int i : {0, 2}) {
    EXPECT_GE(RingPoints(canvas, truth.markers[i].left_px), 20) << truth.markers[i].name;
    EXPECT_GE(RingPoints(canvas, truth.markers[i].right_px + cv::Point2d(640, 0)), 20);
  }
  // No 3D angle without the middle marker; each camera still has its own.
  EXPECT_FALSE(view.chart().newest(StereoView::kAngle3d));
  EXPECT_TRUE(view.chart().newest(StereoView::kAngleLeft));
  std::vector<std::string> lines;
  StereoStatusLines(result, lines);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[1].find("blue (epipolar)"), std::string::npos) << lines[1];
}

TEST_F(StereoViewTest, ASmallScreenScalesBothViewsDownAndTheRingsWithThem) {
  StereoSession session(config_, config_, testing::CalibrationOfRig(scene_.rig()));
  StereoViewOptions options;
  options.max_canvas = cv::Size(800, 700);
  StereoView view(options);
  view.set_configs(config_, config_);
  StereoSceneTruth truth;
  const FramePair pair = Pair(3, &truth);
  const StereoFrameResult& result = session.process(pair);
  view.add(result);
  const cv::Mat& canvas =
      view.compose(pair, result, session.left_result(), session.right_result(), "");
  EXPECT_LE(canvas.cols, 800);
  EXPECT_LE(canvas.rows, 700);
  const cv::Rect left = view.view_rect(StereoView::kLeft), right = view.view_rect(StereoView::kRight);
  EXPECT_EQ(left.width, right.width);
  EXPECT_EQ(right.x, left.br().x);
  const double scale = left.width / 640.0;
  EXPECT_LT(scale, 0.7);
  // The red marker's (a ring of 12 px scaled with the view) centre: the scaled truth.
  const cv::Mat shown = canvas(right);
  cv::Mat full;
  cv::resize(shown, full, cv::Size(640, 480), 0, 0, cv::INTER_LINEAR);
  EXPECT_GE(RingPoints(full, truth.markers[0].right_px, 12), 12);
}

TEST(StereoWindowKeys, SpacePausesDotStepsWhilePausedQAndEscapeStop) {
  StereoWindowKeys keys;
  EXPECT_EQ(keys.press(-1), "");
  EXPECT_EQ(keys.press('.'), "");  // Playing: nothing to step.
  EXPECT_FALSE(keys.step);
  EXPECT_EQ(keys.press(' '), "paused");
  EXPECT_TRUE(keys.paused);
  EXPECT_EQ(keys.press('.'), "step");
  EXPECT_TRUE(keys.step);
  EXPECT_EQ(keys.press(' '), "resumed");
  EXPECT_FALSE(keys.paused);
  EXPECT_FALSE(keys.step);
  EXPECT_EQ(keys.press('x'), "");
  EXPECT_FALSE(keys.quit);
  EXPECT_EQ(keys.press('q'), "stop");
  EXPECT_TRUE(keys.quit);
  StereoWindowKeys escape;
  escape.press(27 | 0x100000);  // waitKeyEx's modifier bits do not matter.
  EXPECT_TRUE(escape.quit);
}

}  // namespace
}  // namespace softsight
