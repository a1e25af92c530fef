// The offset between two cameras' videos against exact truth: the two-view renderer's frames,
// the second view's video started a known number of frames before or after the first's.
#include "softsight/io/frame_offset.h"

#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "softsight/sim/stereo_scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using ::testing::Optional;

constexpr int kFrames = 50;   // Each video's length.
constexpr int kMaxShift = 7;  // The scene is rendered this many frames longer.

// A bend that starts, stops and changes speed: segments of 2-7 frames at one speed each
// (fixed seed), kept within 5..115 deg.
std::vector<double> JerkyBend(int frames) {
  cv::RNG rng(27);
  const double speeds[] = {0.0, 0.0, 1.5, 3.0, 6.0, -2.0, -5.0};
  std::vector<double> bend;
  double angle = 40.0, speed = 0.0;
  int left_in_segment = 0;
  for (int i = 0; i < frames; ++i) {
    if (left_in_segment-- <= 0) {
      speed = speeds[rng.uniform(0, 7)];
      left_in_segment = rng.uniform(2, 8);
    }
    angle += speed;
    if (angle < 5 || angle > 115) {
      speed = -speed;
      angle = std::clamp(angle, 5.0, 115.0);
    }
    bend.push_back(angle);
  }
  return bend;
}

// Renders the scene once and returns each view's signal for a video that starts at scene frame
// `left_start` (left) and `right_start` (right): the truth is offset = left_start - right_start
// (left frame i shows scene frame i + left_start = right frame i + left_start - right_start).
struct Videos {
  SyncSignal left, right;
};
Videos RenderVideos(const StereoSceneOptions& options, int left_start, int right_start) {
  const StereoScene scene(MakeStereoRig(), options);
  Videos videos;
  cv::Mat left, right;
  for (int t = 0; t < options.frame_count; ++t) {
    scene.render(t, left, right);
    if (t >= left_start && t < left_start + kFrames) videos.left.add(left);
    if (t >= right_start && t < right_start + kFrames) videos.right.add(right);
  }
  return videos;
}

StereoSceneOptions Scene(std::vector<double> bend) {
  StereoSceneOptions options;
  options.frame_count = static_cast<int>(bend.size());
  options.bend_deg_per_frame = std::move(bend);
  options.supersample = 2;
  return options;
}

struct OffsetCase {
  int offset;
  bool flash;
};
void PrintTo(const OffsetCase& c, std::ostream* os) {
  *os << "offset " << c.offset << (c.flash ? " with a flash" : " from the motion");
}

class FrameOffsetTruthTest : public ::testing::TestWithParam<OffsetCase> {};

TEST_P(FrameOffsetTruthTest, TheOffsetFoundIsExact) {
  const auto [offset, flash] = GetParam();
  StereoSceneOptions options = Scene(JerkyBend(kFrames + kMaxShift));
  if (flash) options.flash_frame = 24;
  const int left_start = offset > 0 ? offset : 0, right_start = offset < 0 ? -offset : 0;
  const Videos videos = RenderVideos(options, left_start, right_start);
  const FrameOffsetEstimate estimate = EstimateFrameOffset(videos.left, videos.right);
  EXPECT_THAT(estimate.offset_frames, Optional(offset)) << estimate.refusal;
  EXPECT_EQ(estimate.method, flash ? FrameOffsetEstimate::Method::kFlash
                                   : FrameOffsetEstimate::Method::kMotion);
  if (flash) {
    EXPECT_THAT(estimate.left_flash_frame, Optional(24 - left_start));
    EXPECT_GT(estimate.left_flash_step, 50.0);
  } else {
    // Clearly peaked: the motion's correlation at the truth far above any other offset's.
    EXPECT_THAT(estimate.peak_correlation, Optional(::testing::Gt(0.9)));
    EXPECT_LT(estimate.second_correlation.value_or(0.0), *estimate.peak_correlation - 0.3);
    std::cout << "[ figures  ] offset " << offset << ": peak r " << *estimate.peak_correlation
              << ", second " << estimate.second_correlation.value_or(-1) << " at "
              << estimate.second_offset.value_or(0) << "\n";
  }
  // Without the flash the motion alone finds the same offset (the flash is not motion).
  if (flash) {
    FrameOffsetOptions no_flash;
    no_flash.flash_min_step = 255;
    EXPECT_THAT(EstimateFrameOffset(videos.left, videos.right, no_flash).offset_frames,
                Optional(offset));
  }
}

