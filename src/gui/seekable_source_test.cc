// The live window's seekable source on an image sequence whose numbering starts at 5: every
// frame it returns after a seek is the sequence's own (index from the file's number).
#include "gui/seekable_source.h"
#include "core/test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace softsight {
namespace {

namespace fs = std::filesystem;

TEST(SeekableSource, SeeksInAnImageSequenceKeepingItsFileNumbersInsideAndOutsideTheRing) {
  const testing::TempDir temp;
  const fs::path& dir = temp.path();
  for (int n = 5; n < 15; ++n) {
    // Each image's grey level says which file it is.
    cv::imwrite((dir / cv::format("f%d.png", n)).string(),
                cv::Mat(8, 8, CV_8UC3, cv::Scalar::all(n * 10)));
  }
  FrameSourceSpec spec;
  spec.input = (dir / "f%d.png").string();
  spec.sequence_fps = 10.0;
  SeekableSource source(OpenFrameSource(spec), [spec] { return OpenFrameSource(spec); },
                        3 * 8 * 8 * 3);  // A ring of 3 frames.
  Frame frame;
  const auto expect_file = [&](int n) {
    EXPECT_EQ(frame.index, n);
    EXPECT_NEAR(frame.time_s, (n - 5) / 10.0, 1e-9);
    EXPECT_EQ(frame.image.at<cv::Vec3b>(0, 0)[0], n * 10);
  };
  for (int n = 5; n < 10; ++n) {
    ASSERT_TRUE(source.read(frame));
    expect_file(n);
  }
  source.seek(3);  // In the ring (positions 2..4).
  ASSERT_TRUE(source.read(frame));
  expect_file(8);
  EXPECT_EQ(source.frames_decoded(), 5);
  source.seek(0);  // Behind the ring: the sequence's own seek, one file read.
  ASSERT_TRUE(source.read(frame));
  expect_file(5);
  EXPECT_EQ(source.frames_decoded(), 6);
  EXPECT_EQ(source.direct_seeks(), 1);
  EXPECT_FALSE(source.length());
  // To the count's last file, then checked: nothing follows. Within kReadThroughFrames of the
  // decoder, the files on the way are read (9 of them) rather than seeking.
  ASSERT_TRUE(source.seek_last());
  EXPECT_EQ(source.length(), 10);
  EXPECT_EQ(source.frames_decoded(), 15);
  EXPECT_EQ(source.direct_seeks(), 1);
  ASSERT_TRUE(source.read(frame));
  expect_file(14);
  EXPECT_FALSE(source.read(frame));
  source.seek(25);
  EXPECT_FALSE(source.read(frame));
}

// FFmpeg's own seek (through the container's index) is what makes a seek in a long file fast;
// OpenCV's CAP_PROP_POS_FRAMES is exact only with some containers and codecs, so this measures it
// for the ones a recording uses: after each seek, anywhere, forwards and back, the frame (pixels,
// index, time) is the one reading forward from the start gives, and it took one direct seek.
TEST(SeekableSource, AVideosOwnSeekShowsTheFrameReadingForwardShowsInEachLosslessContainer) {
  const fs::path dir = fs::temp_directory_path() / "softsight_seekable_video_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  struct Case {
    const char* file;
    const char* fourcc;
  };
  for (const Case& c : {Case{"huffyuv.avi", "HFYU"}, Case{"ffv1.avi", "FFV1"},
                        Case{"mjpg.avi", "MJPG"}, Case{"ffv1.mkv", "FFV1"}}) {
    SCOPED_TRACE(c.file);
    const std::string path = (dir / c.file).string();
    const int frames = 90;
    {
      cv::VideoWriter writer(path, cv::CAP_FFMPEG,
                             cv::VideoWriter::fourcc(c.fourcc[0], c.fourcc[1], c.fourcc[2],
                                                     c.fourcc[3]),
                             30.0, cv::Size(96, 64));
      ASSERT_TRUE(writer.isOpened());
      cv::Mat image(64, 96, CV_8UC3);
      cv::RNG rng(25);
      for (int i = 0; i < frames; ++i) {
        rng.fill(image, cv::RNG::UNIFORM, 0, 64);  // Noise, so frames near each other differ everywhere.
        cv::putText(image, std::to_string(i), {4, 40}, cv::FONT_HERSHEY_SIMPLEX, 1.0,
                    cv::Scalar(255, 255, 255), 2);
        writer.write(image);
      }
    }
    FrameSourceSpec spec;
    spec.input = path;
    std::vector<Frame> truth;
    {
      std::unique_ptr<FrameSource> forward = OpenFrameSource(spec);
      Frame frame;
      while (forward->read(frame)) truth.push_back({frame.image.clone(), frame.index, frame.time_s});
    }
    ASSERT_EQ(truth.size(), size_t{frames});
    SeekableSource source(OpenFrameSource(spec), [spec] { return OpenFrameSource(spec); },
                          2 * 96 * 64 * 3);  // A ring of 2: every seek below leaves it.
    Frame frame;
    int64_t seeks = 0;
    for (const int64_t target : {89, 0, 45, 17, 88, 30, 1, 60, 20, 75}) {
      source.seek(target);
      ASSERT_TRUE(source.read(frame)) << "frame " << target;
      EXPECT_EQ(source.direct_seeks(), ++seeks) << "frame " << target;
      const Frame& want = truth[static_cast<size_t>(target)];
      EXPECT_EQ(frame.index, want.index);
      EXPECT_NEAR(frame.time_s, want.time_s, 1e-9) << "frame " << target;
      EXPECT_EQ(cv::norm(frame.image, want.image, cv::NORM_INF), 0.0) << "frame " << target;
      if (target + 1 < frames) {  // And the one after it, read on.
        ASSERT_TRUE(source.read(frame));
        EXPECT_EQ(frame.index, target + 1);
        EXPECT_EQ(cv::norm(frame.image, truth[static_cast<size_t>(target + 1)].image,
                           cv::NORM_INF), 0.0);
      }
    }
    ASSERT_TRUE(source.seek_last());
    EXPECT_EQ(source.length(), frames);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace softsight
