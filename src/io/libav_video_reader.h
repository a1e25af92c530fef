// A video file decoded with FFmpeg the way OpenCV 4.6's FFmpeg reader (cv::VideoCapture with
// CAP_FFMPEG, modules/videoio/src/cap_ffmpeg_impl.hpp) decodes it, frame for frame and bit for
// bit, that also says of each frame whether its decoder concealed damage in it
// (AVFrame::decode_error_flags, which VideoCapture does not pass on).
//
// Why: for codecs that predict frames from earlier ones (H.264, MPEG-4) the decoder's word on
// damage is needed for every frame, and reading the frames through VideoCapture meant decoding
// the file a second time (io/decode_probe.h) only to learn it: about half again the decode's
// time and memory (issue 45). One decoder gives the frames, this mark and its log messages
// (io/decoder_log.h) here. With frame threads FFmpeg 5's mark can miss the frame handed out (its
// thread copied the picture before the mark was set): a mark is always true, but not every
// concealed frame has one; the decoder's "concealing ..." message always comes, a few frames
// early at most (frames_decoded_ahead()), and VideoFileSource counts it.
// What is kept as OpenCV has it, so that rows do not change:
// - the first video stream, FFmpeg's default decoder for it, one decoder thread per processor
//   (cv::getNumberOfCPUs(), at most 16, or $OPENCV_FFMPEG_THREADS), no hardware decoding;
// - the BGR picture: sws_scale to BGR24 with SWS_BICUBIC, sized by the decoder's coded size into
//   a 32-byte aligned buffer, of which the stream's width x height is copied out (or, where that
//   gives the same bytes, converted straight into the caller's Mat);
// - the frame's time (CAP_PROP_POS_MSEC): its pts (else its packet's dts) from the stream's
//   start, and 0 for a frame received without a packet sent (OpenCV 4.6 keeps no time for it);
// - when reading stops: the demuxer's end (the decoder drained), a packet the decoder refuses, or
//   one frame past the header's frame count;
// - a seek to a frame number (CAP_PROP_POS_FRAMES), by OpenCV's steps.
// Not kept: OpenCV's metadata rotation (a file that has one is read by VideoCapture) and its
// $OPENCV_FFMPEG_CAPTURE_OPTIONS.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

struct AVCodecContext;
struct AVFormatContext;
struct AVFrame;
struct AVPacket;
struct SwsContext;

namespace softsight {

class LibavVideoReader {
 public:
  // Opens `path`'s first video stream; opened() says whether FFmpeg could. With `wanted_tag`,
  // only a stream whose container's header names its codec by a tag (fourcc, not 0) that
  // `wanted_tag` accepts: any other is left closed after the header alone was read (no stream
  // probing, no decoder), so that a caller that reads other files another way pays little.
  explicit LibavVideoReader(const std::string& path, bool (*wanted_tag)(uint32_t) = nullptr);
  ~LibavVideoReader();
  LibavVideoReader(const LibavVideoReader&) = delete;
  LibavVideoReader& operator=(const LibavVideoReader&) = delete;

  bool opened() const { return codec_ != nullptr; }

  // What VideoCapture::get gives for the file (CAP_PROP_FRAME_COUNT, CAP_PROP_FPS,
  // CAP_PROP_FOURCC; CAP_PROP_ORIENTATION_META 0), where it surely is OpenCV's: the stream has a
  // codec tag (OpenCV's fourcc then is that tag) and neither a display matrix nor a "rotate" tag
  // (whose rotation OpenCV would report). So a caller needs no VideoCapture opened beside this
  // reader only for these figures (its open probes the stream and starts a decoder: 5 ms of CPU
  // at 640x480, 20 ms at 1080p, ~3 MB; issue 45).
  struct Header {
    double frame_count = 0.0;
    double fps = 0.0;
    uint32_t fourcc = 0;
  };
  std::optional<Header> unrotated_header() const;

  // VideoCapture::read: the next frame into `bgr` (CV_8UC3 of the stream's size; its buffer is
  // reused when it has that size already); false when there is none (see above).
  bool read(cv::Mat& bgr);
  // VideoCapture::grab: the next frame decoded, not converted.
  bool grab();
  // Whether the decoder concealed damage in the frame decoded last (its decode_error_flags, or
  // the frame flagged corrupt).
  bool concealed() const { return concealed_; }
  // How many frames past the one read last the decoder may have decoded (its frame threads, and
  // the frames it decodes before the ones shown before them: B-frames); its log messages of a
  // frame come this many frames early at most.
  int64_t frames_decoded_ahead() const;
  // CAP_PROP_POS_MSEC after that frame: its time stamp, in ms from the stream's start.
  double position_ms() const;
  // CAP_PROP_POS_FRAMES: the next read() returns frame `frame` (as OpenCV's seek finds it).
  void seek(int64_t frame);

 private:
  int64_t total_frames() const;
  double fps() const;
  double seconds(int64_t timestamp) const;
  int64_t frame_number_at(int64_t timestamp) const;

  AVFormatContext* format_ = nullptr;
  AVCodecContext* codec_ = nullptr;
  AVPacket* packet_ = nullptr;
  AVFrame* frame_ = nullptr;  // The decoded frame (reused: avcodec_receive_frame unrefs it).
  AVFrame* bgr_ = nullptr;    // The BGR24 picture of the coded size (allocated once).
  SwsContext* convert_ = nullptr;
  bool direct_ = false;  // Converts straight into read()'s Mat (see read()).
  int stream_ = -1;
  int width_ = 0, height_ = 0;  // The stream's size: the picture handed out.
  int64_t pts_;                 // The frame's time stamp (AV_NOPTS_VALUE: none).
  int64_t frame_number_ = 0;    // Frames decoded (OpenCV's frame_number).
  int64_t first_frame_number_ = -1;
  bool concealed_ = false;
};

}  // namespace softsight
