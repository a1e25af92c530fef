#include "softsight/io/frame_writer.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/io/frame_source.h"
#include "softsight/sim/scene.h"

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

std::string OpenError(const FrameWriterOptions& options) {
  try {
    FrameWriter writer(options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Rendered VGA frames of the bending scene: clean ones, and one with sensor noise (the hardest
// content for a lossless coder; a lossy or YUV path shows up there first).
std::vector<cv::Mat> RenderedFrames() {
  SceneOptions scene;
  scene.size = cv::Size(640, 480);
  scene.frame_count = 4;
  SyntheticScene clean(scene);
  NoiseOptions noise;
  noise.sigma = 6.0;
  noise.seed = 11;
  SyntheticScene noisy(scene, noise);
  std::vector<cv::Mat> frames(4);
  for (int i = 0; i < 3; ++i) clean.render(i, frames[i]);
  noisy.render(3, frames[3]);
  return frames;
}

// Every frame read back through the project's reader, each compared pixel for pixel.
void ExpectReadsBackBitExact(const std::string& path, const std::vector<cv::Mat>& frames) {
  FrameSourceSpec spec;
  spec.input = path;
  std::unique_ptr<FrameSource> source = OpenFrameSource(spec);
  Frame frame;
  for (size_t i = 0; i < frames.size(); ++i) {
    ASSERT_TRUE(source->read(frame)) << path << ": frame " << i;
    ASSERT_EQ(frame.image.size(), frames[i].size());
    EXPECT_EQ(cv::norm(frame.image, frames[i], cv::NORM_INF), 0.0) << path << ": frame " << i;
  }
  EXPECT_FALSE(source->read(frame)) << path;
}

int FourccOf(const std::string& path) {
  cv::VideoCapture video(path, cv::CAP_FFMPEG);
  return static_cast<int>(video.get(cv::CAP_PROP_FOURCC));
}

TEST(FrameWriter, DefaultVideoIsHuffyuvAndReadsBackBitExact) {
  TempDir dir;
  const std::vector<cv::Mat> frames = RenderedFrames();
  ASSERT_GT(cv::norm(frames[3], frames[2], cv::NORM_L1), 0.0);
  for (const char* name : {"raw.avi", "raw.mkv"}) {
    const std::string path = dir.file(name);
    {
      FrameWriter writer({path, "", 25.0});
      EXPECT_EQ(writer.format(), "HuffYUV video (lossless)");
      for (size_t i = 0; i < frames.size(); ++i) writer.write(frames[i], static_cast<int64_t>(i));
      EXPECT_EQ(writer.written(), 4);
    }
    EXPECT_EQ(FourccOf(path), cv::VideoWriter::fourcc('H', 'F', 'Y', 'U')) << name;
    ExpectReadsBackBitExact(path, frames);
  }
  cv::VideoCapture video(dir.file("raw.avi"), cv::CAP_FFMPEG);
  EXPECT_DOUBLE_EQ(video.get(cv::CAP_PROP_FPS), 25.0);
}

TEST(FrameWriter, Ffv1OnRequestReadsBackBitExact) {
  TempDir dir;
  cv::setRNGSeed(3);
  const std::vector<cv::Mat> frames = {Pattern(1), Pattern(2), Pattern(3)};
  {
    FrameWriter writer({dir.file("raw.avi"), "ffv1", 25.0});
    for (size_t i = 0; i < frames.size(); ++i) writer.write(frames[i], static_cast<int64_t>(i));
  }
  EXPECT_EQ(FourccOf(dir.file("raw.avi")), cv::VideoWriter::fourcc('F', 'F', 'V', '1'));
  ExpectReadsBackBitExact(dir.file("raw.avi"), frames);
}

// Recordings made before HuffYUV became the default (FFV1, written straight through
// cv::VideoWriter as the old writers did) still read, bit-exact.
TEST(FrameWriter, OldFfv1RecordingsStillRead) {
  TempDir dir;
  const std::vector<cv::Mat> frames = RenderedFrames();
  const std::string path = dir.file("old.raw.avi");
  {
    cv::VideoWriter old(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 30.0,
                        frames[0].size());
    ASSERT_TRUE(old.isOpened());
    for (const cv::Mat& frame : frames) old.write(frame);
  }
  ExpectReadsBackBitExact(path, frames);
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

// The pattern is parsed, never handed to printf as a format: what printf would misread is
// refused, and "%%" is a literal percent sign.
TEST(FrameWriter, ImagePatternIsNeverAPrintfFormat) {
  TempDir dir;
  for (const char* bad : {"f%s.png", "f%n.png", "f%099d.png", "f%5d.png", "f%x.png", "f%ld.png"}) {
    EXPECT_THAT(OpenError({dir.file(bad), "", 30.0}), HasSubstr(bad));
  }
  const cv::Mat frame = Pattern(3);
  {
    FrameWriter writer({dir.file("run_100%%_%03d.png"), "", 30.0});
    writer.write(frame, 7);
  }
  const cv::Mat read = cv::imread(dir.file("run_100%_007.png"), cv::IMREAD_COLOR);
  ASSERT_FALSE(read.empty()) << "\"%%\" is a literal percent sign";
  EXPECT_EQ(cv::norm(read, frame, cv::NORM_INF), 0.0);
}

TEST(FrameWriter, BadOutputsAreRefusedBeforeAnyFrame) {
  TempDir dir;
  EXPECT_THAT(OpenError({dir.file("none/raw.avi"), "", 30.0}), HasSubstr("does not exist"));
  EXPECT_THAT(OpenError({dir.file("raw.xyz"), "", 30.0}), HasSubstr("unknown video type"));
  EXPECT_THAT(OpenError({dir.file("raw.avi"), "h265", 30.0}), HasSubstr("h265"));
  EXPECT_THAT(OpenError({dir.file("f%d%d.png"), "", 30.0}), HasSubstr("more than one number"));
  EXPECT_THAT(OpenError({dir.file("raw.avi"), "", 0.0}), HasSubstr("frame rate"));
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
// A video cut by a file-size limit (ulimit -f; a full disk does the same): FFmpeg says nothing,
// the file holds a fraction of the frames. Closing reads it back and says so, naming the file.
// Run in a child process, which alone gets the limit.
TEST(FrameWriter, AVideoCutByAFullDiskIsAnErrorAtClose) {
  namespace fs = std::filesystem;
  TempDir dir;
  const std::string path = dir.file("cut.avi");
  testing::WriteTextFile(path, "the previous run's video");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // As main() does: the write fails with EFBIG instead.
    constexpr rlim_t kLimitBytes = 200 * 1024;
    const rlimit limit{kLimitBytes, kLimitBytes};
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(3);
    cv::Mat image(480, 640, CV_8UC3);
    try {
      FrameWriter writer({path, "", 30.0});
      for (int i = 0; i < 10; ++i) {
        cv::randu(image, 0, 255);  // Noise: HuffYUV cannot shrink it, 10 frames pass the limit.
        writer.write(image, i);
      }
      writer.close();
    } catch (const InputError& e) {
      _exit(std::string(e.what()).find("cut.avi: the video holds") != std::string::npos ? 0 : 4);
    }
    _exit(5);  // Not noticed.
  }
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0);
  // The cut video never took the output's name: the older file is intact, no temporary is left.
  EXPECT_EQ(testing::ReadTextFile(path), "the previous run's video");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

// A video is written beside its output and renamed into place only when whole: a writer left by
// an exception (a run that failed mid-way) abandons its video and an older file of the name is
// left as it was; a finished one replaces it. No temporary file stays behind either way.
TEST(FrameWriter, AnOutputIsReplacedOnlyByAFinishedVideo) {
  namespace fs = std::filesystem;
  TempDir dir;
  const std::string path = dir.file("run.avi");
  testing::WriteTextFile(path, "the previous run's video");
  const std::vector<cv::Mat> frames = RenderedFrames();
  const auto files_in_folder = [&dir] {
    return std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator());
  };
  try {
    FrameWriter writer({path, "", 25.0});
    writer.write(frames[0], 0);
    writer.write(frames[1], 1);
    EXPECT_EQ(files_in_folder(), 2) << "the temporary file beside the output";
    EXPECT_EQ(testing::ReadTextFile(path), "the previous run's video") << "not touched yet";
    throw InputError("the run failed at frame 2");
  } catch (const InputError&) {
  }
  EXPECT_EQ(testing::ReadTextFile(path), "the previous run's video");
  EXPECT_EQ(files_in_folder(), 1);

  {
    FrameWriter writer({path, "", 25.0});
    for (size_t i = 0; i < frames.size(); ++i) writer.write(frames[i], static_cast<int64_t>(i));
    writer.close();
  }
  ExpectReadsBackBitExact(path, frames);
  EXPECT_EQ(files_in_folder(), 1);

  // A writer that made no frame makes no file.
  const std::string never = dir.file("never.avi");
  FrameWriter({never, "", 25.0}).close();
  EXPECT_FALSE(fs::exists(never));
  EXPECT_EQ(files_in_folder(), 1);
}

}  // namespace softsight
