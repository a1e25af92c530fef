#include "softsight/io/frame_source.h"

#include <algorithm>
#include <fstream>
#include <optional>
#include <random>
#include <set>

#include <sys/stat.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/test_util.h"
#include "io/damaged_video_test_util.h"
#include "io/decode_probe.h"
#include "io/decoder_log.h"
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
int CountFramesToTheEnd(FrameSource& source) {
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
    CountFramesToTheEnd(*source);
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
  EXPECT_THROW(CountFramesToTheEnd(*source), InputError);
}

// Frames that differ from each other everywhere a little and in one place a lot: a textured
// background and a disc moving 6 px per frame.
std::vector<cv::Mat> DistinctFrames(int count) {
  cv::RNG rng(1);
  cv::Mat background(240, 320, CV_8UC3);
  rng.fill(background, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(background, background, {0, 0}, 3);
  std::vector<cv::Mat> frames;
  for (int i = 0; i < count; ++i) {
    frames.push_back(background.clone());
    cv::circle(frames.back(), {20 + 6 * i, 120}, 15, {0, 0, 255}, -1);
  }
  return frames;
}

std::string WriteFrames(const std::string& path, const char* fourcc,
                        const std::vector<cv::Mat>& frames) {
  cv::VideoWriter writer(path, cv::CAP_FFMPEG,
                         cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]), 30.0,
                         frames.front().size());
  EXPECT_TRUE(writer.isOpened());
  for (const cv::Mat& frame : frames) writer << frame;
  return path;
}

void WriteBytes(const std::string& path, const std::string& data) {
  std::ofstream(path, std::ios::binary).write(data.data(), static_cast<std::streamsize>(data.size()));
}

// Which of `originals` a decoded frame is closest to (mean absolute difference per pixel). The
// distances between the originals are computed once: by the triangle inequality an original j
// farther from the expected one than twice the frame's distance to it cannot be closer, so most
// frames need one or two comparisons instead of one per original (57 % of this file's time).
class ClosestOriginal {
 public:
  explicit ClosestOriginal(const std::vector<cv::Mat>& originals)
      : originals_(originals), between_(originals.size(), std::vector<double>(originals.size())) {
    for (size_t i = 0; i < originals.size(); ++i) {
      for (size_t j = i + 1; j < originals.size(); ++j) {
        between_[i][j] = between_[j][i] = Distance(originals[i], originals[j]);
      }
    }
  }

  // The closest original's index (the first of equals), starting from the `expected` one.
  int operator()(const cv::Mat& image, int64_t expected, double* distance) const {
    const size_t n = originals_.size();
    const size_t first =
        expected >= 0 && static_cast<size_t>(expected) < n ? static_cast<size_t>(expected) : 0;
    const double to_first = Distance(image, originals_[first]);
    size_t best = first;
    *distance = to_first;
    for (size_t j = 0; j < n; ++j) {
      if (j == first || between_[first][j] - to_first > *distance) continue;
      const double d = Distance(image, originals_[j]);
      if (d < *distance || (d == *distance && j < best)) *distance = d, best = j;
    }
    return static_cast<int>(best);
  }

 private:
  static double Distance(const cv::Mat& a, const cv::Mat& b) {
    return cv::norm(a, b, cv::NORM_L1) / static_cast<double>(a.total());
  }
  const std::vector<cv::Mat>& originals_;
  std::vector<std::vector<double>> between_;
};

// Cut short at many places: every frame returned is the frame its index names (never a stale
// copy of an earlier one, never half decoded), and the end is an error.
TEST(VideoFileSource, TruncatedVideoReturnsOnlyWholeFramesOfTheRightIndex) {
  TempDir dir;
  const std::vector<cv::Mat> originals = DistinctFrames(40);
  const ClosestOriginal closest(originals);
  for (const char* codec : {"FFV1", "MJPG"}) {
    const std::string full = testing::ReadTextFile(WriteFrames(dir.file("full.avi"), codec, originals));
    for (double cut = 0.20; cut < 0.70; cut += 0.02) {
      const std::string path = dir.file("cut.avi");
      WriteBytes(path, full.substr(0, static_cast<size_t>(cut * full.size())));
      auto source = OpenFrameSource({path, {}, 30.0});
      Frame frame;
      int read = 0;
      try {
        while (source->read(frame)) {
          double distance = 0;
          ASSERT_EQ(closest(frame.image, frame.index, &distance), frame.index)
              << codec << " cut at " << cut << ": frame " << frame.index << " shows another frame";
          // FFV1 is lossless; MJPG at OpenCV's quality stays within a few grey levels.
          ASSERT_LE(distance, std::string(codec) == "FFV1" ? 0.0 : 2.0 * 3)
              << codec << " cut at " << cut << ": frame " << frame.index << " is damaged";
          ASSERT_EQ(frame.index, read++);
        }
        ADD_FAILURE() << codec << " cut at " << cut << ": the truncation was not reported";
      } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("truncated")) << e.what();
      }
      EXPECT_GT(read, 3) << codec << " cut at " << cut;
    }
  }
}

