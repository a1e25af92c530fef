#include "softsight/io/async_frame_writer.h"

#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/test_util.h"
#include "io/encoder_gate_test_util.h"
#include "softsight/io/frame_source.h"

namespace softsight {
namespace {

using testing::TempDir;

// Frame `i`: a textured image that differs from every other frame everywhere.
cv::Mat TexturedNumberedFrame(int i) {
  cv::Mat image(96, 128, CV_8UC3);
  cv::RNG rng(static_cast<uint64_t>(i) + 1);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  cv::putText(image, std::to_string(i), {10, 60}, cv::FONT_HERSHEY_SIMPLEX, 1.2, {255, 255, 255}, 2);
  return image;
}

std::vector<Frame> ReadBack(const std::string& path) {
  std::unique_ptr<FrameSource> source = OpenFrameSource({path, {}, 30.0});
  std::vector<Frame> frames;
  Frame frame;
  while (source->read(frame)) {
    frames.push_back(frame);
    frames.back().image = frame.image.clone();
  }
  return frames;
}

bool SameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

TEST(AsyncFrameWriter, AFileRecordingWaitsForTheEncoderAndKeepsEveryFrameBitExact) {
  TempDir dir;
  const std::string path = dir.file("rec.avi");
  {
    AsyncFrameWriter writer({path, "hfyu", 30.0}, /*capacity=*/2);
    EXPECT_EQ(writer.format(), "HuffYUV video (lossless)");
    for (int i = 0; i < 40; ++i) {
      cv::Mat* slot = writer.acquire();
      ASSERT_NE(slot, nullptr) << "never dropped";
      TexturedNumberedFrame(i).copyTo(*slot);
      writer.commit(i);
    }
    writer.close();
    EXPECT_EQ(writer.queued(), 40);
  }
  const std::vector<Frame> frames = ReadBack(path);
  ASSERT_EQ(frames.size(), 40u);
  for (int i = 0; i < 40; ++i) {
    EXPECT_EQ(frames[i].index, i);
    EXPECT_TRUE(SameImage(frames[i].image, TexturedNumberedFrame(i))) << "frame " << i;
  }
}

TEST(AsyncFrameWriter, AWaitingWriterCountsTheFramesThatHeldUpThePipelineAndLosesNone) {
  TempDir dir;
  const std::string path = dir.file("rec.avi");
  testing::EncoderGate gate;  // Holds frame 0.
  {
    AsyncFrameWriter writer({path, "hfyu", 30.0}, /*capacity=*/2,
                            [&gate](int64_t index) { gate.wait(index); });
    // Frame 0 is held at the encoder and frame 1 waits behind it: the producer's frame 2 waits
    // for a free buffer until the encoder goes on.
    std::thread producer([&writer] {
      for (int i = 0; i < 5; ++i) {
        cv::Mat* slot = writer.acquire();
        ASSERT_NE(slot, nullptr) << "never dropped";
        TexturedNumberedFrame(i).copyTo(*slot);
        writer.commit(i);
      }
    });
    while (writer.waited() == 0) std::this_thread::yield();  // The producer is held up.
    EXPECT_EQ(writer.queued(), 2);
    gate.open();
    producer.join();
    writer.close();
    EXPECT_EQ(writer.queued(), 5);
    EXPECT_GE(writer.waited(), 1);
    EXPECT_LE(writer.waited(), 3) << "only frames 2..4 can find the queue full";
  }
  const std::vector<Frame> frames = ReadBack(path);
  ASSERT_EQ(frames.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(SameImage(frames[i].image, TexturedNumberedFrame(i))) << "frame " << i;
  }
}

}  // namespace
}  // namespace softsight
