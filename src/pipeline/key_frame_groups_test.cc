#include "pipeline/key_frame_groups.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace softsight {
namespace {

constexpr int kKeyFrameInterval = 12;

// Three markers moving 2 px per frame to the right (with a little jitter, as a tracker's
// positions have), in a video with a key frame every 12th frame. `damage(index, marker)` adds
// the displacement of a damaged picture.
struct Track {
  template <typename Damage>
  std::vector<FrameResult> results(int frames, Damage damage) const {
    std::vector<FrameResult> out;
    for (int i = 0; i < frames; ++i) {
      FrameResult r;
      r.frame_index = i;
      for (int m = 0; m < 3; ++m) {
        MarkerObservation o;
        o.name = "m" + std::to_string(m);
        const double jitter = 0.2 * std::sin(1.7 * i + m);
        o.observation.position_px = cv::Point2d(100 + 2.0 * i + jitter, 100 + 50 * m) + damage(i, m);
        r.markers.push_back(o);
      }
      r.measurement.angle_deg = 150.0;
      out.push_back(r);
    }
    return out;
  }
};

struct Released {
  std::vector<int64_t> order;
  std::vector<FrameResult> results;
};

// Runs `results` through the check; every frame's release is recorded.
Released CheckGroups(const std::vector<FrameResult>& results, bool predicted, KeyFrameGroups& groups,
                     bool ended_damaged = false) {
  Released released;
  const KeyFrameGroups::Release release = [&](const Frame& frame, const FrameResult& result) {
    EXPECT_EQ(frame.index, result.frame_index);
    released.order.push_back(frame.index);
    released.results.push_back(result);
  };
  Frame frame;
  frame.image = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(0));
  for (const FrameResult& result : results) {
    frame.index = result.frame_index;
    frame.key_frame = !predicted || result.frame_index % kKeyFrameInterval == 0;
    groups.add(frame, result, release);
  }
  groups.flush(release, ended_damaged);
  return released;
}

// The tracker did not find `marker` in frames [first, last].
void Hide(std::vector<FrameResult>& results, int marker, int first, int last,
          MarkerStatus why = MarkerStatus::kLost) {
  for (int i = first; i <= last; ++i) {
    results[static_cast<size_t>(i)].markers[static_cast<size_t>(marker)].observation =
        Observation::NotFound(why);
  }
}

void ExpectEveryFrameOnceInOrder(const Released& released, int frames) {
  ASSERT_EQ(static_cast<int>(released.order.size()), frames);
  for (int i = 0; i < frames; ++i) EXPECT_EQ(released.order[i], i);
}

TEST(KeyFrameGroups, AMarkerMovedFromMidGroupToTheKeyFrameIsNotBelievedThere) {
  // Frames 28-35 slid 16 px (one macroblock) for markers 0 and 1; key frame 36 is clean.
  const auto damage = [](int i, int m) {
    return i >= 28 && i < 36 && m < 2 ? cv::Point2d(-16, 0) : cv::Point2d(0, 0);
  };
  KeyFrameGroups groups;
  const Released released = CheckGroups(Track{}.results(60, damage), true, groups);
  ExpectEveryFrameOnceInOrder(released, 60);
  for (int i = 0; i < 60; ++i) {
    const bool damaged = i >= 28 && i < 36;
    for (int m = 0; m < 3; ++m) {
      const Observation& o = released.results[i].markers[m].observation;
      EXPECT_EQ(o.found(), !(damaged && m < 2)) << "frame " << i << " marker " << m;
      if (!o.found()) {
        EXPECT_EQ(o.status(), MarkerStatus::kImplausible);
      }
    }
    EXPECT_EQ(released.results[i].measurement.angle_deg.has_value(), !damaged) << i;
  }
  EXPECT_EQ(groups.demoted(), 2 * 8);
}

TEST(KeyFrameGroups, ADamagedKeyFrameLeavesItsWholeGroupNotBelieved) {
  const auto damage = [](int i, int) {
    return i >= 24 && i < 36 ? cv::Point2d(16, -16) : cv::Point2d(0, 0);
  };
  KeyFrameGroups groups;
  const Released released = CheckGroups(Track{}.results(60, damage), true, groups);
  ExpectEveryFrameOnceInOrder(released, 60);
  for (int i = 0; i < 60; ++i) {
    const bool damaged = i >= 24 && i < 36;
    for (int m = 0; m < 3; ++m) {
      EXPECT_EQ(released.results[i].markers[m].observation.found(), !damaged) << i << " " << m;
    }
  }
  EXPECT_EQ(groups.demoted(), 3 * 12);
}

