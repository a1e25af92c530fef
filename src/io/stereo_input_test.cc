// Pairing two views' frames: by index with an offset, by time (two stand-in cameras at slightly
// different rates, each frame with its capture time, against a brute-force pairing), and the two
// halves of a side-by-side frame.
#include "softsight/io/stereo_input.h"

#include <chrono>
#include <cmath>
#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "softsight/core/error.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using Clock = std::chrono::steady_clock;

// A stand-in camera: frame k is captured at start_ms + k * 1000 / fps on the machine's clock
// (Frame::captured, from an arbitrary epoch: no real time passes), its own time_s counted from
// its own opening (which differs from camera to camera), its index written into its pixels.
class StandInCamera : public FrameSource {
 public:
  StandInCamera(double fps, double start_ms, int frames, std::string name)
      : fps_(fps), start_ms_(start_ms), frames_(frames), name_(std::move(name)) {}
  bool read(Frame& frame) override {
    if (next_ >= frames_) return false;
    frame.image.create(4, 6, CV_8UC3);
    frame.image.setTo(cv::Scalar::all(next_ % 256));
    const double ms = start_ms_ + next_ * 1000.0 / fps_;
    frame.captured = Clock::time_point(std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double, std::milli>(ms + 1e6)));
    frame.time_s = next_ / fps_ + 3.0;  // Its own clock: useless for pairing with another camera.
    frame.index = next_++;
    return true;
  }
  std::string description() const override { return name_; }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override { return fps_; }
  bool is_live() const override { return true; }

 private:
  double fps_, start_ms_;
  int frames_, next_ = 0;
  std::string name_;
};

// The reference: every left frame's nearest right frame and every right frame's nearest left
// one, all capture times in hand; a pair where both agree and they are within `tolerance_ms`.
std::map<int, int> MutualNearest(double fps_l, double start_l, int n_l, double fps_r,
                                 double start_r, int n_r, double tolerance_ms) {
  const auto t_l = [&](int i) { return start_l + i * 1000.0 / fps_l; };
  const auto t_r = [&](int j) { return start_r + j * 1000.0 / fps_r; };
  std::map<int, int> pairs;
  for (int i = 0; i < n_l; ++i) {
    int best_j = 0;
    for (int j = 1; j < n_r; ++j)
      if (std::abs(t_r(j) - t_l(i)) < std::abs(t_r(best_j) - t_l(i))) best_j = j;
    int best_i = 0;
    for (int k = 1; k < n_l; ++k)
      if (std::abs(t_l(k) - t_r(best_j)) < std::abs(t_l(best_i) - t_r(best_j))) best_i = k;
    if (best_i == i && std::abs(t_r(best_j) - t_l(i)) <= tolerance_ms) pairs[i] = best_j;
  }
  return pairs;
}

TEST(PairByTimeTest, TwoCamerasAtSlightlyDifferentRatesPairAsTheBruteForceDoes) {
  // 30 fps and 28.5 fps, the second started 11 ms later: they drift a frame apart every
  // 0.6 s, so some frames have no partner within half a frame interval (16.7 ms).
  constexpr int kLeft = 150, kRight = 140;
  const std::map<int, int> expected =
      MutualNearest(30.0, 0.0, kLeft, 28.5, 11.0, kRight, 0.5 * 1000.0 / 30.0);
  auto input = PairByTime(std::make_unique<StandInCamera>(30.0, 0.0, kLeft, "camera 0"),
                          std::make_unique<StandInCamera>(28.5, 11.0, kRight, "camera 1"),
                          {TimePairingOptions::Clock::kCaptureTime, 0.0, std::nullopt});
  FramePair pair;
  std::map<int, int> got;
  double worst_dt_ms = 0.0;
  while (input->read(pair)) {
    ASSERT_TRUE(pair.pair_dt_ms.has_value());
    const double expected_dt = (11.0 + pair.right.index * 1000.0 / 28.5) -
                               pair.left.index * 1000.0 / 30.0;
    EXPECT_NEAR(*pair.pair_dt_ms, expected_dt, 1e-6) << "left frame " << pair.left.index;
    EXPECT_EQ(pair.left.image.at<cv::Vec3b>(0, 0)[0], pair.left.index % 256);
    got[static_cast<int>(pair.left.index)] = static_cast<int>(pair.right.index);
    worst_dt_ms = std::max(worst_dt_ms, std::abs(*pair.pair_dt_ms));
  }
  // The right camera runs out first (140 frames at 28.5 fps: 4.9 s against 5.0 s).
  EXPECT_THAT(input->ended_first().value_or(""), HasSubstr("camera 1 ended first"));
  // Every pair the reference makes before the right camera ended, and no other.
  std::map<int, int> expected_read;
  for (const auto& [i, j] : expected)
    if (j < kRight - 1) expected_read[i] = j;
  for (const auto& [i, j] : got) EXPECT_TRUE(expected.count(i) && expected.at(i) == j) << i;
  for (const auto& [i, j] : expected_read) EXPECT_TRUE(got.count(i)) << "left frame " << i;
  EXPECT_LE(worst_dt_ms, 1000.0 / 60.0);
  // Frames left out: those read before the end that are in no pair.
  EXPECT_GT(input->left_unpaired(), 0);
  const int64_t last_left = got.rbegin()->first;
  EXPECT_EQ(input->left_unpaired(), last_left + 1 - static_cast<int64_t>(got.size()));
}

