#include "softsight/io/frame_source.h"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/sim/plate_scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

cv::Mat MakeFrame(int i) {
  cv::Mat frame(120, 160, CV_8UC3, cv::Scalar(40, 90, 60));
  cv::circle(frame, {30 + 3 * i, 60}, 10, {0, 0, 255}, -1);
  return frame;
}

std::string WriteVideo(const TempDir& dir, int frames) {
  const std::string path = dir.file("clip.avi");
  cv::VideoWriter writer(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0,
                         {160, 120});
  EXPECT_TRUE(writer.isOpened());
  for (int i = 0; i < frames; ++i) writer << MakeFrame(i);
  return path;
}

// Reads until the end; returns the frames read (rethrows the source's error).
int ReadAll(FrameSource& source) {
  Frame frame;
  int read = 0;
  while (source.read(frame)) ++read;
  return read;
}

void Damage(const std::string& path, bool truncate) {
  std::ifstream in(path, std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(in)), {});
  in.close();
  if (truncate) {
    data.resize(data.size() / 2);
  } else {
    for (size_t i = data.size() / 2; i < data.size() / 2 + 400; ++i) data[i] = 0;
  }
  std::ofstream(path, std::ios::binary).write(data.data(), static_cast<std::streamsize>(data.size()));
}

TEST(VideoFileSource, ReadsEveryFrameWithIndicesAndTimestamps) {
  TempDir dir;
  const std::string path = WriteVideo(dir, 20);
  auto source = OpenFrameSource({path, {}, 30.0});
  ASSERT_EQ(source->frame_count(), 20);
  EXPECT_NEAR(*source->fps(), 25.0, 1e-6);
  Frame frame;
  for (int i = 0; i < 20; ++i) {
    ASSERT_TRUE(source->read(frame)) << "frame " << i;
    EXPECT_EQ(frame.index, i);
    EXPECT_NEAR(frame.time_s, i / 25.0, 1e-3);
    EXPECT_EQ(frame.image.type(), CV_8UC3);
    EXPECT_EQ(frame.image.size(), cv::Size(160, 120));
  }
  EXPECT_FALSE(source->read(frame));
}

TEST(VideoFileSource, TruncatedFileIsAnErrorNamingTheFile) {
  TempDir dir;
  const std::string path = WriteVideo(dir, 40);
  Damage(path, /*truncate=*/true);
  try {
    auto source = OpenFrameSource({path, {}, 30.0});
    ReadAll(*source);
    FAIL() << "a truncated video was read without an error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
    EXPECT_THAT(e.what(), HasSubstr("truncated or corrupt"));
  }
}

TEST(VideoFileSource, FrameThatFailsToDecodeIsAnError) {
  TempDir dir;
  const std::string path = WriteVideo(dir, 40);
  Damage(path, /*truncate=*/false);
  auto source = OpenFrameSource({path, {}, 30.0});
  EXPECT_THROW(ReadAll(*source), InputError);
}

TEST(VideoFileSource, MissingOrNonVideoFileIsAnError) {
  TempDir dir;
  try {
    OpenFrameSource({dir.file("nothing.avi"), {}, 30.0});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("nothing.avi"));
  }
  testing::WriteTextFile(dir.file("notes.avi"), "this is not a video");
  EXPECT_THROW(OpenFrameSource({dir.file("notes.avi"), {}, 30.0}), InputError);
}

TEST(ImageSequenceSource, FolderIsReadInNameOrderAtTheGivenRate) {
  TempDir dir;
  for (int i = 0; i < 5; ++i) {
    cv::imwrite(dir.file("shot_" + std::to_string(i) + ".png"), MakeFrame(i));
  }
  testing::WriteTextFile(dir.file("README.txt"), "not an image, ignored");
  auto source = OpenFrameSource({dir.path().string(), {}, 10.0});
  ASSERT_EQ(source->frame_count(), 5);
  Frame frame;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(source->read(frame));
    EXPECT_NEAR(frame.time_s, i / 10.0, 1e-12);
    // The disc moves 3 px per frame: the frames come back in order.
    EXPECT_EQ(frame.image.at<cv::Vec3b>(60, 30 + 3 * i), cv::Vec3b(0, 0, 255));
  }
  EXPECT_FALSE(source->read(frame));
}