INSTANTIATE_TEST_SUITE_P(Offsets, FrameOffsetTruthTest,
                         ::testing::Values(OffsetCase{-7, false}, OffsetCase{0, false},
                                           OffsetCase{5, false}, OffsetCase{-7, true},
                                           OffsetCase{0, true}, OffsetCase{5, true}),
                         [](const auto& info) {
                           return std::string(info.param.offset < 0 ? "minus" : "plus") +
                                  std::to_string(std::abs(info.param.offset)) +
                                  (info.param.flash ? "_flash" : "_motion");
                         });

TEST(FrameOffsetTest, AFlashInAStillSceneGivesTheOffset) {
  StereoSceneOptions options = Scene(std::vector<double>(kFrames + kMaxShift, 60.0));
  options.flash_frame = 30;
  options.flash_length_frames = 0;  // A lamp switched on: a step that stays.
  const Videos videos = RenderVideos(options, 0, 4);
  const FrameOffsetEstimate estimate = EstimateFrameOffset(videos.left, videos.right);
  EXPECT_THAT(estimate.offset_frames, Optional(-4));
  EXPECT_EQ(estimate.method, FrameOffsetEstimate::Method::kFlash);
  EXPECT_THAT(estimate.right_flash_frame, Optional(26));
}

TEST(FrameOffsetTest, ARepeatingMotionIsRefusedNotGuessed) {
  // A bend swinging with a period of 8 frames: offsets 8 apart fit the motion alike.
  std::vector<double> bend;
  for (int i = 0; i < kFrames + kMaxShift; ++i)
    bend.push_back(60.0 + 40.0 * std::sin(2.0 * std::numbers::pi * i / 8.0));
  const Videos videos = RenderVideos(Scene(bend), 5, 0);
  const FrameOffsetEstimate estimate = EstimateFrameOffset(videos.left, videos.right);
  EXPECT_EQ(estimate.offset_frames, std::nullopt);
  EXPECT_THAT(estimate.refusal, HasSubstr("two offsets fit the motion alike"));
  ASSERT_TRUE(estimate.second_correlation.has_value());
  // The two best peaks are whole periods (or half: |speed| repeats twice a swing) apart.
  EXPECT_EQ(std::abs(*estimate.peak_offset - *estimate.second_offset) % 4, 0);
}

TEST(FrameOffsetTest, AStillSceneIsRefused) {
  StereoSceneOptions options = Scene(std::vector<double>(kFrames + kMaxShift, 60.0));
  options.noise_sigma = 1.0;  // Sensor noise: the frames still differ, by chance only.
  const Videos videos = RenderVideos(options, 3, 0);
  const FrameOffsetEstimate estimate = EstimateFrameOffset(videos.left, videos.right);
  EXPECT_EQ(estimate.offset_frames, std::nullopt);
  EXPECT_FALSE(estimate.refusal.empty());
}

TEST(FrameOffsetTest, AnOffsetBeyondTheRangeIsRefused) {
  // The truth (6) outside +-2: nothing inside the range correlates like the same motion, and
  // the flash, 6 frames apart, is not believed either.
  StereoSceneOptions options = Scene(JerkyBend(kFrames + kMaxShift));
  options.flash_frame = 24;
  const Videos videos = RenderVideos(options, 6, 0);
  FrameOffsetOptions narrow;
  narrow.max_offset_frames = 2;
  const FrameOffsetEstimate estimate = EstimateFrameOffset(videos.left, videos.right, narrow);
  EXPECT_EQ(estimate.method, FrameOffsetEstimate::Method::kMotion);
  EXPECT_EQ(estimate.offset_frames, std::nullopt) << *estimate.peak_correlation;
  EXPECT_THAT(estimate.refusal, HasSubstr("not clearly the same motion"));
  EXPECT_EQ(estimate.correlation.size(), 5u);
}

TEST(FrameOffsetTest, OptionsNameTheBadField) {
  std::string error;
  FrameOffsetOptions options;
  EXPECT_TRUE(options.Check(&error));
  options.max_offset_frames = -1;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_THAT(error, HasSubstr("max_offset_frames"));
}

}  // namespace
}  // namespace softsight