// Bits flipped in an MJPG video: the frames whose decoding FFmpeg logged an error for get no
// frame (no row), the others keep their indices, and the end of the stream reports the count.
TEST(VideoFileSource, FramesTheDecoderFoundDamagedAreLeftOutAndReported) {
  TempDir dir;
  const std::vector<cv::Mat> originals = DistinctFrames(40);
  std::string data = testing::ReadTextFile(WriteFrames(dir.file("clip.avi"), "MJPG", originals));
  std::mt19937 random(5);
  for (int flip = 0; flip < 20; ++flip) {
    const size_t at = data.size() * 4 / 10 + random() % (data.size() / 5);
    data[at] = static_cast<char>(data[at] ^ (1 << (random() % 8)));
  }
  const std::string path = dir.file("flipped.avi");
  WriteBytes(path, data);

  // Which frames the decoder itself complains about, read with OpenCV directly, and which
  // differ from the clean file's (the decoder concealed more than it complained about).
  CaptureDecoderErrors();
  std::set<int64_t> complained, changed;
  {
    cv::VideoCapture capture(path, cv::CAP_FFMPEG);
    cv::VideoCapture clean(dir.file("clip.avi"), cv::CAP_FFMPEG);
    cv::Mat image, clean_image;
    for (int64_t i = 0;; ++i) {
      const uint64_t before = DecoderErrorCount();
      if (!capture.read(image) || !clean.read(clean_image)) break;
      if (DecoderErrorCount() != before) complained.insert(i);
      if (cv::norm(image, clean_image, cv::NORM_INF) > 0) changed.insert(i);
    }
  }
  ASSERT_FALSE(complained.empty()) << "these flips no longer upset the decoder: choose others";

  // Every frame the decoder complained about is left out; so may be others its data or its
  // picture shows damaged (io/jpeg_scan.h, io/damaged_band.h), but only frames that are.
  std::string report;
  const std::vector<int64_t> indices =
      testing::ReadExpectingDamageLeftOut(path, complained, &report);
  EXPECT_THAT(report, HasSubstr(std::to_string(40 - indices.size()) + " frame"));
  for (int64_t i = 0; i < 40; ++i) {
    if (std::count(indices.begin(), indices.end(), i) == 0) {
      EXPECT_EQ(changed.count(i), 1u) << "frame " << i << " is whole, and was left out";
    }
  }
}

// The second decoding that marks the frames FFmpeg concealed damage in (io/decode_probe.h).
TEST(DecodeProbe, MarksNoFrameOfACleanVideoAndSaysWhereTheVideoEnds) {
  TempDir dir;
  const std::string path = WriteFrames(dir.file("clean.mp4"), "mp4v", DistinctFrames(30));
  DecodeProbe probe(path);
  for (int64_t i = 0; i < 30; ++i) EXPECT_EQ(probe.concealed(i), std::optional<bool>(false)) << i;
  EXPECT_EQ(probe.concealed(30), std::nullopt) << "past the last frame the probe cannot say";
  EXPECT_EQ(probe.concealed(-1), std::nullopt);
  DecodeProbe missing(dir.file("none.mp4"));
  EXPECT_EQ(missing.concealed(0), std::nullopt);
}

TEST(DecodeProbe, MarksTheSameFramesOfADamagedVideoEveryTimeAndLogsNothingOfItsOwn) {
  TempDir dir;
  std::string data =
      testing::ReadTextFile(WriteFrames(dir.file("clip.mp4"), "mp4v", DistinctFrames(40)));
  std::mt19937 random(3);
  for (int flip = 0; flip < 20; ++flip) {
    const size_t at = data.size() / 10 + random() % (data.size() * 8 / 10);
    data[at] = static_cast<char>(data[at] ^ (1 << (random() % 8)));
  }
  const std::string path = dir.file("flipped.mp4");
  WriteBytes(path, data);
  CaptureDecoderErrors();
  const uint64_t errors_before = DecoderErrorCount();
  std::vector<std::vector<bool>> runs;
  for (int run = 0; run < 3; ++run) {
    DecodeProbe probe(path);
    std::vector<bool> marks;
    for (int64_t i = 0;; ++i) {
      const std::optional<bool> concealed = probe.concealed(i);
      if (!concealed) break;
      marks.push_back(*concealed);
    }
    runs.push_back(marks);
  }
  EXPECT_EQ(DecoderErrorCount(), errors_before) << "the probe's own complaints were counted";
  ASSERT_GT(runs[0].size(), 20u);
  EXPECT_EQ(runs[1], runs[0]);
  EXPECT_EQ(runs[2], runs[0]);
  EXPECT_GT(std::count(runs[0].begin(), runs[0].end(), true), 0) << "choose flips that do damage";
}

