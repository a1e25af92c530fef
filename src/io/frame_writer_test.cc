#include "softsight/io/frame_writer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/test_util.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

cv::Mat Pattern(int seed) {
  cv::Mat image(48, 64, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  image.row(seed % 48).setTo(cv::Scalar(seed, 255 - seed, 7));
  return image;
}

std::string ErrorOf(const FrameWriterOptions& options) {
  try {
    FrameWriter writer(options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FrameWriter, Ffv1VideoReadsBackBitExact) {
  TempDir dir;
  cv::setRNGSeed(3);
  std::vector<cv::Mat> frames = {Pattern(1), Pattern(2), Pattern(3)};
  {
    FrameWriter writer({dir.file("raw.avi"), "", 25.0});
    EXPECT_EQ(writer.format(), "FFV1 video (lossless)");
    for (size_t i = 0; i < frames.size(); ++i) writer.write(frames[i], static_cast<int64_t>(i));
    EXPECT_EQ(writer.written(), 3);
  }
  cv::VideoCapture video(dir.file("raw.avi"), cv::CAP_FFMPEG);
  ASSERT_TRUE(video.isOpened());
  EXPECT_DOUBLE_EQ(video.get(cv::CAP_PROP_FPS), 25.0);
  cv::Mat read;
  for (const cv::Mat& frame : frames) {
    ASSERT_TRUE(video.read(read));
    EXPECT_EQ(cv::norm(read, frame, cv::NORM_INF), 0.0);
  }
  EXPECT_FALSE(video.read(read));
}

TEST(FrameWriter, ImagePatternNamesEachFileByTheFrameIndex) {
  TempDir dir;
  const cv::Mat frame = Pattern(5);
  {
    FrameWriter writer({dir.file("f%04d.png"), "", 30.0});
    writer.write(frame, 17);
  }
  const cv::Mat read = cv::imread(dir.file("f0017.png"), cv::IMREAD_COLOR);
  ASSERT_FALSE(read.empty());
  EXPECT_EQ(cv::norm(read, frame, cv::NORM_INF), 0.0);
}

TEST(FrameWriter, BadOutputsAreRefusedBeforeAnyFrame) {
  TempDir dir;
  EXPECT_THAT(ErrorOf({dir.file("none/raw.avi"), "", 30.0}), HasSubstr("does not exist"));
  EXPECT_THAT(ErrorOf({dir.file("raw.xyz"), "", 30.0}), HasSubstr("unknown video type"));
  EXPECT_THAT(ErrorOf({dir.file("raw.avi"), "h265", 30.0}), HasSubstr("h265"));
  EXPECT_THAT(ErrorOf({dir.file("f%d%d.png"), "", 30.0}), HasSubstr("exactly one"));
  EXPECT_THAT(ErrorOf({dir.file("raw.avi"), "", 0.0}), HasSubstr("frame rate"));
}

TEST(FrameWriter, AFrameOfAnotherSizeIsAnErrorNamingTheFrame) {
  TempDir dir;
  FrameWriter writer({dir.file("raw.avi"), "", 30.0});
  writer.write(Pattern(1), 0);
  EXPECT_THROW(
      {
        try {
          writer.write(cv::Mat(10, 10, CV_8UC3, cv::Scalar::all(0)), 1);
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("frame 1"));
          throw;
        }
      },
      InputError);
}

}  // namespace
}  // namespace softsight