TEST(KeyFrameGroups, ADamagedKeyFrameThatAlsoStoppedTheMarkerLeavesItsGroupNotBelieved) {
  // Key frame 24 was decoded 16 px off for marker 0, and the frames predicted from it left the
  // marker standing still while it really moved on: the jump at key frame 36 does not undo the
  // one at 24. Marker 0 is also hidden in frame 23, just before the group: the group is tied to
  // the marker's past by frame 22.
  const auto damage = [](int i, int m) {
    return i >= 24 && i < 36 && m == 0 ? cv::Point2d(16 - 2.0 * (i - 24), -16) : cv::Point2d(0, 0);
  };
  std::vector<FrameResult> results = Track{}.results(60, damage);
  Hide(results, 0, 23, 23, MarkerStatus::kCovered);
  KeyFrameGroups groups;
  const Released released = CheckGroups(results, true, groups);
  ExpectEveryFrameOnceInOrder(released, 60);
  for (int i = 0; i < 60; ++i) {
    const bool damaged = i >= 24 && i < 36;
    EXPECT_EQ(released.results[i].markers[0].observation.found(), !damaged && i != 23) << i;
    EXPECT_TRUE(released.results[i].markers[1].observation.found()) << i;
  }
  EXPECT_EQ(groups.demoted(), 12);
}

TEST(KeyFrameGroups, AMarkerFoundInTooFewFramesOfItsGroupToCheckIsNotBelievedThere) {
  // Marker 0 is found in frames 30 and 31 only of the group 24-35 (the tracker refused the rest
  // of the damaged group) and at key frame 36; marker 1, found just before its group 36-47, is
  // found in frames 42 and 43 only, and not at key frame 48. Two positions tell nothing of the
  // group's motion: neither is believed.
  std::vector<FrameResult> results = Track{}.results(60, [](int i, int m) {
    return (m == 0 && i >= 24 && i < 36) || (m == 1 && i >= 36 && i < 48) ? cv::Point2d(16, 16)
                                                                           : cv::Point2d(0, 0);
  });
  Hide(results, 0, 20, 29, MarkerStatus::kImplausible);
  Hide(results, 0, 32, 35, MarkerStatus::kImplausible);
  Hide(results, 1, 36, 41, MarkerStatus::kLost);
  Hide(results, 1, 44, 48, MarkerStatus::kLost);
  KeyFrameGroups groups;
  const Released released = CheckGroups(results, true, groups);
  ExpectEveryFrameOnceInOrder(released, 60);
  for (const int i : {30, 31}) EXPECT_FALSE(released.results[i].markers[0].observation.found()) << i;
  for (const int i : {42, 43}) EXPECT_FALSE(released.results[i].markers[1].observation.found()) << i;
  EXPECT_TRUE(released.results[36].markers[0].observation.found()) << "the key frame is its own";
  EXPECT_EQ(groups.demoted(), 4);
}

TEST(KeyFrameGroups, ADamagedKeyFrameWhoseGroupMovesErraticallyIsNotBelieved) {
  // Marker 0's track through a bit-flipped MPEG-4 clip: it moves down 3.7 px per frame; key frame
  // 84 was decoded with damage, and in its group the tracker found the marker only in frames 84,
  // 85, 89 and 91, 16-35 px off and drifting left; key frame 96 shows it on its way again. With
  // so few frames, the two jumps would swamp the group's own scatter if it were measured with
  // them.
  std::vector<FrameResult> results = Track{}.results(108, [](int, int) { return cv::Point2d(); });
  const auto place = [&](int i, cv::Point2d p) {
    results[static_cast<size_t>(i)].markers[0].observation.position_px = p;
  };
  for (int i = 0; i < 108; ++i) {
    place(i, cv::Point2d(415.2, 294.0) + (i - 82) * cv::Point2d(-0.764, 3.729));
  }
  place(84, {397.7, 309.6});
  place(85, {395.8, 311.1});
  place(89, {385.9, 311.2});
  place(91, {382.0, 310.9});
  for (const int i : {83, 86, 87, 88, 90, 92, 93, 94, 95}) Hide(results, 0, i, i, MarkerStatus::kLost);
  KeyFrameGroups groups;
  const Released released = CheckGroups(results, true, groups);
  ExpectEveryFrameOnceInOrder(released, 108);
  for (const int i : {84, 85, 89, 91}) {
    EXPECT_FALSE(released.results[i].markers[0].observation.found()) << i;
  }
  EXPECT_TRUE(released.results[82].markers[0].observation.found());
  EXPECT_TRUE(released.results[96].markers[0].observation.found());
  EXPECT_EQ(groups.demoted(), 4);
}

