// The association's parts against exact answers: the minimum-cost assignment (against brute
// force), the motion model (a constant-velocity and an accelerating path), and the track
// manager's decisions (a look-alike another track explains, a jump, a candidate the tracker did
// not choose, a repeated frame).
#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/assignment.h"
#include "pipeline/marker_tracks.h"
#include "pipeline/motion_model.h"

namespace softsight {
namespace {

double BruteForceCost(const std::vector<std::vector<double>>& cost,
                      const std::vector<double>& unassigned) {
  // Every way of giving each marker a distinct candidate or none.
  const size_t markers = cost.size(), candidates = cost.empty() ? 0 : cost[0].size();
  double best = std::numeric_limits<double>::infinity();
  std::vector<int> choice(markers, -1);
  const auto recurse = [&](auto&& self, size_t m, std::vector<bool>& used, double sum) -> void {
    if (m == markers) {
      best = std::min(best, sum);
      return;
    }
    self(self, m + 1, used, sum + unassigned[m]);
    for (size_t c = 0; c < candidates; ++c) {
      if (used[c] || !std::isfinite(cost[m][c])) continue;
      used[c] = true;
      self(self, m + 1, used, sum + cost[m][c]);
      used[c] = false;
    }
  };
  std::vector<bool> used(candidates, false);
  recurse(recurse, 0, used, 0.0);
  return best;
}

TEST(AssignMinimumCost, EqualsBruteForceOnRandomMatricesWithForbiddenPairs) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> value(0.0, 2.0);
  std::uniform_int_distribution<int> size(0, 5);
  for (int trial = 0; trial < 300; ++trial) {
    const size_t markers = static_cast<size_t>(size(rng)), candidates = static_cast<size_t>(size(rng));
    std::vector<std::vector<double>> cost(markers, std::vector<double>(candidates));
    std::vector<double> unassigned(markers);
    for (size_t m = 0; m < markers; ++m) {
      unassigned[m] = value(rng);
      for (size_t c = 0; c < candidates; ++c) {
        cost[m][c] = rng() % 3 == 0 ? kForbidden : value(rng);
      }
    }
    const std::vector<int> assigned = AssignMinimumCost(cost, unassigned);
    ASSERT_EQ(assigned.size(), markers);
    double sum = 0.0;
    std::vector<int> taken;
    for (size_t m = 0; m < markers; ++m) {
      if (assigned[m] < 0) {
        sum += unassigned[m];
        continue;
      }
      ASSERT_TRUE(std::isfinite(cost[m][static_cast<size_t>(assigned[m])])) << "trial " << trial;
      sum += cost[m][static_cast<size_t>(assigned[m])];
      taken.push_back(assigned[m]);
    }
    std::sort(taken.begin(), taken.end());
    EXPECT_TRUE(std::adjacent_find(taken.begin(), taken.end()) == taken.end()) << "trial " << trial;
    EXPECT_NEAR(sum, BruteForceCost(cost, unassigned), 1e-9) << "trial " << trial;
  }
}

TEST(AssignMinimumCost, TwoMarkersWantingOneCandidateGiveItToTheCheaper) {
  // Marker 0 near candidate 0 (cost 0.1), marker 1 farther (0.6) and with nothing else.
  const std::vector<int> a = AssignMinimumCost({{0.1}, {0.6}}, {1.5, 1.5});
  EXPECT_EQ(a, (std::vector<int>{0, -1}));
}

TEST(MotionModel, LearnsAConstantVelocityAndPredictsItExactly) {
  MotionModel model;
  model.start({100, 50});
  for (int f = 1; f <= 20; ++f) {
    model.predict();
    model.update({100 + 30.0 * f, 50 - 4.0 * f});
  }
  model.predict();
  EXPECT_NEAR(model.position().x, 100 + 30.0 * 21, 0.05);
  EXPECT_NEAR(model.position().y, 50 - 4.0 * 21, 0.05);
  // A report a marker's width off the straight path is far outside a steady marker's gate.
  EXPECT_LT(model.distance2({730, -34}), 1.0);
  EXPECT_GT(model.distance2({745, -34}), 16.0);
}

TEST(MotionModel, AnAcceleratingMarkerStaysInsideItsGate) {
  MotionModel model;
  model.start({60, 150});
  double worst = 0.0;
  for (int f = 1; f <= 15; ++f) {
    model.predict();
    const double x = f <= 10 ? 60 + 3.0 * f * f : 360 + 60.0 * (f - 10);
    if (f >= 2) worst = std::max(worst, model.distance2({x, 150}));
    model.update({x, 150});
  }
  EXPECT_LT(worst, 16.0);
}

TEST(MotionModel, ItsUncertaintyGrowsWhileTheMarkerIsNotSeen) {
  MotionModel model;
  model.start({0, 0});
  for (int f = 1; f <= 10; ++f) {
    model.predict();
    model.update({5.0 * f, 0});
  }
  double before = 0.0;
  for (int f = 0; f < 10; ++f) {
    model.predict();
    EXPECT_GT(model.sigma_px(), before);
    before = model.sigma_px();
  }
}

std::vector<MarkerObservation> Reports(const std::vector<std::optional<cv::Point2d>>& at) {
  std::vector<MarkerObservation> markers;
  for (size_t i = 0; i < at.size(); ++i) {
    MarkerObservation m;
    m.name = std::string(1, static_cast<char>('a' + i));
    if (at[i]) m.observation.position_px = *at[i];
    markers.push_back(m);
  }
  return markers;
}

MarkerCandidate Candidate(const cv::Point2d& p, CandidateVerdict verdict) {
  MarkerCandidate c;
  c.position_px = p;
  c.verdict = verdict;
  return c;
}

// Two markers moving right at 10 px a frame, 100 px apart, for `frames` frames.
MarkerTracks TwoMovingTracks(int frames) {
  MarkerTracks tracks({6.0, 6.0});
  for (int f = 0; f < frames; ++f) {
    std::vector<MarkerObservation> m = Reports({cv::Point2d(10.0 * f, 0), cv::Point2d(100 + 10.0 * f, 0)});
    const std::vector<MarkerCandidate> a = {Candidate(*m[0].observation.position_px, CandidateVerdict::kChosen)};
    const std::vector<MarkerCandidate> b = {Candidate(*m[1].observation.position_px, CandidateVerdict::kChosen)};
    tracks.associate(m, {&a, &b});
    tracks.commit(m);
  }
  return tracks;
}

TEST(MarkerTracks, AReportOnAnotherMarkersPredictedPlaceIsNotBelieved) {
  MarkerTracks tracks = TwoMovingTracks(10);
  // Frame 10: marker 0's tracker lost its marker and re-acquired on marker 1's twin.
  std::vector<MarkerObservation> m = Reports({cv::Point2d(200, 0), cv::Point2d(200, 0)});
  const std::vector<MarkerCandidate> list = {Candidate({200, 0}, CandidateVerdict::kChosen)};
  const auto& d = tracks.associate(m, {&list, &list});
  EXPECT_EQ(d[0].action, MarkerTracks::Decision::Action::kReject);
  EXPECT_FALSE(m[0].observation.found());
  EXPECT_EQ(m[0].observation.status(), MarkerStatus::kImplausible);
  EXPECT_EQ(d[1].action, MarkerTracks::Decision::Action::kKeep);
  EXPECT_TRUE(m[1].observation.found());
}

TEST(MarkerTracks, AMarkerBackFromBehindACoverIsNotClaimedByAnotherCoastingThere) {
  // Both markers go behind a finger for 9 frames; marker 1 comes out where it was last seen
  // (the actuator bent back), its own tracker recognising it. Marker 0, still hidden, has coasted
  // onto that place with a gate grown wide, but its tracker did not list it: it is marker 1's.
  MarkerTracks tracks = TwoMovingTracks(10);
  const std::vector<MarkerCandidate> none;
  for (int f = 0; f < 9; ++f) {
    std::vector<MarkerObservation> hidden = Reports({std::nullopt, std::nullopt});
    tracks.associate(hidden, {&none, &none});
    tracks.commit(hidden);
  }
  // (Not exactly there: that would be a repeated frame.)
  std::vector<MarkerObservation> m = Reports({std::nullopt, cv::Point2d(191.5, 0.8)});
  const std::vector<MarkerCandidate> b = {Candidate({191.5, 0.8}, CandidateVerdict::kChosen)};
  const auto& d = tracks.associate(m, {&none, &b});
  EXPECT_EQ(d[1].action, MarkerTracks::Decision::Action::kKeep);
  EXPECT_TRUE(m[1].observation.found());
  EXPECT_FALSE(m[0].observation.found());
}

TEST(MarkerTracks, ACandidateTheTrackerDidNotChooseIsAdoptedWhereTheMotionSaysTheMarkerIs) {
  MarkerTracks tracks = TwoMovingTracks(10);
  // Marker 0's tracker chose the twin at marker 1's place; its own marker was a candidate too.
  std::vector<MarkerObservation> m = Reports({cv::Point2d(200, 0), cv::Point2d(200, 0)});
  const std::vector<MarkerCandidate> a = {Candidate({100, 0}, CandidateVerdict::kFits),
                                          Candidate({200, 0}, CandidateVerdict::kChosen)};
  const std::vector<MarkerCandidate> b = {Candidate({200, 0}, CandidateVerdict::kChosen)};
  const auto& d = tracks.associate(m, {&a, &b});
  ASSERT_EQ(d[0].action, MarkerTracks::Decision::Action::kAdopt);
  EXPECT_EQ(d[0].candidate, 0u);
  EXPECT_EQ(d[1].action, MarkerTracks::Decision::Action::kKeep);
}

TEST(MarkerTracks, AJumpNoMotionExplainsIsNotBelievedButAMarkerBackWithinItsReachIs) {
  MarkerTracks tracks({6.0});
  const std::vector<MarkerCandidate> none;
  for (int f = 0; f < 10; ++f) {
    std::vector<MarkerObservation> m = Reports({cv::Point2d(100 + 5.0 * f, 100)});
    tracks.associate(m, {&none});
    tracks.commit(m);
  }
  // 200 px away in one frame: a look-alike.
  std::vector<MarkerObservation> jump = Reports({cv::Point2d(350, 100)});
  EXPECT_EQ(tracks.associate(jump, {&none})[0].action, MarkerTracks::Decision::Action::kReject);
  tracks.commit(jump);
  // Lost for two frames; back where its motion took it.
  std::vector<MarkerObservation> lost = Reports({std::nullopt});
  tracks.associate(lost, {&none});
  tracks.commit(lost);
  std::vector<MarkerObservation> back = Reports({cv::Point2d(160, 100)});
  EXPECT_EQ(tracks.associate(back, {&none})[0].action, MarkerTracks::Decision::Action::kKeep);
}

// One state per marker: tentative on its track's first report, confirmed from the second,
// coasting while unseen (a skipped frame too) for up to kCoastFrames, then lost; forgotten (a
// seek, a re-selection) it is lost at once.
TEST(MarkerTracks, EachMarkerHasOneTrackStateThatFollowsItsReports) {
  MarkerTracks tracks({6.0});
  const std::vector<MarkerCandidate> none;
  const auto frame = [&](std::optional<cv::Point2d> at) {
    std::vector<MarkerObservation> m = Reports({at});
    tracks.associate(m, {&none});
    tracks.commit(m);
    return tracks.state(0);
  };
  EXPECT_EQ(tracks.state(0), TrackState::kLost);  // Never seen.
  EXPECT_EQ(frame(cv::Point2d(100, 100)), TrackState::kTentative);
  EXPECT_EQ(frame(cv::Point2d(104, 100)), TrackState::kConfirmed);
  EXPECT_EQ(frame(cv::Point2d(108, 100)), TrackState::kConfirmed);
  tracks.skip();  // A frame nothing was believed in (it changed as a whole).
  EXPECT_EQ(tracks.state(0), TrackState::kCoasting);
  EXPECT_EQ(frame(cv::Point2d(116, 100)), TrackState::kConfirmed);  // Where its motion took it.
  for (int f = 1; f <= kCoastFrames; ++f) {
    ASSERT_EQ(frame(std::nullopt), TrackState::kCoasting) << f << " frames unseen";
  }
  EXPECT_EQ(frame(std::nullopt), TrackState::kLost);
  EXPECT_EQ(TrackStateName(TrackState::kCoasting), std::string("coasting"));
  tracks.forget(0);
  EXPECT_EQ(tracks.state(0), TrackState::kLost);
}

TEST(MarkerTracks, ARepeatedFrameIsBelievedAndTheStepAfterItIsExpected) {
  MarkerTracks tracks({4.0});
  const std::vector<MarkerCandidate> none;
  double x = 0;
  for (int f = 0; f < 10; ++f, x += 16) {
    std::vector<MarkerObservation> m = Reports({cv::Point2d(x, 0)});
    tracks.associate(m, {&none});
    tracks.commit(m);
  }
  // The footage repeats the last frame: the marker exactly where it was.
  std::vector<MarkerObservation> repeat = Reports({cv::Point2d(x - 16, 0)});
  EXPECT_EQ(tracks.associate(repeat, {&none})[0].action, MarkerTracks::Decision::Action::kKeep);
  tracks.commit(repeat);
  // Then two frames' worth at once.
  std::vector<MarkerObservation> next = Reports({cv::Point2d(x + 16, 0)});
  EXPECT_EQ(tracks.associate(next, {&none})[0].action, MarkerTracks::Decision::Action::kKeep);
}


// The checks after association ask the one motion model how well a report continues its track:
// 0 at the prediction, growing with its distance from it, and no support at all for a marker not
// believed in the last frame, a first report, or a report outside the gate.
TEST(MarkerTracks, MotionSupportSaysHowWellAReportContinuesItsTrack) {
  MarkerTracks tracks({6.0});
  const std::vector<MarkerCandidate> none;
  std::vector<MarkerObservation> m = Reports({cv::Point2d(100, 100)});
  tracks.associate(m, {&none});
  EXPECT_FALSE(tracks.MotionSupport(0, {100, 100})) << "no track before its first report";
  tracks.commit(m);
  for (int f = 1; f < 10; ++f) {
    m = Reports({cv::Point2d(100 + 5.0 * f, 100)});
    tracks.associate(m, {&none});
    tracks.commit(m);
  }
  m = Reports({cv::Point2d(150, 100)});
  tracks.associate(m, {&none});
  const std::optional<double> on_course = tracks.MotionSupport(0, {150, 100});
  const std::optional<double> off_course = tracks.MotionSupport(0, {150, 104});
  ASSERT_TRUE(on_course && off_course);
  EXPECT_LT(*on_course, 0.1);
  EXPECT_GT(*off_course, *on_course);
  EXPECT_FALSE(tracks.MotionSupport(0, {350, 100})) << "200 px off: outside the gate";
  tracks.commit(Reports({std::nullopt}));
  m = Reports({cv::Point2d(160, 100)});
  tracks.associate(m, {&none});
  EXPECT_FALSE(tracks.MotionSupport(0, {160, 100})) << "not believed in the last frame";
}

// A thing seen once (a lamp the tracker weighed and no marker took) has no motion yet, only a
// wide reach for its first step (3 sizes plus the fastest marker's speed). A marker whose next
// report continues its own track inside that reach is the marker, not the thing's first step.
// Before, the ball toss's ball (45 px a frame) was refused at the top of its arc this way.
TEST(MarkerTracks, AThingSeenOnceDoesNotTakeAReportThatContinuesAMarkersTrack) {
  MarkerTracks tracks({10.0});
  for (int f = 0; f < 5; ++f) {
    const cv::Point2d at(100 + 40.0 * f, 200);
    std::vector<MarkerObservation> m = Reports({at});
    std::vector<MarkerCandidate> list = {Candidate(at, CandidateVerdict::kChosen)};
    // In frame 4 the tracker also weighed a look-alike far from the ball's course.
    if (f == 4) list.push_back(Candidate({280, 140}, CandidateVerdict::kFits));
    const auto& d = tracks.associate(m, {&list});
    ASSERT_EQ(d[0].action, MarkerTracks::Decision::Action::kKeep) << f;
    tracks.commit(m);
  }
  EXPECT_EQ(tracks.others(), 1u);
  // Frame 5: the ball where its track puts it, 63 px from the look-alike (within its first
  // step's reach of 70 px).
  std::vector<MarkerObservation> m = Reports({cv::Point2d(300, 200)});
  const std::vector<MarkerCandidate> list = {Candidate({300, 200}, CandidateVerdict::kChosen)};
  EXPECT_EQ(tracks.associate(m, {&list})[0].action, MarkerTracks::Decision::Action::kKeep);
  EXPECT_TRUE(m[0].observation.found());
}

// A soft actuator at rest, then a sudden step of pressure: the tip marker, still for 60 frames
// (its learned acceleration at the minimum), leaps 40 px in one frame and goes on. Its gate
// rejects the first reports; three in a row on one smooth motion restart the track, and from
// then on it is followed. Never is a report believed at a place it was not.
TEST(MarkerTracks, AMarkerThatStartsMovingSuddenlyIsReacquiredOnItsOwnSmoothReports) {
  MarkerTracks tracks({8.0});
  const std::vector<MarkerCandidate> none;
  for (int f = 0; f < 60; ++f) {
    std::vector<MarkerObservation> m = Reports({cv::Point2d(220, 80)});
    tracks.associate(m, {&none});
    tracks.commit(m);
  }
  // 40, 30, 22, 16, 12, ... px a frame (a first-order approach to 310, 130).
  cv::Point2d at(220, 80);
  const cv::Point2d end(310, 130);
  int believed_from = -1;
  for (int f = 0; f < 15; ++f) {
    at += 0.45 * (end - at);
    std::vector<MarkerObservation> m = Reports({at});
    tracks.associate(m, {&none});
    if (m[0].observation.found()) {
      EXPECT_LT(cv::norm(*m[0].observation.position_px - at), 1e-9);
      if (believed_from < 0) believed_from = f;
    } else {
      EXPECT_LT(believed_from, 0) << "lost again at frame " << f;
    }
    tracks.commit(m);
  }
  EXPECT_EQ(believed_from, 2) << "restarted on the third report of the run";
}

// The same rule takes nothing another marker explains, and no run far from where the marker was.
TEST(MarkerTracks, NoRunStartsFarAwayOrOnAnotherMarkersPlace) {
  const std::vector<MarkerCandidate> none;
  // One marker at rest; a look-alike appears 200 px away and stays (its own smooth "run").
  {
    MarkerTracks tracks({8.0});
    for (int f = 0; f < 30; ++f) {
      std::vector<MarkerObservation> m = Reports({cv::Point2d(100, 100)});
      tracks.associate(m, {&none});
      tracks.commit(m);
    }
    for (int f = 0; f < 6; ++f) {
      std::vector<MarkerObservation> m = Reports({cv::Point2d(300 + 5.0 * f, 100)});
      EXPECT_EQ(tracks.associate(m, {&none})[0].action, MarkerTracks::Decision::Action::kReject)
          << "frame " << f;
      tracks.commit(m);
    }
  }
  // Two markers 60 px apart: marker 0's tracker jumps onto marker 1 and follows it.
  {
    MarkerTracks tracks({8.0, 8.0});
    for (int f = 0; f < 30; ++f) {
      std::vector<MarkerObservation> m = Reports({cv::Point2d(100, 100), cv::Point2d(160, 100)});
      tracks.associate(m, {&none, &none});
      tracks.commit(m);
    }
    for (int f = 0; f < 6; ++f) {
      const cv::Point2d b(160 + 2.0 * f, 100);
      std::vector<MarkerObservation> m = Reports({b, b});
      const auto& d = tracks.associate(m, {&none, &none});
      EXPECT_NE(d[0].action, MarkerTracks::Decision::Action::kKeep) << "frame " << f;
      EXPECT_FALSE(m[0].observation.found()) << "frame " << f;
      EXPECT_TRUE(m[1].observation.found());
      tracks.commit(m);
    }
  }
}


// Two markers that jump by one translation together (the camera was bumped) are followed there;
// one that jumps alone is not the camera.
TEST(MarkerTracks, MarkersThatJumpTogetherByOneTranslationMoveTheirTracks) {
  MarkerTracks tracks = TwoMovingTracks(10);
  std::vector<MarkerObservation> m = Reports({cv::Point2d(100 + 30, 40), cv::Point2d(200 + 30, 40)});
  ASSERT_TRUE(tracks.AnyJustLost(m));
  const std::optional<cv::Point2d> shift = tracks.CommonShift(m);
  ASSERT_TRUE(shift.has_value());
  EXPECT_NEAR(shift->x, 30.0, 1e-6);
  EXPECT_NEAR(shift->y, 40.0, 1e-6);
  ASSERT_TRUE(tracks.FollowCamera(m, *shift));
  const std::vector<MarkerCandidate> none;
  const auto& d = tracks.associate(m, {&none, &none});
  EXPECT_EQ(d[0].action, MarkerTracks::Decision::Action::kKeep);
  EXPECT_EQ(d[1].action, MarkerTracks::Decision::Action::kKeep);
  EXPECT_TRUE(m[0].observation.found() && m[1].observation.found());

  MarkerTracks alone = TwoMovingTracks(10);
  std::vector<MarkerObservation> one = Reports({cv::Point2d(100 + 30, 40), cv::Point2d(200, 0)});
  EXPECT_FALSE(alone.CommonShift(one).has_value());
  // A shift that explains no report does not move the tracks.
  EXPECT_FALSE(alone.FollowCamera(one, {-300, 0}));
}

// A look-alike in view elsewhere when a marker is lost is another object: however far the
// marker's reach grows while it is lost, it never takes it; a candidate that appears later
// within the reach is taken.
TEST(MarkerTracks, ALostMarkerNeverTakesAnObjectThatWasElsewhereWhenItWasLost) {
  MarkerTracks tracks({5.0});
  const std::vector<MarkerCandidate> none;
  for (int f = 0; f < 10; ++f) {
    std::vector<MarkerObservation> m = Reports({cv::Point2d(100 + 20.0 * f, 100)});
    tracks.associate(m, {&none});
    tracks.commit(m);
  }
  // Lost at (300, 100) moving 20 px a frame; its tracker's report is a twin at (400, 100) that
  // moves 10 px a frame: beyond reach when the marker is lost, within it a few frames later.
  int believed = 0;
  for (int f = 10; f < 30; ++f) {
    std::vector<MarkerObservation> m = Reports({cv::Point2d(400 + 10.0 * (f - 10), 100)});
    const std::vector<MarkerCandidate> list = {
        Candidate(*m[0].observation.position_px, CandidateVerdict::kChosen)};
    tracks.associate(m, {&list});
    believed += m[0].observation.found();
    tracks.commit(m);
  }
  EXPECT_EQ(believed, 0);
  EXPECT_EQ(tracks.others_excluded_for(0), 1u);
}

// Two markers cannot be at one place: candidates closer than kCoincidentMarkerPx are one, which
// one marker takes at most. Two markers' first acquisitions on one place are nobody's: nothing
// tells which marker it is.
TEST(MarkerTracks, TwoMarkersNeverTakeOnePlace) {
  MarkerTracks tracks({2.0, 2.0});
  const std::vector<MarkerCandidate> none;
  std::vector<MarkerObservation> both = Reports({cv::Point2d(50, 50), cv::Point2d(52.5, 50)});
  const auto& first = tracks.associate(both, {&none, &none});
  EXPECT_EQ(first[0].action, MarkerTracks::Decision::Action::kReject);
  EXPECT_EQ(first[1].action, MarkerTracks::Decision::Action::kReject);
  EXPECT_FALSE(both[0].observation.found());
  EXPECT_FALSE(both[1].observation.found());
  tracks.commit(both);
  // Apart, each is believed; then marker 1's tracker jumps onto marker 0 (2 px off): marker 0's
  // track explains that place, marker 1's does not.
  for (int f = 0; f < 5; ++f) {
    std::vector<MarkerObservation> m = Reports({cv::Point2d(50, 50), cv::Point2d(80, 50)});
    tracks.associate(m, {&none, &none});
    EXPECT_TRUE(m[0].observation.found() && m[1].observation.found()) << "frame " << f;
    tracks.commit(m);
  }
  std::vector<MarkerObservation> jumped = Reports({cv::Point2d(50, 50), cv::Point2d(52, 50)});
  const auto& d = tracks.associate(jumped, {&none, &none});
  EXPECT_EQ(d[0].action, MarkerTracks::Decision::Action::kKeep);
  EXPECT_EQ(d[1].action, MarkerTracks::Decision::Action::kReject);
}

// A decoding error turned part of a frame's colours: the red marker looked blue, and the blue
// tracker acquired it there while red itself was not found. Two markers cannot swap places within
// a second: that report is not believed. The place is anyone's again once red is reported where
// its motion allows, a second after it was last believed there, or when the places are forgotten
// (a person re-selected a marker).
TEST(MarkerTracks, AReportWhereAMissingMarkerWasAMomentAgoIsNotBelieved) {
  const std::vector<MarkerCandidate> none;
  const cv::Point2d red_last(220, 300), on_red(221, 300.5);
  // Red moves right at 30 px a frame (last believed at red_last), then is missing `missing`
  // frames; blue has never been found.
  const auto red_gone = [&](int missing) {
    MarkerTracks tracks({6.0, 6.0});
    for (int f = 0; f < 5; ++f) {
      std::vector<MarkerObservation> m = Reports({cv::Point2d(100 + 30.0 * f, 300), std::nullopt});
      tracks.associate(m, {&none, &none});
      tracks.commit(m);
    }
    for (int f = 0; f < missing; ++f) {
      std::vector<MarkerObservation> m = Reports({std::nullopt, std::nullopt});
      tracks.associate(m, {&none, &none});
      tracks.commit(m);
    }
    return tracks;
  };
  const auto blue_believed = [&](MarkerTracks& tracks, std::optional<cv::Point2d> red) {
    std::vector<MarkerObservation> m = Reports({red, on_red});
    tracks.associate(m, {&none, &none});
    return m[1].observation.found();
  };
  {
    MarkerTracks tracks = red_gone(5);
    std::vector<MarkerObservation> m = Reports({std::nullopt, on_red});
    tracks.associate(m, {&none, &none});
    EXPECT_FALSE(m[1].observation.found());
    EXPECT_EQ(m[1].observation.status(), MarkerStatus::kImplausible);
  }
  {
    MarkerTracks tracks = red_gone(5);
    tracks.forget_places();
    EXPECT_TRUE(blue_believed(tracks, std::nullopt));
  }
  {
    MarkerTracks tracks = red_gone(40);
    EXPECT_TRUE(blue_believed(tracks, std::nullopt));
  }
  {
    // Red back on its path, where its motion since allows: it has left that place.
    MarkerTracks tracks = red_gone(1);
    EXPECT_TRUE(blue_believed(tracks, cv::Point2d(280, 300)));
  }
}

// What the decoder made of damaged data is no candidate: a report next to it is not believed,
// and another candidate of the marker's elsewhere, where its motion puts it, may be adopted.
TEST(MarkerTracks, NothingNextToDecodedGarbageIsACandidate) {
  const std::vector<MarkerCandidate> none;
  const auto moving = [&]() {
    MarkerTracks tracks({6.0});
    for (int f = 0; f < 5; ++f) {
      std::vector<MarkerObservation> m = Reports({cv::Point2d(100 + 5.0 * f, 100)});
      tracks.associate(m, {&none});
      tracks.commit(m);
    }
    return tracks;
  };
  const auto garbage = [](const cv::Point2d& p) { return p.x > 120; };
  {
    MarkerTracks tracks = moving();
    std::vector<MarkerObservation> m = Reports({cv::Point2d(125, 100)});
    const std::vector<MarkerCandidate> list = {Candidate({125, 100}, CandidateVerdict::kChosen)};
    EXPECT_EQ(tracks.associate(m, {&list}, garbage)[0].action,
              MarkerTracks::Decision::Action::kReject);
    EXPECT_EQ(m[0].observation.status(), MarkerStatus::kImplausible);
  }
  {
    // The same report in an undamaged frame is the marker's.
    MarkerTracks tracks = moving();
    std::vector<MarkerObservation> m = Reports({cv::Point2d(125, 100)});
    const std::vector<MarkerCandidate> list = {Candidate({125, 100}, CandidateVerdict::kChosen)};
    EXPECT_EQ(tracks.associate(m, {&list})[0].action, MarkerTracks::Decision::Action::kKeep);
  }
  {
    // Damage on the right only: the tracker's choice there is not believed; its other candidate,
    // where the motion puts the marker, is adopted.
    MarkerTracks tracks = moving();
    const auto right = [](const cv::Point2d& p) { return p.x > 150; };
    std::vector<MarkerObservation> m = Reports({cv::Point2d(160, 100)});
    const std::vector<MarkerCandidate> list = {Candidate({160, 100}, CandidateVerdict::kChosen),
                                               Candidate({125, 100}, CandidateVerdict::kFits)};
    const auto& d = tracks.associate(m, {&list}, right);
    ASSERT_EQ(d[0].action, MarkerTracks::Decision::Action::kAdopt);
    EXPECT_EQ(d[0].candidate, 1u);
  }
}

}  // namespace
}  // namespace softsight
