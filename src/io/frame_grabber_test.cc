#include "io/frame_grabber.h"

#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
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
  int64_t last = -1, taken = 0;
  while (!grabber.finished()) {
    if (grabber.wait_take(g, std::chrono::milliseconds(50))) {
      last = g.frame.index;
      ++taken;
    }
  }
  EXPECT_EQ(last, 5);
  // Frame 5 is due 100 ms after frame 0: pacing holds it back (a lower bound only).
  EXPECT_GE(SteadyClock::now() - start, std::chrono::milliseconds(100));
  // Whether this consumer keeps up depends on the machine's load, so only the books must
  // balance (a file that must never drop goes through PacedFrameSource instead).
  EXPECT_EQ(grabber.dropped_count() + taken, 6);
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

// A camera stand-in: delivers `burst` frames at once, then holds the next read until released,
// so the test knows exactly how many frames arrived before the consumer looked.
class BurstSource : public FrameSource {
 public:
  explicit BurstSource(int burst) : burst_(burst) {}
  bool read(Frame& frame) override {
    if (next_ == burst_) {
      std::unique_lock<std::mutex> lock(mutex_);
      delivered_ = true;
      changed_.notify_all();
      changed_.wait(lock, [this] { return released_; });
      return false;  // The camera is gone after the burst.
    }
    frame.image.create(4, 4, CV_8UC3);
    frame.index = next_;
    frame.time_s = next_ / 30.0;
    ++next_;
    return true;
  }
  std::string description() const override { return "camera 9"; }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override { return 30.0; }
  bool is_live() const override { return true; }

  void wait_delivered() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return delivered_; });
  }
  void release() {
    std::lock_guard<std::mutex> lock(mutex_);
    released_ = true;
    changed_.notify_all();
  }

 private:
  int burst_;
  int next_ = 0;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool delivered_ = false, released_ = false;
};

struct ReleaseAtExit {
  BurstSource& camera;
  ~ReleaseAtExit() { camera.release(); }
};

TEST(NewestFrameSource, AStaleFrameIsDroppedCountedAndTheNewestKeepsItsIndex) {
  auto burst = std::make_unique<BurstSource>(10);
  BurstSource& camera = *burst;
  NewestFrameSource source(std::move(burst));
  const ReleaseAtExit guard{camera};  // Runs before the source's destructor joins its thread.
  camera.wait_delivered();  // All 10 frames arrived before the consumer's first read.
  Frame frame;
  ASSERT_TRUE(source.read(frame));
  EXPECT_EQ(frame.index, 9) << "newest frame wins";
  EXPECT_NEAR(frame.time_s, 9 / 30.0, 1e-12);
  EXPECT_EQ(source.dropped_frames(), 9);
  EXPECT_TRUE(source.is_live());
  EXPECT_EQ(source.description(), "camera 9");
  camera.release();
  EXPECT_FALSE(source.read(frame));
  EXPECT_EQ(source.dropped_frames(), 9);
}

TEST(NewestFrameSource, ASilentCameraIsAnErrorNamingIt) {
  auto burst = std::make_unique<BurstSource>(0);
  BurstSource& camera = *burst;
  NewestFrameSource source(std::move(burst), std::chrono::milliseconds(0));
  const ReleaseAtExit guard{camera};
  Frame frame;
  EXPECT_THROW(
      {
        try {
          source.read(frame);
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("camera 9"), std::string::npos);
          throw;
        }
      },
      InputError);
}

}  // namespace
}  // namespace softsight
