#include "io/libav_video_reader.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>

#include <opencv2/core/utility.hpp>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libswscale/swscale.h>
}

namespace softsight {
namespace {

double ToDouble(AVRational r) {
  return r.num == 0 || r.den == 0 ? 0.0 : static_cast<double>(r.num) / static_cast<double>(r.den);
}

// OpenCV's decoder threads (fill_codec_context): one per processor, at most 16 (more is not
// recommended by FFmpeg), or $OPENCV_FFMPEG_THREADS. With as many threads as the bare
// VideoCapture decode, this decode is as fast (and H.264's frame threads give the same pictures
// with any count).
int DecoderThreads() {
  if (const char* threads = std::getenv("OPENCV_FFMPEG_THREADS")) return std::atoi(threads);
  return std::min(cv::getNumberOfCPUs(), 16);
}

}  // namespace

LibavVideoReader::LibavVideoReader(const std::string& path, bool (*wanted_tag)(uint32_t))
    : pts_(AV_NOPTS_VALUE) {
  format_ = avformat_alloc_context();
  if (format_ == nullptr) return;
  // On failure avformat_open_input frees the context (and sets it to null).
  if (avformat_open_input(&format_, path.c_str(), nullptr, nullptr) != 0) return;
  if (wanted_tag != nullptr) {
    // The header's streams (AVI, MP4, MKV list theirs there): the first video one's tag.
    uint32_t tag = 0;
    for (unsigned i = 0; i < format_->nb_streams; ++i) {
      if (format_->streams[i]->codecpar->codec_type == AVMEDIA_TYPE_VIDEO) {
        tag = format_->streams[i]->codecpar->codec_tag;
        break;
      }
    }
    if (tag == 0 || !wanted_tag(tag)) return;
  }
  if (avformat_find_stream_info(format_, nullptr) < 0) return;
  // OpenCV takes the first video stream (not av_find_best_stream's choice).
  for (unsigned i = 0; i < format_->nb_streams; ++i) {
    if (format_->streams[i]->codecpar->codec_type == AVMEDIA_TYPE_VIDEO) {
      stream_ = static_cast<int>(i);
      break;
    }
  }
  if (stream_ < 0) return;
  const AVCodecParameters* parameters = format_->streams[stream_]->codecpar;
  const AVCodec* decoder = avcodec_find_decoder(parameters->codec_id);
  if (decoder == nullptr) return;
  AVCodecContext* codec = avcodec_alloc_context3(decoder);
  if (codec == nullptr) return;
  codec->thread_count = DecoderThreads();
  if (avcodec_parameters_to_context(codec, parameters) < 0 ||
      avcodec_open2(codec, decoder, nullptr) < 0) {
    avcodec_free_context(&codec);
    return;
  }
  // As OpenCV: the stream's size stands (a decoder may change it while opening, e.g. vp6f).
  if (parameters->width != 0 && codec->width != parameters->width) codec->width = parameters->width;
  if (parameters->height != 0 && codec->height != parameters->height) {
    codec->height = parameters->height;
  }
  width_ = parameters->width;
  height_ = parameters->height;
  packet_ = av_packet_alloc();
  frame_ = av_frame_alloc();
  bgr_ = av_frame_alloc();
  if (packet_ == nullptr || frame_ == nullptr || bgr_ == nullptr) {
    avcodec_free_context(&codec);
    return;
  }
  codec_ = codec;
}

LibavVideoReader::~LibavVideoReader() {
  sws_freeContext(convert_);
  av_frame_free(&bgr_);
  av_frame_free(&frame_);
  av_packet_free(&packet_);
  avcodec_free_context(&codec_);
  avformat_close_input(&format_);
}

// OpenCV's grabFrame, step for step (its limits on packets of other streams and on failed
// decodes included), and the frame's damage mark.
bool LibavVideoReader::grab() {
  if (codec_ == nullptr) return false;
  const AVStream* stream = format_->streams[stream_];
  if (stream->nb_frames > 0 && frame_number_ > stream->nb_frames) return false;
  pts_ = AV_NOPTS_VALUE;
  constexpr size_t kMaxReadAttempts = 4096, kMaxDecodeAttempts = 64;
  size_t read_attempts = 0, decode_attempts = 0;
  // A frame still in the decoder from the packet sent last.
  bool valid = avcodec_receive_frame(codec_, frame_) >= 0;
  while (!valid) {
    av_packet_unref(packet_);
    int ret = av_read_frame(format_, packet_);
    if (ret == AVERROR(EAGAIN)) continue;
    if (ret == AVERROR_EOF) {
      // Flushes the frames the decoder holds (an empty packet).
      packet_->data = nullptr;
      packet_->size = 0;
      packet_->stream_index = stream_;
    }
    if (packet_->stream_index != stream_) {
      av_packet_unref(packet_);
      if (++read_attempts > kMaxReadAttempts) break;
      continue;
    }
    if (avcodec_send_packet(codec_, packet_) < 0) break;
    ret = avcodec_receive_frame(codec_, frame_);
    if (ret >= 0) {
      // OpenCV 4.6 takes the time stamp here only: a frame the decoder still held from an earlier
      // packet (drained at the end of the stream) has none (CAP_PROP_POS_MSEC 0).
      pts_ = frame_->pts != AV_NOPTS_VALUE && frame_->pts != 0 ? frame_->pts : frame_->pkt_dts;
      valid = true;
    } else if (ret != AVERROR(EAGAIN)) {
      if (++decode_attempts > kMaxDecodeAttempts) break;
    }
  }
  if (!valid) return false;
  ++frame_number_;
  if (first_frame_number_ < 0) first_frame_number_ = frame_number_at(pts_);
  concealed_ = frame_->decode_error_flags != 0 || (frame_->flags & AV_FRAME_FLAG_CORRUPT) != 0;
  return true;
}

// OpenCV's retrieveFrame and VideoCapture's copy out of its buffer (or, where that gives the
// same bytes, the conversion straight into `bgr`).
bool LibavVideoReader::read(cv::Mat& bgr) {
  if (!grab() || frame_->data[0] == nullptr) return false;
  if (convert_ == nullptr) {
    // Sized by the coded size (OpenCV: "some sws_scale optimizations have some assumptions about
    // alignment of data/step/width/height"): the same size selects the same conversion code, so
    // the same bytes. Made once, from the first frame, as OpenCV does.
    const int width = codec_->coded_width, height = codec_->coded_height;
    convert_ = sws_getCachedContext(nullptr, width, height,
                                    static_cast<AVPixelFormat>(frame_->format), width, height,
                                    AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr, nullptr);
    if (convert_ == nullptr) return false;
    bgr_->format = AV_PIX_FMT_BGR24;
    bgr_->width = width;
    bgr_->height = height;
    if (av_frame_get_buffer(bgr_, 32) != 0) {
      sws_freeContext(convert_);
      convert_ = nullptr;
      return false;
    }
    // 8-bit 4:2:0 (H.264's and MPEG-4's usual format) of the same size goes through swscale's
    // unscaled YUV -> RGB converter, which writes each of the slice's rows and nothing else: into
    // rows of the same length (the coded width is the width, and the aligned buffer's rows have
    // no padding), the same bytes, without the copy (6 MB a 1080p frame). Any other format may
    // go through the scaler, whose last rows of a slice shorter than the coded height are left
    // as they were in OpenCV's buffer: that buffer is kept.
    direct_ = frame_->format == AV_PIX_FMT_YUV420P && width == width_ &&
              bgr_->linesize[0] == width_ * 3;
  }
  if (direct_ && frame_->format == AV_PIX_FMT_YUV420P && frame_->height == height_) {
    bgr.create(height_, width_, CV_8UC3);
    if (bgr.isContinuous()) {
      uint8_t* rows[4] = {bgr.data, nullptr, nullptr, nullptr};
      const int steps[4] = {width_ * 3, 0, 0, 0};
      sws_scale(convert_, frame_->data, frame_->linesize, 0, frame_->height, rows, steps);
      return true;
    }
  }
  sws_scale(convert_, frame_->data, frame_->linesize, 0, frame_->height, bgr_->data,
            bgr_->linesize);
  cv::Mat(height_, width_, CV_8UC3, bgr_->data[0], static_cast<size_t>(bgr_->linesize[0]))
      .copyTo(bgr);
  return true;
}

std::optional<LibavVideoReader::Header> LibavVideoReader::unrotated_header() const {
  if (codec_ == nullptr) return std::nullopt;
  AVStream* stream = format_->streams[stream_];
  // OpenCV 4.6's CAP_PROP_FOURCC is the codec tag when there is one (else a name it looks up).
  const uint32_t tag = stream->codecpar->codec_tag;
  if (tag == 0) return std::nullopt;
  // Its rotation comes from the display matrix (or, with older FFmpeg, the "rotate" tag).
  if (av_stream_get_side_data(stream, AV_PKT_DATA_DISPLAYMATRIX, nullptr) != nullptr ||
      av_dict_get(stream->metadata, "rotate", nullptr, 0) != nullptr) {
    return std::nullopt;
  }
  // OpenCV 4.6's get_fps(): the stream's average frame rate (its fallback, when that is 0, is
  // left to VideoCapture), and get_total_frames(): the header's count, else the duration times
  // that rate.
  constexpr double kEpsZero = 0.000025;  // OpenCV's eps_zero.
  const double fps = ToDouble(stream->avg_frame_rate);
  if (fps < kEpsZero) return std::nullopt;
  int64_t frames = stream->nb_frames;
  if (frames == 0) {
    double duration = static_cast<double>(format_->duration) / AV_TIME_BASE;
    if (duration < kEpsZero) {
      duration = static_cast<double>(stream->duration) * ToDouble(stream->time_base);
    }
    frames = static_cast<int64_t>(std::floor(duration * fps + 0.5));
  }
  Header header;
  header.frame_count = static_cast<double>(frames);
  header.fps = fps;
  header.fourcc = tag;
  return header;
}

int64_t LibavVideoReader::frames_decoded_ahead() const {
  if (codec_ == nullptr) return 0;
  return std::max(codec_->thread_count - 1, 0) + std::max(codec_->has_b_frames, 0);
}

double LibavVideoReader::position_ms() const {
  if (codec_ == nullptr || pts_ == AV_NOPTS_VALUE) return 0.0;
  return seconds(pts_) * 1000.0;
}

int64_t LibavVideoReader::total_frames() const {
  const AVStream* stream = format_->streams[stream_];
  if (stream->nb_frames != 0) return stream->nb_frames;
  double duration = static_cast<double>(format_->duration) / AV_TIME_BASE;
  if (duration < 0.000025) {
    duration = static_cast<double>(stream->duration) * ToDouble(stream->time_base);
  }
  return static_cast<int64_t>(std::floor(duration * fps() + 0.5));
}

double LibavVideoReader::fps() const {
  return ToDouble(av_guess_frame_rate(format_, format_->streams[stream_], nullptr));
}

double LibavVideoReader::seconds(int64_t timestamp) const {
  const AVStream* stream = format_->streams[stream_];
  return static_cast<double>(timestamp - stream->start_time) * ToDouble(stream->time_base);
}

int64_t LibavVideoReader::frame_number_at(int64_t timestamp) const {
  return static_cast<int64_t>(fps() * seconds(timestamp) + 0.5);
}

// OpenCV's seek(int64_t): to the key frame before a point `delta` frames ahead of the target
// (further back while that lands past it), then grabbing forward by the frames' time stamps.
void LibavVideoReader::seek(int64_t target) {
  if (codec_ == nullptr) return;
  const AVStream* stream = format_->streams[stream_];
  target = std::min(target, total_frames());
  int delta = 16;
  if (first_frame_number_ < 0 && total_frames() > 1) grab();
  while (true) {
    const int64_t from = std::max<int64_t>(target - delta, 0);
    const double sec = static_cast<double>(from) / fps();
    int64_t timestamp = stream->start_time;
    timestamp += static_cast<int64_t>(sec / ToDouble(stream->time_base) + 0.5);
    if (total_frames() > 1) av_seek_frame(format_, stream_, timestamp, AVSEEK_FLAG_BACKWARD);
    avcodec_flush_buffers(codec_);
    if (target <= 0) {
      frame_number_ = 0;
      break;
    }
    grab();
    if (target == 1) {
      frame_number_ = 1;
      break;
    }
    frame_number_ = frame_number_at(pts_) - first_frame_number_;
    if (frame_number_ < 0 || frame_number_ > target - 1) {
      if (from == 0 || delta >= INT_MAX / 4) break;
      delta = delta < 16 ? delta * 2 : delta * 3 / 2;
      continue;
    }
    while (frame_number_ < target - 1) {
      if (!grab()) break;
    }
    ++frame_number_;
    break;
  }
}

}  // namespace softsight