TEST(KeyFrameGroups, RealMotionThatChangesAtAKeyFrameIsBelieved) {
  // A puck bouncing at key frame 36 (2 px per frame to the right, then 6 to the left), and a
  // camera bumped by 16 px at frame 30 that stays bumped: nothing jumps back.
  const auto motion = [](int i, int m) {
    if (m == 0) return i >= 36 ? cv::Point2d(-8.0 * (i - 35), 0) : cv::Point2d(0, 0);
    return i >= 30 ? cv::Point2d(16, 0) : cv::Point2d(0, 0);
  };
  KeyFrameGroups groups;
  const Released released = CheckGroups(Track{}.results(60, motion), true, groups);
  ExpectEveryFrameOnceInOrder(released, 60);
  for (const FrameResult& r : released.results) {
    for (const MarkerObservation& m : r.markers) EXPECT_TRUE(m.observation.found()) << r.frame_index;
  }
  EXPECT_EQ(groups.demoted(), 0);
}

TEST(KeyFrameGroups, FastOscillationIsBelieved) {
  // Markers swinging 40 px back and forth, one cycle in 15, 24 and 40 frames (a group of 12
  // frames sees most of a cycle): their speed changes within every group and at every key frame,
  // and marker 0 is hidden now and then.
  std::vector<FrameResult> results = Track{}.results(120, [](int i, int m) {
    const double period = m == 0 ? 15.0 : m == 1 ? 24.0 : 40.0;
    return cv::Point2d(-2.0 * i + 40.0 * std::sin(2 * M_PI * i / period),
                       25.0 * std::cos(2 * M_PI * i / period));
  });
  for (const int i : {11, 23, 30, 31, 47, 59, 60, 71, 83, 95}) Hide(results, 0, i, i);
  KeyFrameGroups groups;
  const Released released = CheckGroups(results, true, groups);
  ExpectEveryFrameOnceInOrder(released, 120);
  EXPECT_EQ(groups.demoted(), 0);
}

TEST(KeyFrameGroups, AJumpMidGroupIsNotBelievedWhenTheKeyFrameDoesNotShowTheMarker) {
  // Marker 0 slid 16 px from frame 28; at key frame 36 its tracker refused the jump back (or
  // lost it): nothing after frame 28 vouches for it. Marker 1 is hidden at the key frame too
  // but did not jump: believed. Marker 2 is seen at the key frame, where it did not move.
  const auto damage = [](int i, int m) {
    return i >= 28 && i < 36 && m == 0 ? cv::Point2d(-16, 0) : cv::Point2d(0, 0);
  };
  std::vector<FrameResult> results = Track{}.results(60, damage);
  Hide(results, 0, 36, 37, MarkerStatus::kImplausible);
  Hide(results, 1, 36, 36);
  KeyFrameGroups groups;
  const Released released = CheckGroups(results, true, groups);
  ExpectEveryFrameOnceInOrder(released, 60);
  for (int i = 0; i < 60; ++i) {
    const bool hidden0 = i == 36 || i == 37;
    EXPECT_EQ(released.results[i].markers[0].observation.found(), i < 28 || (i > 37))
        << "frame " << i << (hidden0 ? " (hidden)" : "");
    EXPECT_EQ(released.results[i].markers[1].observation.found(), i != 36) << "frame " << i;
    EXPECT_TRUE(released.results[i].markers[2].observation.found()) << "frame " << i;
  }
  EXPECT_EQ(groups.demoted(), 8);
}

TEST(KeyFrameGroups, AMarkerNeitherJustBeforeItsGroupNorAfterItIsNotBelievedInIt) {
  // Marker 2 is not in frame 23 (before the group 24-35) nor at key frame 36: its positions in
  // the group, however steady, are tied to nothing (a key frame the damage moved it in).
  std::vector<FrameResult> results = Track{}.results(60, [](int, int) { return cv::Point2d(); });
  Hide(results, 2, 20, 23);
  Hide(results, 2, 36, 40);
  KeyFrameGroups groups;
  const Released released = CheckGroups(results, true, groups);
  for (int i = 24; i < 36; ++i) {
    EXPECT_FALSE(released.results[i].markers[2].observation.found()) << "frame " << i;
    EXPECT_TRUE(released.results[i].markers[1].observation.found()) << "frame " << i;
  }
  EXPECT_EQ(groups.demoted(), 12);
}

