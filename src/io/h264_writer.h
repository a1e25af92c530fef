// BGR frames encoded as H.264 in MP4 with FFmpeg (libx264 where the build has it), with a chosen
// key-frame interval and B-frames, as a phone or `ffmpeg -i x.avi y.mp4` writes them. Not part of
// the installed API: for the tests that need such files (libav_video_reader_test.cc) and
// softsight_h264_clip (scripts/bench.sh).
//
// Why not OpenCV's writer: OpenCV 4.6 (Debian's, all the project builds on) sets neither the
// key-frame interval (it writes a key frame every 12 frames) nor B-frames, and long groups and a
// decoder that reorders are what these files are for.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

namespace softsight {

struct H264WriterOptions {
  cv::Size size;  // Every frame's size; even (4:2:0 chroma).
  int fps = 30;
  int gop = 250;  // A key frame every `gop` frames (libx264's default).
  int max_b_frames = 2;
  int threads = 0;            // Encoder threads; 0 leaves the choice to FFmpeg.
  const char* crf = nullptr;  // libx264's constant rate factor; null keeps its default (23).
};

class H264Writer {
 public:
  // Creates `path` and writes its header. Throws std::runtime_error, with FFmpeg's reason, when
  // the build has no H.264 encoder or the file cannot be written.
  H264Writer(const std::string& path, const H264WriterOptions& options);
  // Frees the encoder; the file is complete only if finish() was called.
  ~H264Writer();
  H264Writer(const H264Writer&) = delete;
  H264Writer& operator=(const H264Writer&) = delete;

  // Encodes one CV_8UC3 frame of options.size (a view into a larger image is fine). The YUV
  // conversion's buffer is kept from frame to frame.
  void write(const cv::Mat& bgr);
  // Drains the encoder and writes the trailer; nothing may be written after.
  void finish();

  // The encoder's name: "libx264", or FFmpeg's default H.264 encoder where there is no libx264.
  const char* encoder() const;
  int64_t frames() const { return frames_; }

 private:
  struct Context;
  void drain();

  std::unique_ptr<Context> context_;
  cv::Mat yuv_;
  int64_t frames_ = 0;
};

}  // namespace softsight