TEST(ImageSequenceSource, PrintfPatternStartingAtOne) {
  TempDir dir;
  for (int i = 1; i <= 3; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "f%03d.png", i);
    cv::imwrite(dir.file(name), MakeFrame(i));
  }
  auto source = OpenFrameSource({dir.file("f%03d.png"), {}, 30.0});
  EXPECT_EQ(ReadAll(*source), 3);
}

TEST(ImageSequenceSource, CorruptImageMidSequenceNamesFileAndFrame) {
  TempDir dir;
  for (int i = 0; i < 4; ++i) cv::imwrite(dir.file("f" + std::to_string(i) + ".png"), MakeFrame(i));
  testing::WriteTextFile(dir.file("f2.png"), "garbage");
  auto source = OpenFrameSource({dir.path().string(), {}, 30.0});
  Frame frame;
  ASSERT_TRUE(source->read(frame));
  ASSERT_TRUE(source->read(frame));
  try {
    source->read(frame);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("f2.png"));
    EXPECT_THAT(e.what(), HasSubstr("frame 2"));
  }
}

TEST(ImageSequenceSource, EmptyFolderOrUnmatchedPatternIsAnError) {
  TempDir dir;
  EXPECT_THROW(OpenFrameSource({dir.path().string(), {}, 30.0}), InputError);
  EXPECT_THROW(OpenFrameSource({dir.file("x%04d.png"), {}, 30.0}), InputError);
}

TEST(SyntheticSource, RendersTheNamedSceneWithItsTimestamps) {
  auto source = OpenFrameSource({"synth:wedge1", {}, 30.0});
  ASSERT_TRUE(source->frame_count().has_value());
  EXPECT_THAT(source->description(), HasSubstr("wedge1"));
  Frame frame;
  ASSERT_TRUE(source->read(frame));
  ASSERT_TRUE(source->read(frame));
  EXPECT_EQ(frame.index, 1);
  EXPECT_NEAR(frame.time_s, 1.0 / *source->fps(), 1e-9);
  EXPECT_EQ(frame.image.type(), CV_8UC3);
  EXPECT_FALSE(IsGrayscale(frame.image));
  EXPECT_THROW(OpenFrameSource({"synth:spiral", {}, 30.0}), InputError);
}

TEST(SyntheticSource, OpensTheBenchAndThePlate) {
  auto bench = OpenFrameSource({"synth:bench", {}, 30.0});
  EXPECT_THAT(bench->description(), HasSubstr("bench"));
  Frame frame;
  ASSERT_TRUE(bench->read(frame));
  EXPECT_FALSE(IsGrayscale(frame.image));
  auto plate = OpenFrameSource({"synth:plate", {}, 30.0});
  EXPECT_THAT(plate->description(), HasSubstr("plate"));
  ASSERT_TRUE(plate->read(frame));
  EXPECT_EQ(frame.image.type(), CV_8UC3);
  EXPECT_TRUE(IsGrayscale(frame.image));
  EXPECT_EQ(plate->frame_count(), PlateSceneOptions{}.frame_count);
}

TEST(IsGrayscale, TellsGrayFromColour) {
  cv::Mat gray(8, 8, CV_8UC3, cv::Scalar(77, 77, 77));
  EXPECT_TRUE(IsGrayscale(gray));
  gray.at<cv::Vec3b>(3, 3) = {10, 200, 10};
  EXPECT_FALSE(IsGrayscale(gray));
}

}  // namespace
}  // namespace softsight
