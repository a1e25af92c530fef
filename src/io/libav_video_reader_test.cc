// LibavVideoReader gives what cv::VideoCapture (CAP_FFMPEG) gives, frame for frame and bit for
// bit, with the same time stamps, count and seeks (io/libav_video_reader.h), and marks the frames
// its decoder concealed damage in.
#include "io/libav_video_reader.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/test_util.h"
#include "io/damaged_video_test_util.h"
#include "io/decode_probe.h"
#include "io/h264_writer.h"

namespace softsight {
namespace {

using testing::TempDir;

// A textured background and a disc moving 5 px per frame: every frame differs from the last.
cv::Mat MovingDisc(cv::Size size, int i) {
  cv::Mat frame(size, CV_8UC3);
  cv::RNG rng(3);
  rng.fill(frame, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(frame, frame, {0, 0}, 2);
  cv::circle(frame, {10 + 5 * i, size.height / 2}, size.height / 8, {30, 40, 230}, -1);
  return frame;
}

// `frames` frames as H.264 (libx264) in MP4, a key frame every `gop`, with B-frames (so the
// decoder reorders, and time stamps are the presentation's), as a phone or ffmpeg writes them.
// One encoder thread: libx264's output depends on its thread count, which by default follows the
// machine's processors, and the damage test flips bytes at fixed fractions of the file.
std::string WriteH264(const std::string& path, cv::Size size, int frames, int gop) {
  H264WriterOptions options;
  options.size = size;
  options.gop = gop;
  options.threads = 1;
  H264Writer writer(path, options);
  if (std::strcmp(writer.encoder(), "libx264") != 0) throw std::runtime_error("no libx264");
  for (int i = 0; i < frames; ++i) writer.write(MovingDisc(size, i));
  writer.finish();
  return path;
}

std::string WriteWithOpenCv(const std::string& path, const char* fourcc, cv::Size size,
                            int frames) {
  cv::VideoWriter writer(path, cv::CAP_FFMPEG,
                         cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]), 25.0,
                         size);
  EXPECT_TRUE(writer.isOpened());
  for (int i = 0; i < frames; ++i) writer << MovingDisc(size, i);
  return path;
}

// Reads `path` to its end through both readers, `seek_to` first when given; the same pictures
// (every byte), the same time stamps, the same count (`expected_frames` too, unless -1), no
// damage marked.
void ExpectSameAsVideoCapture(const std::string& path, int64_t expected_frames,
                              int64_t seek_to = -1) {
  LibavVideoReader reader(path);
  ASSERT_TRUE(reader.opened()) << path;
  cv::VideoCapture capture(path, cv::CAP_FFMPEG);
  ASSERT_TRUE(capture.isOpened()) << path;
  // The header's figures, where the reader gives them, are VideoCapture's (VideoFileSource then
  // opens no VideoCapture).
  if (const std::optional<LibavVideoReader::Header> header = reader.unrotated_header()) {
    EXPECT_EQ(header->frame_count, capture.get(cv::CAP_PROP_FRAME_COUNT)) << path;
    EXPECT_EQ(header->fps, capture.get(cv::CAP_PROP_FPS)) << path;
    EXPECT_EQ(header->fourcc, static_cast<uint32_t>(capture.get(cv::CAP_PROP_FOURCC))) << path;
    EXPECT_EQ(capture.get(cv::CAP_PROP_ORIENTATION_META), 0.0) << path;
  }
  if (seek_to >= 0) {
    reader.seek(seek_to);
    ASSERT_TRUE(capture.set(cv::CAP_PROP_POS_FRAMES, static_cast<double>(seek_to)));
  }
  cv::Mat ours, theirs;
  int64_t frames = 0;
  while (true) {
    const bool read = reader.read(ours);
    const bool captured = capture.read(theirs);
    ASSERT_EQ(read, captured) << path << " frame " << frames;
    if (!read) break;
    ASSERT_EQ(ours.type(), CV_8UC3);
    ASSERT_EQ(ours.size(), theirs.size()) << path << " frame " << frames;
    ASSERT_TRUE(ours.isContinuous());
    ASSERT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0.0) << path << " frame " << frames;
    ASSERT_EQ(reader.position_ms(), capture.get(cv::CAP_PROP_POS_MSEC))
        << path << " frame " << frames;
    EXPECT_FALSE(reader.concealed()) << path << " frame " << frames;
    ++frames;
  }
  if (expected_frames >= 0) {
    EXPECT_EQ(frames, expected_frames) << path;
  }
}

TEST(LibavVideoReader, GivesVideoCapturesFramesOfH264) {
  TempDir dir;
  // A macroblock-aligned size, one that is not (the conversion is sized by the coded size), and
  // 1080 rows (coded as 1088).
  for (const cv::Size size : {cv::Size(320, 240), cv::Size(330, 186), cv::Size(1920, 1080)}) {
    const int frames = size.width > 1000 ? 8 : 40;
    const std::string path = WriteH264(
        dir.file("clip_" + std::to_string(size.width) + ".mp4"), size, frames, 12);
    // OpenCV 4.6 may lose the last frame as its frame threads drain (330x186: 39 of 40), and
    // gives no time stamp (0 ms) to a frame that came out of the decoder without a packet sent:
    // the same here, so that `track` gives the same rows.
    ExpectSameAsVideoCapture(path, -1);
  }
}