TEST(DecodeProbe, StopsWhenDroppedMidFile) {
  TempDir dir;
  const std::string path = WriteFrames(dir.file("clean.mp4"), "mp4v", DistinctFrames(60));
  for (int i = 0; i < 5; ++i) {
    DecodeProbe probe(path);
    EXPECT_EQ(probe.concealed(1), std::optional<bool>(false));
  }  // Each destructor returns: the thread stopped between packets.
}

// Each frame says whether it was decoded on its own: MPEG-4 as OpenCV writes it has a key frame
// every 12th frame, whose damage (or the frames' before it) the frames after it do not repeat;
// in an intra-only codec (HuffYUV, MJPG) every frame is one.
TEST(VideoFileSource, FramesSayWhetherTheyAreKeyFrames) {
  TempDir dir;
  const std::vector<cv::Mat> frames = DistinctFrames(40);
  for (const char* fourcc : {"mp4v", "HFYU", "MJPG"}) {
    const std::string path = WriteFrames(dir.file(std::string("v_") + fourcc +
                                                  (fourcc[0] == 'm' ? ".mp4" : ".avi")),
                                         fourcc, frames);
    FrameSourceSpec spec;
    spec.input = path;
    auto source = OpenFrameSource(spec);
    Frame frame;
    int read = 0;
    while (source->read(frame)) {
      const bool predicted_codec = fourcc[0] == 'm';
      EXPECT_EQ(frame.key_frame, !predicted_codec || frame.index % 12 == 0)
          << fourcc << " frame " << frame.index;
      ++read;
    }
    EXPECT_EQ(read, 40) << fourcc;
  }
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

// A pipe would be read by the decoder and, in part, by the source's second readers (the key
// frame index, the damage probe), each taking frames from the other: refused before it is opened
// (opening a pipe nobody writes to would block).
TEST(VideoFileSource, PipeIsRefusedWithoutBeingOpened) {
  TempDir dir;
  const std::string pipe = dir.file("stream.avi");
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  try {
    OpenFrameSource({pipe, {}, 30.0});
    FAIL() << "a pipe was accepted as a video file";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("stream.avi: not a regular file"));
  }
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
  EXPECT_EQ(CountFramesToTheEnd(*source), 3);
}

TEST(ImageSequenceSource, PatternWithAGapKeepsEachFilesNumberAndSaysSo) {
  TempDir dir;
  for (int i : {1, 2, 3, 4, 8, 9}) {
    char name[32];
    std::snprintf(name, sizeof(name), "f%03d.png", i);
    cv::imwrite(dir.file(name), MakeFrame(i));
  }
  auto source = OpenFrameSource({dir.file("f%03d.png"), {}, 10.0});
  EXPECT_EQ(source->frame_count(), 6);
  ASSERT_TRUE(source->note().has_value());
  EXPECT_THAT(*source->note(), HasSubstr("3 file numbers missing (first: 5..7)"));
  Frame frame;
  for (int i : {1, 2, 3, 4, 8, 9}) {
    ASSERT_TRUE(source->read(frame));
    EXPECT_EQ(frame.index, i);
    EXPECT_NEAR(frame.time_s, (i - 1) / 10.0, 1e-12);
    EXPECT_EQ(frame.image.at<cv::Vec3b>(60, 30 + 3 * i), cv::Vec3b(0, 0, 255)) << "file " << i;
  }
  EXPECT_FALSE(source->read(frame));
}

TEST(ImageSequenceSource, FolderWithAGapIsNumberedByTheFileNames) {
  TempDir dir;
  for (int i : {0, 1, 2, 5, 6, 10}) {
    cv::imwrite(dir.file("shot_" + std::to_string(i) + ".png"), MakeFrame(i));
  }
  auto source = OpenFrameSource({dir.path().string(), {}, 30.0});
  ASSERT_TRUE(source->note().has_value());
  EXPECT_THAT(*source->note(), HasSubstr("5 file numbers missing (first: 3..4)"));
  Frame frame;
  for (int i : {0, 1, 2, 5, 6, 10}) {  // Number order, not name order (shot_10 < shot_2).
    ASSERT_TRUE(source->read(frame));
    EXPECT_EQ(frame.index, i);
    EXPECT_EQ(frame.image.at<cv::Vec3b>(60, 30 + 3 * i), cv::Vec3b(0, 0, 255)) << "file " << i;
  }
  EXPECT_FALSE(source->read(frame));
}

TEST(ImageSequenceSource, PatternWithAnythingButOneNumberIsRefusedNotFormatted) {
  TempDir dir;
  cv::imwrite(dir.file("0.png"), MakeFrame(0));
  for (const char* bad : {"%s.png", "%n.png", "%d%d.png", "%5d.png"}) {
    try {
      OpenFrameSource({dir.file(bad), {}, 30.0});
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(bad));
    }
  }
}

TEST(ImageSequenceSource, CorruptImageMidSequenceNamesFileAndFrame) {
  TempDir dir;
  for (int i = 0; i < 4; ++i) {
    cv::imwrite(dir.file(std::string("f").append(std::to_string(i)).append(".png")), MakeFrame(i));
  }
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
