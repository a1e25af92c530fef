// softsight_h264_clip INPUT OUTPUT.mp4 [GOP]: re-encodes a video (any the program reads, e.g. one
// `softsight synth` rendered) as H.264 in MP4 with a key frame every GOP frames (default 250,
// FFmpeg's libx264 default, as a phone, a webcam's software or `ffmpeg -i x.avi y.mp4` writes it).
// For scripts/bench.sh (issue 45: `track` on H.264 beside a bare decode of the same file): OpenCV's
// writer has no H.264 key-frame interval setting in 4.6 (it writes a key frame every 12 frames),
// and Debian's OpenCV is all the project builds on. A benchmark tool: not installed, not tested.
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
}

#include "softsight/io/frame_source.h"

namespace {

void Check(int rc, const char* what) {
  if (rc < 0) {
    char text[128];
    av_strerror(rc, text, sizeof text);
    throw std::runtime_error(std::string(what) + ": " + text);
  }
}

int Main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: softsight_h264_clip INPUT OUTPUT.mp4 [GOP]\n";
    return 2;
  }
  const std::string output = argv[2];
  const int gop = argc > 3 ? std::atoi(argv[3]) : 250;
  std::unique_ptr<softsight::FrameSource> source = softsight::OpenFrameSource({argv[1], {}, 30.0});
  const double fps = source->fps().value_or(30.0);
  softsight::Frame frame;
  if (!source->read(frame)) throw std::runtime_error("no frames");
  const int w = frame.image.cols & ~1, h = frame.image.rows & ~1;

  AVFormatContext* format = nullptr;
  Check(avformat_alloc_output_context2(&format, nullptr, "mp4", output.c_str()), "output");
  const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
  if (!codec) codec = avcodec_find_encoder(AV_CODEC_ID_H264);
  if (!codec) throw std::runtime_error("no H.264 encoder in this FFmpeg");
  AVStream* stream = avformat_new_stream(format, nullptr);
  AVCodecContext* enc = avcodec_alloc_context3(codec);
  enc->width = w;
  enc->height = h;
  enc->pix_fmt = AV_PIX_FMT_YUV420P;
  enc->time_base = AVRational{1, static_cast<int>(fps + 0.5)};
  enc->framerate = AVRational{static_cast<int>(fps + 0.5), 1};
  enc->gop_size = gop;
  enc->max_b_frames = 2;
  if (format->oformat->flags & AVFMT_GLOBALHEADER) enc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  av_opt_set(enc->priv_data, "preset", "veryfast", 0);
  av_opt_set(enc->priv_data, "crf", "20", 0);
  Check(avcodec_open2(enc, codec, nullptr), "encoder");
  Check(avcodec_parameters_from_context(stream->codecpar, enc), "parameters");
  stream->time_base = enc->time_base;
  Check(avio_open(&format->pb, output.c_str(), AVIO_FLAG_WRITE), output.c_str());
  Check(avformat_write_header(format, nullptr), "header");

  AVFrame* picture = av_frame_alloc();
  picture->format = AV_PIX_FMT_YUV420P;
  picture->width = w;
  picture->height = h;
  Check(av_frame_get_buffer(picture, 0), "frame");
  AVPacket* packet = av_packet_alloc();
  const auto drain = [&] {
    while (avcodec_receive_packet(enc, packet) == 0) {
      av_packet_rescale_ts(packet, enc->time_base, stream->time_base);
      packet->stream_index = stream->index;
      Check(av_interleaved_write_frame(format, packet), "write");
    }
  };
  cv::Mat yuv;
  int64_t n = 0;
  do {
    cv::cvtColor(frame.image(cv::Rect(0, 0, w, h)), yuv, cv::COLOR_BGR2YUV_I420);
    Check(av_frame_make_writable(picture), "writable");
    for (int y = 0; y < h; ++y) {
      std::memcpy(picture->data[0] + y * picture->linesize[0], yuv.ptr(y), w);
    }
    const uchar* u = yuv.ptr(h);
    const uchar* v = u + (w / 2) * (h / 2);
    for (int y = 0; y < h / 2; ++y) {
      std::memcpy(picture->data[1] + y * picture->linesize[1], u + y * (w / 2), w / 2);
      std::memcpy(picture->data[2] + y * picture->linesize[2], v + y * (w / 2), w / 2);
    }
    picture->pts = n++;
    Check(avcodec_send_frame(enc, picture), "encode");
    drain();
  } while (source->read(frame));
  Check(avcodec_send_frame(enc, nullptr), "flush");
  drain();
  Check(av_write_trailer(format), "trailer");
  avio_closep(&format->pb);
  av_packet_free(&packet);
  av_frame_free(&picture);
  avcodec_free_context(&enc);
  avformat_free_context(format);
  std::printf("%s: %lld frames %dx%d, H.264 (%s), a key frame every %d\n", output.c_str(),
              static_cast<long long>(n), w, h, codec->name, gop);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "softsight_h264_clip: " << e.what() << "\n";
    return 1;
  }
}