TEST(PairByTimeTest, TheTimeOffsetShiftsTheRightViewsClock) {
  // The same rate; the right camera's clock is 100 ms ahead (3 frames) and 4 ms off.
  auto input = PairByTime(std::make_unique<StandInCamera>(30.0, 0.0, 20, "a"),
                          std::make_unique<StandInCamera>(30.0, 104.0 - 100.0 + 0.0, 20, "b"),
                          {TimePairingOptions::Clock::kCaptureTime, -100.0, std::nullopt});
  FramePair pair;
  ASSERT_TRUE(input->read(pair));
  // Right time 4 + j*33.3 + 100 vs left i*33.3: right frame 0 (104 ms) pairs with left frame 3.
  EXPECT_EQ(pair.left.index, 3);
  EXPECT_EQ(pair.right.index, 0);
  EXPECT_NEAR(*pair.pair_dt_ms, 4.0, 1e-9);
  EXPECT_EQ(input->left_unpaired(), 3);
}

TEST(PairByTimeTest, SourceTimesPairWhenNoCaptureTimes) {
  // Two image sequences' times (index / fps) at 30 and 15 fps: every other left frame pairs.
  auto input = PairByTime(std::make_unique<StandInCamera>(30.0, 0.0, 10, "a"),
                          std::make_unique<StandInCamera>(15.0, 0.0, 5, "b"));
  FramePair pair;
  std::vector<std::pair<int64_t, int64_t>> pairs;
  while (input->read(pair)) pairs.emplace_back(pair.left.index, pair.right.index);
  const std::vector<std::pair<int64_t, int64_t>> expected = {{0, 0}, {2, 1}, {4, 2}, {6, 3},
                                                             {8, 4}};
  EXPECT_EQ(pairs, expected);
  EXPECT_EQ(input->left_unpaired(), 4);  // 1, 3, 5, 7 (9 is after the right view's end).
}

TEST(PairByIndexTest, TheOffsetDropsTheEarlierViewsFirstFrames) {
  auto input = PairByIndex(std::make_unique<StandInCamera>(30.0, 0.0, 10, "a"),
                           std::make_unique<StandInCamera>(30.0, 0.0, 10, "b"), -3);
  FramePair pair;
  ASSERT_TRUE(input->read(pair));
  EXPECT_EQ(pair.left.index, 3);
  EXPECT_EQ(pair.right.index, 0);
  EXPECT_EQ(pair.pair_dt_ms, std::nullopt);
  EXPECT_EQ(input->left_unpaired(), 3);
  try {
    PairByIndex(std::make_unique<StandInCamera>(30.0, 0.0, 10, "a"),
                std::make_unique<StandInCamera>(30.0, 0.0, 4, "b"), 5, "--frame-offset");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--frame-offset 5: b has only 4 frames");
  }
}

// One wide frame per read, its columns numbered in its pixels; it counts the reads whose buffer
// was still shared with somebody (the halves of the last frame) and so could not be reused.
class WideFrames : public FrameSource {
 public:
  explicit WideFrames(int width, int* shared_buffers = nullptr)
      : width_(width), shared_buffers_(shared_buffers) {}
  bool read(Frame& frame) override {
    if (next_ == 2) return false;
    if (shared_buffers_ != nullptr && frame.image.u != nullptr && frame.image.u->refcount > 1)
      ++*shared_buffers_;
    frame.image.create(3, width_, CV_8UC3);
    for (int x = 0; x < width_; ++x)
      frame.image.col(x).setTo(cv::Scalar(x % 256, next_, 7));
    frame.index = next_++;
    frame.time_s = frame.index * 0.5;
    return true;
  }
  std::string description() const override { return "video both.avi"; }
  std::optional<int64_t> frame_count() const override { return 2; }
  std::optional<double> fps() const override { return 2.0; }

 private:
  int width_;
  int* shared_buffers_;
  int next_ = 0;
};

TEST(SideBySideTest, EachHalfIsAViewIntoTheDecodedFrame) {
  int shared_buffers = 0;
  auto input = SplitSideBySide(std::make_unique<WideFrames>(20, &shared_buffers));
  FramePair pair;
  ASSERT_TRUE(input->read(pair));
  ASSERT_TRUE(input->read(pair));
  EXPECT_EQ(pair.left.image.size(), cv::Size(10, 3));
  EXPECT_EQ(pair.right.image.size(), cv::Size(10, 3));
  EXPECT_TRUE(pair.left.image.isSubmatrix());  // Not copied.
  EXPECT_EQ(pair.right.image.ptr<uint8_t>(0), pair.left.image.ptr<uint8_t>(0) + 10 * 3);
  EXPECT_EQ(pair.left.image.at<cv::Vec3b>(1, 9)[0], 9);
  EXPECT_EQ(pair.right.image.at<cv::Vec3b>(1, 0)[0], 10);
  EXPECT_EQ(pair.right.image.at<cv::Vec3b>(2, 3)[1], 1);  // The second frame.
  EXPECT_EQ(pair.left.index, 1);
  EXPECT_EQ(pair.right.time_s, 0.5);
  EXPECT_FALSE(input->read(pair));
  EXPECT_TRUE(pair.left.image.empty());  // The halves do not outlive the end.
  EXPECT_EQ(shared_buffers, 0);  // Each read could reuse the decoded frame's buffer.

  auto odd = SplitSideBySide(std::make_unique<WideFrames>(21));
  try {
    odd->read(pair);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("video both.avi: frame 0 is 21x3"));
  }
}

}  // namespace
}  // namespace softsight
