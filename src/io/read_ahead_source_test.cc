#include "io/read_ahead_source.h"

#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/io/frame_writer.h"

namespace softsight {
namespace {

using testing::TempDir;

// Frame `i` shows its number: written as text (for a person looking at the video) and, for the
// test, in binary, one 8x8 block per bit along the top row (white = 1), which any codec keeps.
constexpr int kBits = 12;
cv::Mat NumberedFrame(int i) {
  cv::Mat image(120, 160, CV_8UC3, cv::Scalar(30, 60, 90));
  for (int bit = 0; bit < kBits; ++bit) {
    const uchar level = ((i >> bit) & 1) != 0 ? 255 : 0;
    image(cv::Rect(bit * 8, 0, 8, 8)).setTo(cv::Scalar::all(level));
  }
  cv::putText(image, std::to_string(i), {20, 80}, cv::FONT_HERSHEY_SIMPLEX, 1.5, {255, 255, 255}, 3);
  return image;
}

// The number a frame shows (the blocks' centre pixels).
int NumberShown(const cv::Mat& image) {
  int number = 0;
  for (int bit = 0; bit < kBits; ++bit) {
    const cv::Vec3b centre = image.at<cv::Vec3b>(4, bit * 8 + 4);
    if (centre[1] > 128) number |= 1 << bit;
  }
  return number;
}

std::string WriteNumberedVideo(const std::string& path, const std::string& codec, int frames) {
  FrameWriter writer({path, codec, 30.0});
  for (int i = 0; i < frames; ++i) writer.write(NumberedFrame(i), i);
  writer.close();
  return path;
}

// What a reader saw: per frame its index, time and the number it shows; then how it ended.
struct Reading {
  std::vector<int64_t> indices;
  std::vector<double> times;
  std::vector<int> numbers;
  std::string error;  // Empty: the stream ended without one.
};

Reading ReadAll(FrameSource& source) {
  Reading reading;
  Frame frame;
  try {
    while (source.read(frame)) {
      reading.indices.push_back(frame.index);
      reading.times.push_back(frame.time_s);
      reading.numbers.push_back(NumberShown(frame.image));
    }
  } catch (const InputError& e) {
    reading.error = e.what();
  }
  return reading;
}

TEST(ReadAheadSource, DeliversEveryFrameOfAVideoInOrder) {
  TempDir dir;
  const int frames = 90;
  const std::string path = WriteNumberedVideo(dir.file("numbered.avi"), "hfyu", frames);
  // A queue of 2: the decoder is ahead most of the time and has to wait for the reader.
  ReadAheadSource source(OpenFrameSource({path, {}, 30.0}), 2);
  EXPECT_EQ(source.description(), "video " + path);
  EXPECT_EQ(source.frame_count(), frames);
  EXPECT_EQ(source.files(), std::vector<std::string>{path});
  const Reading reading = ReadAll(source);
  EXPECT_EQ(reading.error, "");
  ASSERT_EQ(reading.indices.size(), static_cast<size_t>(frames));
  for (int i = 0; i < frames; ++i) {
    ASSERT_EQ(reading.indices[i], i);
    ASSERT_EQ(reading.numbers[i], i) << "frame " << i << " shows another frame's number";
    EXPECT_NEAR(reading.times[i], i / 30.0, 1e-3);
  }
  Frame frame;
  EXPECT_FALSE(source.read(frame)) << "the end is the end";
  EXPECT_EQ(source.dropped_frames(), 0);
}

TEST(ReadAheadSource, ImageSequenceKeepsItsNumbersAndNote) {
  TempDir dir;
  // Files 1, 2, 3, 6, 7: a gap the source notes.
  {
    FrameWriter writer({dir.file("f%02d.png"), "", 30.0});
    for (int i : {1, 2, 3, 6, 7}) writer.write(NumberedFrame(i), i);
  }
  auto inner = OpenFrameSource({dir.file("f%02d.png"), {}, 10.0});
  const std::optional<std::string> note = inner->note();
  ASSERT_TRUE(note.has_value());
  ReadAheadSource source(std::move(inner), 1);
  const Reading reading = ReadAll(source);
  EXPECT_EQ(reading.indices, (std::vector<int64_t>{1, 2, 3, 6, 7}));
  EXPECT_EQ(reading.numbers, (std::vector<int>{1, 2, 3, 6, 7}));
  EXPECT_EQ(source.note(), note);
}

// A file cut short (or damaged): the same frames and the same error line, in the same place, as
// reading it without the thread.
TEST(ReadAheadSource, TruncatedOrDamagedFileEndsLikeAnUnthreadedRead) {
  TempDir dir;
  for (const char* codec : {"hfyu", "mjpg"}) {
    const std::string full = testing::ReadTextFile(WriteNumberedVideo(dir.file("full.avi"), codec, 40));
    for (double cut : {0.3, 0.55, 0.8}) {
      for (bool zeroed : {false, true}) {
        std::string data = full;
        if (zeroed) {
          for (size_t i = data.size() * cut; i < data.size() * cut + 300; ++i) data[i] = 0;
        } else {
          data.resize(static_cast<size_t>(cut * data.size()));
        }
        const std::string path = dir.file("damaged.avi");
        std::ofstream(path, std::ios::binary).write(data.data(), static_cast<std::streamsize>(data.size()));
        auto plain = OpenFrameSource({path, {}, 30.0});
        const Reading unthreaded = ReadAll(*plain);
        ReadAheadSource threaded(OpenFrameSource({path, {}, 30.0}), 3);
        const Reading read_ahead = ReadAll(threaded);
        const std::string where = std::string(codec) + " cut at " + std::to_string(cut) +
                                  (zeroed ? " (zeroed)" : " (truncated)");
        // HuffYUV has no checksum: zeroed bytes may decode without complaint, so only a cut
        // is sure to be an error. Either way the two readings must agree.
        if (!zeroed) {
          EXPECT_NE(unthreaded.error, "") << where;
        }
        EXPECT_EQ(read_ahead.error, unthreaded.error) << where;
        EXPECT_EQ(read_ahead.indices, unthreaded.indices) << where;
        EXPECT_EQ(read_ahead.numbers, unthreaded.numbers) << where;
        EXPECT_EQ(read_ahead.times, unthreaded.times) << where;
        Frame frame;
        EXPECT_FALSE(threaded.read(frame)) << where << ": the error is reported once";
      }
    }
  }
}

// Frames whose pixel (0, 0) carries the index; throws at `fail_at`; endless with count < 0.
class IndexInPixelSource : public FrameSource {
 public:
  explicit IndexInPixelSource(int count, int fail_at = -1) : count_(count), fail_at_(fail_at) {}
  bool read(Frame& frame) override {
    if (next_ == fail_at_) throw InputError("counting: frame " + std::to_string(next_) + " is bad");
    if (count_ >= 0 && next_ >= count_) return false;
    frame.image.create(4, 4, CV_8UC3);
    frame.image.setTo(cv::Scalar(next_ % 256, next_ / 256 % 256, 0));
    frame.index = next_;
    frame.time_s = next_ / 30.0;
    ++next_;
    return true;
  }
  std::string description() const override { return "counting"; }
  std::optional<int64_t> frame_count() const override {
    return count_ >= 0 ? std::optional<int64_t>(count_) : std::nullopt;
  }
  std::optional<double> fps() const override { return 30.0; }

