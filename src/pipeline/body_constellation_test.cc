// Where the body puts a marker, against exact arrangements: a plate of dots moved by known
// transforms, two anchors, one anchor, a marker that moves against its body; and the association
// that uses it: a lost dot among identical ones re-acquired only where the others put it, and a
// plate jerked out of every dot's motion gate followed in that frame.
#include "pipeline/body_constellation.h"

#include <cmath>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/marker_tracks.h"

namespace softsight {
namespace {

using DotPositions = std::vector<std::optional<cv::Point2d>>;

// Five dots of a plate (ViSP's mire: one in the middle, four around it), carried by `a`.
DotPositions PlateDots(const cv::Matx23d& a) {
  const cv::Point2d dots[] = {{200, 150}, {120, 170}, {170, 200}, {230, 240}, {110, 260}};
  DotPositions p;
  for (const cv::Point2d& d : dots) {
    p.emplace_back(cv::Point2d(a(0, 0) * d.x + a(0, 1) * d.y + a(0, 2), a(1, 0) * d.x + a(1, 1) * d.y + a(1, 2)));
  }
  return p;
}

const cv::Matx23d kPlateAsIs(1, 0, 0, 0, 1, 0);

TEST(BodyConstellation, APlateMovedByAnAffineTransformPutsItsLostDotExactly) {
  BodyConstellation body(5);
  body.remember(PlateDots(kPlateAsIs), {});
  // Turned, scaled, sheared (tilted in perspective) and moved: dot 3 not seen.
  const cv::Matx23d moved(0.9, -0.3, 40, 0.25, 1.1, -20);
  DotPositions anchors = PlateDots(moved);
  const cv::Point2d truth = *anchors[3];
  anchors[3].reset();
  const std::optional<BodyConstellation::Prediction> p = body.predict(3, anchors, 10);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->anchors, 4);
  EXPECT_FALSE(p->exact);
  EXPECT_LT(cv::norm(p->position_px - truth), 1e-6);
  // The relative motion is not learned yet: a few px per frame of it over 10 frames.
  EXPECT_GT(p->sigma_px, 5.0);
}

TEST(BodyConstellation, TwoAnchorsGiveTheSimilarityOneAnchorTheTranslation) {
  BodyConstellation body(5);
  body.remember(PlateDots(kPlateAsIs), {});
  const double c = std::cos(0.3) * 1.2, s = std::sin(0.3) * 1.2;
  const cv::Matx23d similar(c, -s, 15, s, c, 25);
  DotPositions two = PlateDots(similar);
  const cv::Point2d truth = *two[4];
  for (size_t k : {2u, 3u, 4u}) two[k].reset();  // Dots 0 and 1 only.
  const std::optional<BodyConstellation::Prediction> p = body.predict(4, two, 1);
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->exact);
  EXPECT_LT(cv::norm(p->position_px - truth), 1e-6);

  DotPositions one = PlateDots(cv::Matx23d(1, 0, 7, 0, 1, -3));
  for (size_t k : {1u, 2u, 3u, 4u}) one[k].reset();
  const std::optional<BodyConstellation::Prediction> q = body.predict(4, one, 1);
  ASSERT_TRUE(q);
  EXPECT_TRUE(q->exact);
  EXPECT_NEAR(q->position_px.x, 110 + 7, 1e-9);
  EXPECT_NEAR(q->position_px.y, 260 - 3, 1e-9);
  // It may have turned about the anchor: its uncertainty grows with the distance to it.
  EXPECT_GT(q->sigma_px, 0.1 * cv::norm(cv::Point2d(110, 260) - cv::Point2d(200, 150)));
}

TEST(BodyConstellation, NoAnchorOrNoSnapshotNoPrediction) {
  BodyConstellation body(5);
  EXPECT_FALSE(body.predict(0, PlateDots(kPlateAsIs), 1));  // Never remembered.
  body.remember(PlateDots(kPlateAsIs), {});
  EXPECT_FALSE(body.predict(0, DotPositions(5), 1));     // No anchor.
  body.forget(0);
  EXPECT_FALSE(body.predict(0, PlateDots(kPlateAsIs), 1));
}

TEST(BodyConstellation, AMarkerMovingAgainstItsBodyLearnsAWiderToleranceThanOneThatDoesNot) {
  BodyConstellation body(5);
  DotPositions frame = PlateDots(kPlateAsIs);
  body.remember(frame, {});
  for (int f = 1; f <= 150; ++f) {
    // The plate drifts; dot 4 slides along it 3 px a frame (an actuator's tip bending).
    DotPositions next = PlateDots(cv::Matx23d(1, 0, 0.5 * f, 0, 1, 0.2 * f));
    *next[4] += cv::Point2d(3.0 * f, 0);
    std::vector<std::optional<BodyConstellation::Prediction>> predicted(5);
    for (size_t i = 0; i < 5; ++i) {
      DotPositions anchors = next;
      anchors[i].reset();
      predicted[i] = body.predict(i, anchors, 1);
    }
    body.remember(next, predicted);
  }
  // Once the sliding dot is known to slide, it weighs little in the others' fits: they are seen
  // to keep (nearly) still on the plate.
  EXPECT_NEAR(body.relative_motion_px(4), 3.0, 0.5);
  EXPECT_LT(body.relative_motion_px(3), 0.25 * body.relative_motion_px(4));
}

std::vector<MarkerObservation> DotReports(const DotPositions& at) {
  std::vector<MarkerObservation> markers;
  for (size_t i = 0; i < at.size(); ++i) {
    MarkerObservation m;
    m.name = "d" + std::to_string(i);
    if (at[i]) m.observation.position_px = *at[i];
    markers.push_back(m);
  }
  return markers;
}

