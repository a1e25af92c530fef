#include "sim/corruption.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "softsight/sim/plate_scene.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

cv::Mat Frame() {
  SceneOptions o;
  o.size = cv::Size(160, 120);
  o.frame_count = 2;
  o.length_px = 80;
  o.width_px = 12;
  o.marker_radius_px = 4;
  cv::Mat image;
  SyntheticScene(o).render(0, image);
  return image;
}

TEST(CorruptFrameTest, GarbageBlockCoversAQuarterOrTheGivenBox) {
  const cv::Mat clean = Frame();
  cv::Mat a = clean.clone(), b = clean.clone();
  CorruptFrame(CorruptionKind::kGarbageBlock, 1, cv::Mat(), a);
  CorruptFrame(CorruptionKind::kGarbageBlock, 1, cv::Mat(), b);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);  // Deterministic.
  cv::Mat changed;
  const cv::Mat differs = a != clean;
  cv::reduce(differs.reshape(1, clean.rows * clean.cols), changed, 1, cv::REDUCE_MAX);
  const double fraction = cv::countNonZero(changed) / double(clean.total());
  EXPECT_GT(fraction, 0.2);
  EXPECT_LE(fraction, 0.25);
  cv::Mat c = clean.clone();
  const cv::Rect box(30, 40, 12, 10);
  CorruptFrame(CorruptionKind::kGarbageBlock, 2, cv::Mat(), c, box);
  cv::Mat outside = c.clone();
  clean(box).copyTo(outside(box));
  EXPECT_EQ(cv::norm(outside, clean, cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(c(box), clean(box), cv::NORM_L1) / box.area(), 30.0);
}

TEST(CorruptFrameTest, OtherVideoReplacesTheFrame) {
  const cv::Mat clean = Frame();
  PlateSceneOptions plate;
  plate.size = cv::Size(320, 240);
  plate.frame_count = 1;
  cv::Mat other;
  PlateScene(plate).render(0, other);
  cv::Mat a = clean.clone();
  CorruptFrame(CorruptionKind::kOtherVideo, 1, other, a);
  ASSERT_EQ(a.size(), clean.size());
  ASSERT_EQ(a.type(), clean.type());
  cv::Mat expected;
  cv::resize(other, expected, clean.size(), 0, 0, cv::INTER_AREA);
  EXPECT_EQ(cv::norm(a, expected, cv::NORM_INF), 0);
  cv::Mat b = clean.clone();
  EXPECT_THROW(CorruptFrame(CorruptionKind::kOtherVideo, 1, cv::Mat(), b), InputError);
}

TEST(CorruptFrameTest, ShiftedBandMovesRowsSideways) {
  const cv::Mat clean = Frame();
  cv::Mat a = clean.clone();
  CorruptFrame(CorruptionKind::kShiftedBand, 4, cv::Mat(), a);
  int changed_rows = 0, first = -1, last = -1;
  for (int y = 0; y < clean.rows; ++y) {
    if (cv::norm(a.row(y), clean.row(y), cv::NORM_INF) > 0) {
      ++changed_rows;
      if (first < 0) first = y;
      last = y;
    }
  }
  EXPECT_GE(changed_rows, clean.rows / 8 - 1);
  EXPECT_EQ(last - first + 1, changed_rows);  // One band.
  cv::Mat b = clean.clone();
  CorruptFrame(CorruptionKind::kShiftedBand, 5, cv::Mat(), b);
  EXPECT_GT(cv::norm(a, b, cv::NORM_INF), 0);  // Another seed, another band.
}

}  // namespace
}  // namespace softsight
