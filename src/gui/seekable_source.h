// Internal to gui (and the tests). A file, image sequence or rendered scene that the live window
// can read from any position: the transport (step back, seek +-1 s, start, end, loop) of
// `softsight live`. Every frame it delivers is the wrapped source's own Frame, index and
// timestamp as that source numbers them, so rows after a seek still name the source's frames.
//
// How: the recently read frames are kept in a ring (a step back, or a second back, is a copy).
// A position outside it is reached by the wrapped source's own seek (FrameSource::seek_to: for a
// video FFmpeg's, through the container's index, decoding from the key frame before the target;
// measured exact for HuffYUV, FFV1 and MJPG in AVI and MKV, and 2-20 ms anywhere in a 10-minute
// 640x480 file: docs/measurements.md), else by reopening the source and reading forward to it,
// which is exact for every source but decodes everything before the target. The end is taken
// from the header's frame count, checked by reading its last frame and finding nothing after it.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "softsight/io/frame_source.h"

namespace softsight {

class SeekableSource : public FrameSource {
 public:
  using Opener = std::function<std::unique_ptr<FrameSource>()>;

  // `first`: the source opened (and checked) by the caller; `reopen`: opens the same input again
  // from its first frame. The ring holds as many frames as fit in `cache_bytes` (at least 2).
  SeekableSource(std::unique_ptr<FrameSource> first, Opener reopen,
                 size_t cache_bytes = size_t{192} << 20);

  // The frame at position(), then position() + 1. False at the end (position() is then the
  // length). Throws InputError as the wrapped source does.
  bool read(Frame& frame) override;

  // Position (0-based count from the first frame) of the frame the next read() returns.
  int64_t position() const { return position_; }
  // Makes `position` the next frame read() returns (clamped to 0; past the end, read() says end).
  void seek(int64_t position);
  // Makes the last frame the next one read() returns; false when the source has no frames.
  bool seek_last();
  // The number of frames, once the end has been reached.
  std::optional<int64_t> length() const { return length_; }

  std::string description() const override { return source_->description(); }
  std::optional<int64_t> frame_count() const override {
    return length_ ? length_ : source_->frame_count();
  }
  std::optional<double> fps() const override { return source_->fps(); }
  std::optional<std::string> note() const override { return source_->note(); }
  std::vector<std::string> files() const override { return source_->files(); }

  // Frames decoded from the wrapped source so far, reopenings included (for tests and --help's
  // figure of what a seek costs).
  int64_t frames_decoded() const { return decoded_total_; }
  // Positions reached by the wrapped source's own seek so far.
  int64_t direct_seeks() const { return direct_seeks_; }

 private:
  struct Slot {
    int64_t position = -1;  // -1: empty.
    Frame frame;
  };
  Slot* cached(int64_t position);
  void remember(int64_t position, const Frame& frame);
  bool decode_next(Frame& frame);  // The wrapped source's next frame (at decoded_).
  // Reopens the source and reads forward to `position`: the way that works for every source.
  bool read_forward_to(int64_t position, Frame& frame);

  // Up to this many frames ahead, reading on is as cheap as a seek (which decodes from a key
  // frame before the target up to it: OpenCV starts 16 frames before).
  static constexpr int64_t kReadThroughFrames = 16;

  std::unique_ptr<FrameSource> source_;
  Opener reopen_;
  size_t cache_bytes_;
  std::vector<Slot> ring_;  // Sized on the first frame.
  int64_t position_ = 0;    // Next frame to deliver.
  int64_t decoded_ = 0;     // Position of the wrapped source's next frame.
  int64_t decoded_total_ = 0;
  int64_t landed_ = -1;  // Where the last direct seek put the source, until its frame is read.
  int64_t direct_seeks_ = 0;
  std::optional<int64_t> length_;
  Frame scratch_;  // Frames read on the way to a seek target.
};

}  // namespace softsight