TEST(KeyFrameGroups, TheLastGroupOfARunEndedByDamageDoesNotBelieveAJump) {
  // Frames 48-59 are the last group: no key frame follows. Marker 0 jumps 16 px at frame 52.
  const auto jump = [](int i, int m) {
    return i >= 52 && m == 0 ? cv::Point2d(16, 0) : cv::Point2d(0, 0);
  };
  for (const bool damaged : {false, true}) {
    KeyFrameGroups groups;
    const Released released = CheckGroups(Track{}.results(60, jump), true, groups, damaged);
    ExpectEveryFrameOnceInOrder(released, 60);
    for (int i = 48; i < 60; ++i) {
      EXPECT_EQ(released.results[i].markers[0].observation.found(), !damaged || i < 52)
          << "frame " << i << (damaged ? ", run ended by damage" : ", clean end");
      EXPECT_TRUE(released.results[i].markers[1].observation.found()) << "frame " << i;
    }
    EXPECT_EQ(groups.demoted(), damaged ? 8 : 0);
  }
}

TEST(KeyFrameGroups, FramesThatAreAllKeyFramesPassStraightThrough) {
  // A camera's or an intra-only video's frames: each is handed on within its own add().
  const auto damage = [](int i, int) {
    return i >= 24 && i < 36 ? cv::Point2d(16, 0) : cv::Point2d(0, 0);
  };
  const std::vector<FrameResult> results = Track{}.results(40, damage);
  KeyFrameGroups groups;
  Frame frame;
  frame.image = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(0));
  int released = 0;
  for (const FrameResult& result : results) {
    frame.index = result.frame_index;
    groups.add(frame, result, [&](const Frame& f, const FrameResult& r) {
      EXPECT_EQ(f.index, frame.index) << "handed on later than its own add()";
      EXPECT_EQ(r.markers[0].observation.position_px, result.markers[0].observation.position_px);
      ++released;
    });
  }
  EXPECT_EQ(released, 40);
  EXPECT_EQ(groups.demoted(), 0);
  EXPECT_EQ(groups.unchecked_frames(), 0);
}

TEST(KeyFrameGroups, AGroupOverTheMemoryLimitGoesOnUncheckedInOrder) {
  const auto none = [](int, int) { return cv::Point2d(0, 0); };
  KeyFrameGroups groups(/*max_held_bytes=*/4 * 4 * 3 * 5);  // Five of the test's frames.
  const Released released = CheckGroups(Track{}.results(30, none), true, groups);
  ExpectEveryFrameOnceInOrder(released, 30);
  EXPECT_GT(groups.unchecked_frames(), 0);
}

TEST(KeyFrameGroups, WithoutImagesTheSameDamageIsFoundAndFramesGoOnWithoutPixels) {
  // The first test's damage, held once with images and once without (what a CSV-only run does):
  // the same results, in the same order; the frames handed on carry no image.
  const auto damage = [](int i, int m) {
    return i >= 28 && i < 36 && m < 2 ? cv::Point2d(-16, 0) : cv::Point2d(0, 0);
  };
  const std::vector<FrameResult> results = Track{}.results(48, damage);
  KeyFrameGroups with_images;
  KeyFrameGroups without(size_t{512} << 20, /*hold_images=*/false);
  const Released a = CheckGroups(results, true, with_images);
  int empty_images = 0, frames = 0;
  Released b;
  const KeyFrameGroups::Release release = [&](const Frame& frame, const FrameResult& result) {
    ++frames;
    // Frames before the first predicted one pass straight through, as they came.
    empty_images += frame.image.empty() ? 1 : 0;
    b.order.push_back(frame.index);
    b.results.push_back(result);
  };
  Frame frame;
  frame.image = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(0));
  for (const FrameResult& result : results) {
    frame.index = result.frame_index;
    frame.key_frame = result.frame_index % kKeyFrameInterval == 0;
    without.add(frame, result, release);
  }
  without.flush(release);
  ExpectEveryFrameOnceInOrder(b, 48);
  EXPECT_EQ(empty_images, 47);  // All but frame 0, the key frame before any predicted one.
  EXPECT_EQ(without.demoted(), with_images.demoted());
  EXPECT_GT(without.demoted(), 0);
  for (size_t i = 0; i < a.results.size(); ++i) {
    for (size_t m = 0; m < 3; ++m) {
      EXPECT_EQ(a.results[i].markers[m].observation.status(),
                b.results[i].markers[m].observation.status())
          << "frame " << i << " marker " << m;
    }
  }
}