MarkerCandidate FittingDot(const cv::Point2d& p) {
  MarkerCandidate c;
  c.position_px = p;
  c.verdict = CandidateVerdict::kFits;
  return c;
}

// Five identical dots (radius `size_px`) on a plate drifting 1 px a frame for `frames` frames.
MarkerTracks DriftingPlateTracks(int frames, double size_px = 6.0) {
  MarkerTracks tracks(std::vector<double>(5, size_px));
  const std::vector<MarkerCandidate> none;
  for (int f = 0; f < frames; ++f) {
    std::vector<MarkerObservation> m = DotReports(PlateDots(cv::Matx23d(1, 0, f, 0, 1, 0)));
    tracks.associate(m, std::vector<const std::vector<MarkerCandidate>*>(5, &none));
    tracks.commit(m);
  }
  return tracks;
}

TEST(BodyArrangement, ALostDotAmongIdenticalOnesIsTakenOnlyWhereTheOthersPutIt) {
  MarkerTracks tracks = DriftingPlateTracks(10);
  const std::vector<MarkerCandidate> none;
  // Dot 3 lost for 40 frames while the plate drifts on: its coasting reach grows wide.
  int f = 10;
  for (; f < 50; ++f) {
    DotPositions p = PlateDots(cv::Matx23d(1, 0, f, 0, 1, 0));
    p[3].reset();
    std::vector<MarkerObservation> m = DotReports(p);
    tracks.associate(m, std::vector<const std::vector<MarkerCandidate>*>(5, &none));
    tracks.commit(m);
  }
  // Its tracker's search of the whole frame sees every dot: it chose dot 2's (its nearest), and
  // lists the others. Dot 2 is believed there; dot 3 is adopted at its own place.
  const DotPositions plate = PlateDots(cv::Matx23d(1, 0, f, 0, 1, 0));
  DotPositions p = plate;
  p[3] = plate[2];
  std::vector<MarkerObservation> m = DotReports(p);
  std::vector<MarkerCandidate> list;
  for (size_t k = 0; k < 5; ++k) list.push_back(FittingDot(*plate[k]));
  list[2].verdict = CandidateVerdict::kChosen;
  std::vector<const std::vector<MarkerCandidate>*> candidates(5, &none);
  candidates[3] = &list;
  const std::vector<MarkerTracks::Decision>& d = tracks.associate(m, candidates);
  ASSERT_EQ(d[3].action, MarkerTracks::Decision::Action::kAdopt);
  EXPECT_EQ(d[3].candidate, 3u);
  EXPECT_TRUE(d[3].vouched_by_body);
  EXPECT_EQ(d[2].action, MarkerTracks::Decision::Action::kKeep);

  // Dot 3's tracker reports a look-alike beside the plate, within its wide coasting reach: not
  // where the others put it, not believed.
  MarkerTracks again = DriftingPlateTracks(10);
  for (int g = 10; g < 50; ++g) {
    DotPositions q = PlateDots(cv::Matx23d(1, 0, g, 0, 1, 0));
    q[3].reset();
    std::vector<MarkerObservation> n = DotReports(q);
    again.associate(n, std::vector<const std::vector<MarkerCandidate>*>(5, &none));
    again.commit(n);
  }
  DotPositions q = plate;
  q[3] = *plate[3] + cv::Point2d(25, 15);
  std::vector<MarkerObservation> n = DotReports(q);
  again.associate(n, std::vector<const std::vector<MarkerCandidate>*>(5, &none));
  EXPECT_FALSE(n[3].observation.found());
  EXPECT_EQ(n[3].observation.status(), MarkerStatus::kImplausible);
}

TEST(BodyArrangement, ADotThrownOutOfItsGateWithThePlateIsBelievedWhereThePlatePutsIt) {
  // Dots of 10 px radius (mire-2's): a hand brings the plate 10 % nearer the camera in one frame,
  // about dot 0. Dots 1-3 move 6-9 px, inside their motion gates; dot 4, farthest from dot 0,
  // 14 px: outside its gate, and where the others' arrangement puts it.
  MarkerTracks tracks = DriftingPlateTracks(20, 10.0);
  const DotPositions before = PlateDots(cv::Matx23d(1, 0, 20, 0, 1, 0));
  const cv::Point2d centre = *before[0];
  DotPositions nearer = before;
  for (auto& p : nearer) p = centre + 1.1 * (*p - centre);
  std::vector<MarkerObservation> m = DotReports(nearer);
  const std::vector<MarkerCandidate> none;
  const std::vector<MarkerTracks::Decision>& d =
      tracks.associate(m, std::vector<const std::vector<MarkerCandidate>*>(5, &none));
  for (size_t i = 0; i < m.size(); ++i) EXPECT_TRUE(m[i].observation.found()) << "dot " << i;
  EXPECT_TRUE(d[4].vouched_by_body);
  EXPECT_FALSE(d[0].vouched_by_body);  // It continued its own track.

  // The same jump of dot 4 alone (the others where they were): a look-alike, not believed.
  MarkerTracks alone = DriftingPlateTracks(20, 10.0);
  DotPositions one = PlateDots(cv::Matx23d(1, 0, 20, 0, 1, 0));
  one[4] = nearer[4];
  std::vector<MarkerObservation> n = DotReports(one);
  alone.associate(n, std::vector<const std::vector<MarkerCandidate>*>(5, &none));
  EXPECT_FALSE(n[4].observation.found());
}

}  // namespace
}  // namespace softsight