 private:
  int count_;
  int fail_at_;
  int next_ = 0;
};

TEST(ReadAheadSource, ErrorComesAfterTheFramesBeforeItAndOnce) {
  ReadAheadSource source(std::make_unique<IndexInPixelSource>(10, /*fail_at=*/3), 4);
  Frame frame;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(source.read(frame));
    EXPECT_EQ(frame.index, i);
    EXPECT_EQ(frame.image.at<cv::Vec3b>(0, 0)[0], i);
  }
  EXPECT_THAT([&] { source.read(frame); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("frame 3 is bad")));
  EXPECT_FALSE(source.read(frame));
}

TEST(ReadAheadSource, AFrameKeptByTheReaderIsNeverOverwritten) {
  ReadAheadSource source(std::make_unique<IndexInPixelSource>(600), 2);
  Frame frame;
  std::vector<cv::Mat> kept;  // Shallow copies, as a sink that keeps frames would hold them.
  for (int i = 0; i < 600; ++i) {
    ASSERT_TRUE(source.read(frame));
    if (i % 50 == 0) kept.push_back(frame.image);
  }
  for (size_t k = 0; k < kept.size(); ++k) {
    const cv::Vec3b pixel = kept[k].at<cv::Vec3b>(0, 0);
    EXPECT_EQ(pixel[0] + 256 * pixel[1], static_cast<int>(k) * 50) << "kept frame " << k * 50;
  }
}

TEST(ReadAheadSource, StopsWithAFullQueueOfAnEndlessSource) {
  // The decoder waits on a full queue; destroying the source (a Ctrl-C ending the run) must stop
  // it at once rather than wait for the end of a stream that never ends.
  auto source = std::make_unique<ReadAheadSource>(std::make_unique<IndexInPixelSource>(-1), 2);
  Frame frame;
  ASSERT_TRUE(source->read(frame));
  EXPECT_FALSE(source->frame_count().has_value());
  source.reset();  // Hangs here (the test times out) if the decoder cannot be stopped.
}

}  // namespace
}  // namespace softsight
