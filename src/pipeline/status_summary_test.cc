#include "softsight/pipeline/status_summary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace softsight {
namespace {

using ::testing::ElementsAre;

FrameResult Frame2(int64_t index, Observation red, Observation blue) {
  FrameResult result;
  result.frame_index = index;
  result.markers = {{"red", red}, {"blue", blue}};
  return result;
}

Observation Found() { return Observation{cv::Point2d(1, 2), 1.0}; }

TEST(MarkerStatusSummary, ListsRunsOfFramesPerMarkerAndStatus) {
  MarkerStatusSummary summary;
  for (int64_t i = 0; i < 50; ++i) {
    Observation red = Found();
    if (i <= 12) red = Observation::NotFound(MarkerStatus::kAmbiguous, i < 5 ? 2 : 3);
    if (i == 40 || i == 41) red = Observation::NotFound(MarkerStatus::kImplausible);
    if (i == 45) red = Observation::NotFound(MarkerStatus::kImplausible);
    summary.add(Frame2(i, red, Found()));
  }
  EXPECT_THAT(summary.lines(),
              ElementsAre("red: ambiguous in 13 frames: 0-12 (3 candidates); implausible in 3 "
                          "frames: 40-41, 45"));
  EXPECT_EQ(summary.frames(0, MarkerStatus::kAmbiguous), 13);
  EXPECT_EQ(summary.frames(0, MarkerStatus::kFound), 34);
  EXPECT_EQ(summary.frames(1, MarkerStatus::kFound), 50);
  EXPECT_EQ(summary.frames(7, MarkerStatus::kFound), 0);
}

TEST(MarkerStatusSummary, AGapInFrameIndicesEndsARunAndManyRunsAreCounted) {
  MarkerStatusSummary summary;
  const Observation lost = Observation::NotFound(MarkerStatus::kLost);
  summary.add(Frame2(0, Found(), lost));
  summary.add(Frame2(2, Found(), lost));  // Frame 1 was never processed.
  for (int64_t i = 10; i < 30; i += 2) {
    summary.add(Frame2(i, Found(), lost));
    summary.add(Frame2(i + 1, Found(), Found()));
  }
  EXPECT_THAT(summary.lines(), ElementsAre("blue: lost in 12 frames: 0, 2, 10, 12 and 8 more"));
  MarkerStatusSummary all_found;
  all_found.add(Frame2(0, Found(), Found()));
  EXPECT_TRUE(all_found.lines().empty());
}

}  // namespace
}  // namespace softsight