TEST(LibavVideoReader, GivesVideoCapturesFramesOfMpeg4) {
  TempDir dir;
  for (const char* name : {"clip.mp4", "clip.avi"}) {
    ExpectSameAsVideoCapture(WriteWithOpenCv(dir.file(name), "mp4v", {320, 240}, 30), 30);
  }
}

// H.264 in MP4 and MPEG-4 in MP4 and AVI name their codec by a tag: the reader gives the header's
// figures (checked against VideoCapture's in ExpectSameAsVideoCapture), and opens such a file
// only when the tag is wanted; a file whose tag is not wanted is left closed.
TEST(LibavVideoReader, GivesTheHeaderOfAFileWhoseContainerTagsItsCodec) {
  TempDir dir;
  const auto capture_fps = [](const std::string& path) {
    return cv::VideoCapture(path, cv::CAP_FFMPEG).get(cv::CAP_PROP_FPS);
  };
  const std::string h264 = WriteH264(dir.file("clip.mp4"), {320, 240}, 20, 12);
  const std::string mpeg4 = WriteWithOpenCv(dir.file("clip.avi"), "mp4v", {320, 240}, 20);
  const std::string huffyuv = WriteWithOpenCv(dir.file("huffyuv.avi"), "HFYU", {320, 240}, 5);
  for (const std::string& path : {h264, mpeg4}) {
    LibavVideoReader reader(path, [](uint32_t tag) { return tag != 0; });
    ASSERT_TRUE(reader.opened()) << path;
    const std::optional<LibavVideoReader::Header> header = reader.unrotated_header();
    ASSERT_TRUE(header.has_value()) << path;
    EXPECT_EQ(header->frame_count, 20.0) << path;
    EXPECT_EQ(header->fps, capture_fps(path)) << path;
    ExpectSameAsVideoCapture(path, 20);
  }
  EXPECT_FALSE(LibavVideoReader(huffyuv, [](uint32_t tag) { return tag != 0x55594648; }).opened());
  EXPECT_TRUE(LibavVideoReader(huffyuv, [](uint32_t tag) { return tag == 0x55594648; }).opened());
}

TEST(LibavVideoReader, SeeksWhereVideoCaptureSeeks) {
  TempDir dir;
  const std::string h264 = WriteH264(dir.file("clip.mp4"), {320, 240}, 40, 12);
  const std::string mpeg4 = WriteWithOpenCv(dir.file("clip.avi"), "mp4v", {320, 240}, 40);
  for (const std::string& path : {h264, mpeg4}) {
    for (const int64_t to : {0, 1, 2, 11, 12, 13, 25, 39}) {
      SCOPED_TRACE(path + " seek to " + std::to_string(to));
      ExpectSameAsVideoCapture(path, -1, to);  // As many as VideoCapture reads after it.
    }
  }
}

TEST(LibavVideoReader, OpensNoFileThatIsNoVideo) {
  TempDir dir;
  EXPECT_FALSE(LibavVideoReader(dir.file("none.mp4")).opened());
  std::ofstream(dir.file("text.mp4")) << "not a video";
  LibavVideoReader text(dir.file("text.mp4"));
  EXPECT_FALSE(text.opened());
  cv::Mat image;
  EXPECT_FALSE(text.read(image));
}

// Bytes overwritten in the later key-frame groups: the file's frame source (which reads H.264
// through the reader) leaves out every frame the decoder concealed damage in (as a one-thread
// decode, DecodeProbe, marks them: with frame threads FFmpeg's own mark often misses the frame
// handed out, and the decoder's messages tell), reports them, and keeps the groups before. A
// frame the reader marks is one the decoder concealed damage in.
TEST(LibavVideoReader, FramesItsDecoderConcealedDamageInAreLeftOut) {
  TempDir dir;
  const std::string clean = WriteH264(dir.file("clean.mp4"), {320, 240}, 60, 12);
  std::string data = testing::ReadTextFile(clean);
  std::mt19937 random(11);
  for (int flip = 0; flip < 6; ++flip) {
    const size_t at = data.size() * 7 / 10 + random() % (data.size() / 10);
    data[at] = static_cast<char>(data[at] ^ 0x5a);
  }
  const std::string path = dir.file("damaged.mp4");
  std::ofstream(path, std::ios::binary)
      .write(data.data(), static_cast<std::streamsize>(data.size()));

  std::set<int64_t> marked, probed;
  {
    LibavVideoReader reader(path);
    cv::Mat image;
    for (int64_t i = 0; reader.read(image); ++i) {
      if (reader.concealed()) marked.insert(i);
    }
    DecodeProbe probe(path);
    for (int64_t i = 0;; ++i) {
      const std::optional<bool> concealed = probe.concealed(i);
      if (!concealed) break;
      if (*concealed) probed.insert(i);
    }
  }
  ASSERT_FALSE(probed.empty()) << "these flips no longer upset the decoder: choose others";
  for (const int64_t i : marked) EXPECT_EQ(probed.count(i), 1u) << "frame " << i;
  for (int run = 0; run < 3; ++run) {
    std::string report;
    const std::vector<int64_t> indices = testing::ReadExpectingDamageLeftOut(path, probed, &report);
    EXPECT_THAT(report, ::testing::HasSubstr(path));
    // The first groups, before the damage, are read.
    for (int64_t i = 0; i < 24 && i < *probed.begin(); ++i) {
      EXPECT_EQ(std::count(indices.begin(), indices.end(), i), 1) << "frame " << i;
    }
  }
}

}  // namespace
}  // namespace softsight
