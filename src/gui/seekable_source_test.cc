// The live window's seekable source on an image sequence whose numbering starts at 5: every
// frame it returns after a seek is the sequence's own (index from the file's number).
#include "gui/seekable_source.h"
#include "core/test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

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
  source.seek(0);  // Behind the ring: read again from the first file.
  ASSERT_TRUE(source.read(frame));
  expect_file(5);
  EXPECT_EQ(source.frames_decoded(), 6);
  EXPECT_FALSE(source.length());
  ASSERT_TRUE(source.seek_last());
  EXPECT_EQ(source.length(), 10);
  ASSERT_TRUE(source.read(frame));
  expect_file(14);
  EXPECT_FALSE(source.read(frame));
  source.seek(25);
  EXPECT_FALSE(source.read(frame));
}

}  // namespace
}  // namespace softsight