TEST(KeyFrameGroups, AGroupOverTheFrameLimitGoesOnUncheckedInOrder) {
  const auto none = [](int, int) { return cv::Point2d(0, 0); };
  KeyFrameGroups groups(size_t{512} << 20, /*hold_images=*/false, /*max_held_frames=*/5);
  const Released released = CheckGroups(Track{}.results(30, none), true, groups);
  ExpectEveryFrameOnceInOrder(released, 30);
  EXPECT_GT(groups.unchecked_frames(), 0);
}

// Pairs: the left view clean (a key frame every 12th), the right one's frames 22-29 slid for
// markers 0 and 1 up to its key frame 30 (its key frames every 10th), each pair's row as StereoSession makes it (every
// marker found in 3D, the shape measured). What is handed on, in order.
struct ReleasedPairs {
  std::vector<int64_t> order;
  std::vector<StereoFrameResult> results;
};

ReleasedPairs CheckPairs(int frames, PairKeyFrameGroups& groups) {
  const auto none = [](int, int) { return cv::Point2d(0, 0); };
  const auto slid = [](int i, int m) {
    return i >= 22 && i < 30 && m < 2 ? cv::Point2d(-16, 0) : cv::Point2d(0, 0);
  };
  const std::vector<FrameResult> left = Track{}.results(frames, none);
  const std::vector<FrameResult> right = Track{}.results(frames, slid);
  ReleasedPairs released;
  const PairKeyFrameGroups::Release release = [&](const FramePair& pair,
                                                  const StereoFrameResult& result) {
    EXPECT_EQ(pair.left.index, result.frame_index);
    // The views' results as their checks handed them on, for a sink that draws each view.
    EXPECT_EQ(result.left_view->frame_index, result.frame_index);
    EXPECT_EQ(result.right_view->frame_index, result.frame_index);
    released.order.push_back(pair.left.index);
    released.results.push_back(result);
  };
  FramePair pair;
  pair.left.image = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(0));
  pair.right.image = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(0));
  StereoFrameResult result;
  for (int i = 0; i < frames; ++i) {
    pair.left.index = pair.right.index = i;
    pair.left.key_frame = i % 12 == 0;
    pair.right.key_frame = i % 10 == 0;
    result.frame_index = result.right_frame_index = i;
    result.markers.resize(3);
    for (size_t m = 0; m < 3; ++m) {
      StereoMarkerResult& marker = result.markers[m];
      marker.name = left[i].markers[m].name;
      marker.left = left[i].markers[m].observation;
      marker.right = right[i].markers[m].observation;
      marker.point.status = StereoStatus::kFound;
      marker.point.position_mm = cv::Point3d(0, 0, 300);
      marker.status = "found";
    }
    result.shape.angle_deg = 150.0;
    result.left_angle_deg = result.right_angle_deg = 150.0;
    result.left_view = &left[i];
    result.right_view = &right[i];
    groups.add(pair, result, release);
  }
  groups.flush(release);
  return released;
}

TEST(PairKeyFrameGroups, AMarkerOneViewsDecoderMovedIsNotFoundIn3DInThosePairs) {
  PairKeyFrameGroups groups;
  const ReleasedPairs released = CheckPairs(60, groups);
  ASSERT_EQ(released.order.size(), 60u);
  for (int i = 0; i < 60; ++i) {
    EXPECT_EQ(released.order[i], i) << "every pair once, in order";
    const StereoFrameResult& row = released.results[i];
    const bool damaged = i >= 22 && i < 30;
    for (int m = 0; m < 3; ++m) {
      const StereoMarkerResult& marker = row.markers[m];
      const bool refused = damaged && m < 2;
      EXPECT_EQ(marker.point.found(), !refused) << "frame " << i << " marker " << m;
      EXPECT_EQ(marker.status, refused ? "right_implausible" : "found") << i << " " << m;
      EXPECT_TRUE(marker.left.found());
    }
    EXPECT_EQ(row.shape.angle_deg.has_value(), !damaged) << i;
    EXPECT_EQ(row.right_angle_deg.has_value(), !damaged) << i;
    EXPECT_TRUE(row.left_angle_deg.has_value()) << i;
  }
  EXPECT_EQ(groups.demoted(), 2 * 8);
}

TEST(PairKeyFrameGroups, PairsOverTheMemoryLimitGoOnUncheckedInOrder) {
  PairKeyFrameGroups groups(/*max_held_bytes=*/2 * 4 * 4 * 3 * 5);  // Five of the test's pairs.
  const ReleasedPairs released = CheckPairs(40, groups);
  ASSERT_EQ(released.order.size(), 40u);
  for (int i = 0; i < 40; ++i) EXPECT_EQ(released.order[i], i);
}

}  // namespace
}  // namespace softsight
