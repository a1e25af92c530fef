#include "io/h264_writer.h"

#include <cstring>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
}

namespace softsight {
namespace {

// (Not `Check`: the io library is built in unity batches, where another file's helper of that
// name would clash.)
void CheckH264(int rc, const char* what) {
  if (rc < 0) {
    char text[128];
    av_strerror(rc, text, sizeof text);
    throw std::runtime_error(std::string(what) + ": " + text);
  }
}

}  // namespace

struct H264Writer::Context {
  AVFormatContext* format = nullptr;
  const AVCodec* codec = nullptr;
  AVStream* stream = nullptr;
  AVCodecContext* enc = nullptr;
  AVFrame* picture = nullptr;
  AVPacket* packet = nullptr;

  ~Context() {
    if (format != nullptr && format->pb != nullptr) avio_closep(&format->pb);
    av_packet_free(&packet);
    av_frame_free(&picture);
    avcodec_free_context(&enc);
    avformat_free_context(format);
  }
};

H264Writer::H264Writer(const std::string& path, const H264WriterOptions& options)
    : context_(std::make_unique<Context>()) {
  Context& c = *context_;
  CheckH264(avformat_alloc_output_context2(&c.format, nullptr, "mp4", path.c_str()), "output");
  c.codec = avcodec_find_encoder_by_name("libx264");
  if (c.codec == nullptr) c.codec = avcodec_find_encoder(AV_CODEC_ID_H264);
  if (c.codec == nullptr) throw std::runtime_error("no H.264 encoder in this FFmpeg");
  c.stream = avformat_new_stream(c.format, nullptr);
  c.enc = avcodec_alloc_context3(c.codec);
  if (c.stream == nullptr || c.enc == nullptr) throw std::runtime_error("out of memory");
  c.enc->width = options.size.width;
  c.enc->height = options.size.height;
  c.enc->pix_fmt = AV_PIX_FMT_YUV420P;
  c.enc->time_base = AVRational{1, options.fps};
  c.enc->framerate = AVRational{options.fps, 1};
  c.enc->gop_size = options.gop;
  c.enc->max_b_frames = options.max_b_frames;
  if (options.threads > 0) c.enc->thread_count = options.threads;
  if (c.format->oformat->flags & AVFMT_GLOBALHEADER) c.enc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  av_opt_set(c.enc->priv_data, "preset", "veryfast", 0);
  if (options.crf != nullptr) av_opt_set(c.enc->priv_data, "crf", options.crf, 0);
  CheckH264(avcodec_open2(c.enc, c.codec, nullptr), "encoder");
  CheckH264(avcodec_parameters_from_context(c.stream->codecpar, c.enc), "parameters");
  c.stream->time_base = c.enc->time_base;
  CheckH264(avio_open(&c.format->pb, path.c_str(), AVIO_FLAG_WRITE), path.c_str());
  CheckH264(avformat_write_header(c.format, nullptr), "header");

  c.picture = av_frame_alloc();
  if (c.picture == nullptr) throw std::runtime_error("out of memory");
  c.picture->format = AV_PIX_FMT_YUV420P;
  c.picture->width = options.size.width;
  c.picture->height = options.size.height;
  CheckH264(av_frame_get_buffer(c.picture, 0), "frame");
  c.packet = av_packet_alloc();
  if (c.packet == nullptr) throw std::runtime_error("out of memory");
}

H264Writer::~H264Writer() = default;

const char* H264Writer::encoder() const { return context_->codec->name; }

void H264Writer::write(const cv::Mat& bgr) {
  Context& c = *context_;
  const int w = c.enc->width, h = c.enc->height;
  if (bgr.type() != CV_8UC3 || bgr.cols != w || bgr.rows != h) {
    throw std::invalid_argument("H264Writer: a frame not of the size and type it was opened for");
  }
  cv::cvtColor(bgr, yuv_, cv::COLOR_BGR2YUV_I420);
  CheckH264(av_frame_make_writable(c.picture), "writable");
  // OpenCV's I420 is the three planes one after the other, rows unpadded; FFmpeg's rows are
  // padded to its own line sizes.
  for (int y = 0; y < h; ++y) {
    std::memcpy(c.picture->data[0] + y * c.picture->linesize[0], yuv_.ptr(y), w);
  }
  const uchar* u = yuv_.ptr(h);
  const uchar* v = u + (w / 2) * (h / 2);
  for (int y = 0; y < h / 2; ++y) {
    std::memcpy(c.picture->data[1] + y * c.picture->linesize[1], u + y * (w / 2), w / 2);
    std::memcpy(c.picture->data[2] + y * c.picture->linesize[2], v + y * (w / 2), w / 2);
  }
  c.picture->pts = frames_++;
  CheckH264(avcodec_send_frame(c.enc, c.picture), "encode");
  drain();
}

void H264Writer::finish() {
  Context& c = *context_;
  CheckH264(avcodec_send_frame(c.enc, nullptr), "flush");
  drain();
  CheckH264(av_write_trailer(c.format), "trailer");
  avio_closep(&c.format->pb);
}

// Every packet the encoder has ready, into the file (none may be ready yet: B-frames, threads).
void H264Writer::drain() {
  Context& c = *context_;
  while (avcodec_receive_packet(c.enc, c.packet) == 0) {
    av_packet_rescale_ts(c.packet, c.enc->time_base, c.stream->time_base);
    c.packet->stream_index = c.stream->index;
    CheckH264(av_interleaved_write_frame(c.format, c.packet), "write");
  }
}

}  // namespace softsight
