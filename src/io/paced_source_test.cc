#include "io/paced_source.h"

#include <gtest/gtest.h>

#include <vector>

namespace softsight {
namespace {

using Clock = PacedFrameSource::Clock;

// Ten frames at 10 fps.
class TenFrames : public FrameSource {
 public:
  bool read(Frame& frame) override {
    if (next_ >= 10) return false;
    frame.image.create(2, 2, CV_8UC3);
    frame.index = next_;
    frame.time_s = 0.1 * static_cast<double>(next_);
    ++next_;
    return true;
  }
  std::string description() const override { return "video ten.avi"; }
  std::optional<int64_t> frame_count() const override { return 10; }
  std::optional<double> fps() const override { return 10.0; }

 private:
  int64_t next_ = 0;
};

// A fake clock: sleeping moves it forward; the test moves it for time spent elsewhere.
struct FakeClock {
  Clock::time_point now{};
  std::vector<double> sleeps_to_s;  // Each wait's end, in seconds from the start.

  PacedFrameSource::Timing timing() {
    PacedFrameSource::Timing t;
    t.now = [this] { return now; };
    t.sleep_until = [this](Clock::time_point until) {
      sleeps_to_s.push_back(std::chrono::duration<double>(until - Clock::time_point{}).count());
      if (until > now) now = until;
    };
    return t;
  }
  void advance(double s) {
    now += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }
  double seconds() const { return std::chrono::duration<double>(now - Clock::time_point{}).count(); }
};

TEST(PacedFrameSource, PlaysAtTheFileRateWithoutDroppingAndAPauseIsNoGap) {
  FakeClock clock;
  PacedFrameSource source(std::make_unique<TenFrames>(), clock.timing());
  Frame frame;
  std::vector<int64_t> indices;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(source.read(frame));
    indices.push_back(frame.index);
  }
  EXPECT_NEAR(clock.seconds(), 0.2, 1e-6) << "frame 2 is due 0.2 s after frame 0";

  source.pause();
  clock.advance(5.0);  // Paused for 5 s: the clock stops.
  ASSERT_TRUE(source.read(frame));  // Stepping while paused: at once.
  indices.push_back(frame.index);
  EXPECT_NEAR(clock.seconds(), 5.2, 1e-6);
  source.resume();
  ASSERT_TRUE(source.read(frame));
  indices.push_back(frame.index);
  EXPECT_NEAR(clock.seconds(), 5.3, 1e-6) << "one frame period after the last frame shown";

  clock.advance(1.0);  // A slow consumer: frames come late, none is skipped.
  while (source.read(frame)) indices.push_back(frame.index);
  EXPECT_EQ(indices, (std::vector<int64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(source.dropped_frames(), 0);
  EXPECT_NEAR(frame.time_s, 0.9, 1e-12) << "timestamps are the file's";
}

// At 0.5x a frame period of 0.1 s takes 0.2 s, at 4x 0.025 s; a change starts from the last
// frame delivered (no jump, no burst to catch up).
TEST(PacedFrameSource, SpeedScalesTheFramePeriodFromTheLastFrameOn) {
  FakeClock clock;
  PacedFrameSource source(std::make_unique<TenFrames>(), clock.timing());
  Frame frame;
  ASSERT_TRUE(source.read(frame));
  ASSERT_TRUE(source.read(frame));
  EXPECT_NEAR(clock.seconds(), 0.1, 1e-6);
  source.set_speed(0.5);
  ASSERT_TRUE(source.read(frame));
  EXPECT_NEAR(clock.seconds(), 0.3, 1e-6);
  ASSERT_TRUE(source.read(frame));
  EXPECT_NEAR(clock.seconds(), 0.5, 1e-6);
  clock.advance(1.0);  // Late: the change of speed does not make up for it with a burst.
  source.set_speed(4.0);
  ASSERT_TRUE(source.read(frame));
  EXPECT_NEAR(clock.seconds(), 1.525, 1e-6);
  EXPECT_EQ(frame.index, 4);
  source.set_speed(0.0);  // Not a speed: ignored.
  EXPECT_EQ(source.speed(), 4.0);
}

}  // namespace
}  // namespace softsight
