#include "softsight/gui/frame_grabber.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "softsight/core/error.h"

namespace softsight {
namespace {

// Frames whose pixel (0, 0) carries the index; optionally throws at `fail_at`.
class CountingSource : public FrameSource {
 public:
  CountingSource(int count, double fps, int fail_at = -1)
      : count_(count), fps_(fps), fail_at_(fail_at) {}
  bool read(Frame& frame) override {
    if (next_ == fail_at_)
      throw InputError("video test.avi: frame " + std::to_string(next_) + " does not decode");
    if (next_ >= count_) return false;
    frame.image.create(8, 8, CV_8UC3);
    frame.image.setTo(cv::Scalar(next_ % 256, 0, 0));
    frame.index = next_;
    frame.time_s = next_ / fps_;
    ++next_;
    return true;
  }
  std::string description() const override { return "counting"; }
  std::optional<int64_t> frame_count() const override { return count_; }
  std::optional<double> fps() const override { return fps_; }

 private:
  int count_;
  double fps_;
  int fail_at_;
  int next_ = 0;
};

TEST(FrameGrabberTest, SlowConsumerGetsNewestFramesAndTheLastOne) {
  FrameGrabber grabber(std::make_unique<CountingSource>(200, 1000.0), /*pace=*/false);
  std::vector<int64_t> taken;
  GrabbedFrame g;
  while (!grabber.finished()) {
    if (grabber.wait_take(g, std::chrono::milliseconds(50))) {
      EXPECT_EQ(g.frame.image.at<cv::Vec3b>(0, 0)[0], g.frame.index % 256);  // Buffers intact.
      EXPECT_LE(g.captured, SteadyClock::now());
      taken.push_back(g.frame.index);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));  // A slow consumer.
    }
  }
  ASSERT_FALSE(taken.empty());
  for (size_t i = 1; i < taken.size(); ++i) EXPECT_GT(taken[i], taken[i - 1]);
  EXPECT_EQ(taken.back(), 199);  // The newest frame always wins, including the last.
  EXPECT_EQ(grabber.captured_count(), 200);
  EXPECT_EQ(grabber.dropped_count() + static_cast<int64_t>(taken.size()), 200);
}

TEST(FrameGrabberTest, FileSourcesArePacedAtTheirFrameRate) {
  const auto start = SteadyClock::now();
  FrameGrabber grabber(std::make_unique<CountingSource>(6, 50.0), /*pace=*/true);
  GrabbedFrame g;
  int64_t last = -1;
  while (!grabber.finished()) {
    if (grabber.wait_take(g, std::chrono::milliseconds(50))) last = g.frame.index;
  }
  EXPECT_EQ(last, 5);
  // Frame 5 is due 100 ms after frame 0: pacing holds it back (a lower bound only).
  EXPECT_GE(SteadyClock::now() - start, std::chrono::milliseconds(100));
  EXPECT_EQ(grabber.dropped_count(), 0);  // This consumer keeps up.
}

TEST(FrameGrabberTest, SourceErrorReachesTheConsumerOnce) {
  FrameGrabber grabber(std::make_unique<CountingSource>(10, 30.0, /*fail_at=*/3), false);
  GrabbedFrame g;
  bool threw = false;
  for (int i = 0; i < 200 && !threw; ++i) {
    try {
      grabber.wait_take(g, std::chrono::milliseconds(10));
    } catch (const InputError& e) {
      threw = true;
      EXPECT_NE(std::string(e.what()).find("frame 3"), std::string::npos);
    }
  }
  EXPECT_TRUE(threw);
  EXPECT_FALSE(grabber.take(g));  // Reported once; nothing more to take.
}

TEST(FrameGrabberTest, DestructorStopsAnEndlessSource) {
  // A long paced source: destroying the grabber must not wait for it.
  const auto start = SteadyClock::now();
  {
    FrameGrabber grabber(std::make_unique<CountingSource>(1000000, 1.0), /*pace=*/true);
    GrabbedFrame g;
    EXPECT_TRUE(grabber.wait_take(g, std::chrono::milliseconds(500)));
  }
  EXPECT_LT(SteadyClock::now() - start, std::chrono::seconds(5));
}

}  // namespace
}  // namespace softsight
