#include "softsight/sim/truth_score.h"

#include <gtest/gtest.h>

namespace softsight {
namespace {

MarkerTruth Truth(double x, double y, double visible) {
  MarkerTruth truth;
  if (visible > 0) truth.centroid_px = cv::Point2d(x, y);
  truth.visible_fraction = visible;
  return truth;
}

Observation Found(double x, double y) {
  Observation o;
  o.position_px = cv::Point2d(x, y);
  return o;
}

TEST(Judge, OneVisibilityRuleForWhatMustBeFound) {
  EXPECT_EQ(Judge(Truth(1, 1, 1.0), Found(1, 1)), TruthVerdict::kHit);
  EXPECT_EQ(Judge(Truth(1, 1, kMustFindVisibleFraction), Observation{}), TruthVerdict::kMiss);
  EXPECT_EQ(Judge(Truth(1, 1, 0.49), Observation{}), TruthVerdict::kExempt);
  EXPECT_EQ(Judge(Truth(1, 1, 0.49), Found(1, 1)), TruthVerdict::kExempt);
  EXPECT_EQ(Judge(Truth(0, 0, 0.0), Found(1, 1)), TruthVerdict::kFalseReport);
  EXPECT_EQ(Judge(Truth(0, 0, 0.0), Observation{}), TruthVerdict::kHiddenLost);
}

TEST(TruthScorer, CountsAndErrorsOverFrames) {
  TruthScorer scorer(2);
  SceneTruth truth;
  truth.markers = {Truth(10, 10, 1.0), Truth(0, 0, 0.0)};
  truth.measurement.angle_deg = 150.0;
  FrameResult result;
  result.markers = {{"a", Found(13, 14)}, {"b", Found(5, 5)}};  // 5 px off; a false report.
  result.measurement.angle_deg = 151.0;
  scorer.add(truth, result);
  truth.markers = {Truth(20, 10, 1.0), Truth(4, 4, 0.8)};
  result.markers = {{"a", Found(23, 14)}, {"b", Observation{}}};  // Same offset; a miss.
  result.measurement.angle_deg.reset();
  scorer.add(truth, result);

  const TruthScore score = scorer.score();
  EXPECT_EQ(score.frames, 2);
  EXPECT_EQ(score.visible, 3);
  EXPECT_EQ(score.found_visible, 2);
  EXPECT_EQ(score.misses, 1);
  EXPECT_EQ(score.hidden, 1);
  EXPECT_EQ(score.false_reports, 1);
  EXPECT_DOUBLE_EQ(*score.centroid_rms_px, 5.0);
  EXPECT_DOUBLE_EQ(*score.centroid_max_px, 5.0);
  EXPECT_DOUBLE_EQ(*score.centroid_p95_px, 5.0);
  EXPECT_EQ(score.wrong_finds, 2) << "5 px off is farther than kWrongFindPx";
  EXPECT_DOUBLE_EQ(*score.precision_rms_px, 0.0) << "a constant offset is not imprecision";
  EXPECT_EQ(score.angle_frames, 1);
  EXPECT_DOUBLE_EQ(*score.angle_rms_deg, 1.0);
}

TEST(TruthScorer, P95IsTheNearestRankOfTheHitErrors) {
  TruthScorer scorer(1);
  SceneTruth truth;
  truth.markers = {Truth(0, 0, 1.0)};
  FrameResult result;
  for (int i = 1; i <= 40; ++i) {  // Errors 0.1, 0.2, ... 4.0 px.
    result.markers = {{"a", Found(0.1 * i, 0)}};
    scorer.add(truth, result);
  }
  const TruthScore score = scorer.score();
  EXPECT_NEAR(*score.centroid_p95_px, 3.8, 1e-9);  // The 38th of 40.
  EXPECT_EQ(score.wrong_finds, 10);                 // 3.1 .. 4.0 px.
}

TEST(TruthScorer, NothingFoundLeavesTheErrorsAbsent) {
  TruthScorer scorer(1);
  SceneTruth truth;
  truth.markers = {Truth(1, 1, 1.0)};
  FrameResult result;
  result.markers = {{"a", Observation{}}};
  scorer.add(truth, result);
  EXPECT_FALSE(scorer.score().centroid_rms_px);
  EXPECT_FALSE(scorer.score().angle_rms_deg);
  EXPECT_EQ(scorer.score().misses, 1);
}

}  // namespace
}  // namespace softsight
