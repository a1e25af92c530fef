#include "io/decode_probe.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}

#include "io/decoder_log.h"
#include "io/jpeg_scan.h"

namespace softsight {
namespace {

// FFmpeg's objects, freed however the probe ends.
struct Demuxer {
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  ~Demuxer() {
    if (format != nullptr) IgnoreDecoderLogsFrom(format, false);
    if (codec != nullptr) IgnoreDecoderLogsFrom(codec, false);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    avformat_close_input(&format);
  }
};

}  // namespace

DecodeProbe::DecodeProbe(const std::string& path) : thread_([this, path] { run(path); }) {}

DecodeProbe::~DecodeProbe() {
  stop_ = true;
  thread_.join();
}

std::optional<bool> DecodeProbe::concealed(int64_t index) {
  if (index < 0) return std::nullopt;
  std::unique_lock<std::mutex> lock(mutex_);
  progressed_.wait(lock, [&] { return ended_ || static_cast<int64_t>(concealed_.size()) > index; });
  if (static_cast<int64_t>(concealed_.size()) <= index) return std::nullopt;
  return concealed_[static_cast<size_t>(index)];
}

void DecodeProbe::check_jpeg_packets(AVFormatContext* format, AVPacket* packet, int stream) {
  JpegScanCheck check;
  while (!stop_ && av_read_frame(format, packet) >= 0) {
    if (packet->stream_index == stream) {
      const bool damaged =
          check.check(packet->data, static_cast<size_t>(packet->size)) ==
          JpegScanCheck::Verdict::kDamaged;
      std::lock_guard<std::mutex> lock(mutex_);
      concealed_.push_back(damaged);
      progressed_.notify_all();
    }
    av_packet_unref(packet);
  }
}

void DecodeProbe::run(const std::string& path) {
  CaptureDecoderErrors();
  {
    Demuxer d;
    d.format = avformat_alloc_context();
    if (d.format != nullptr) IgnoreDecoderLogsFrom(d.format, true);
    // On failure avformat_open_input frees the context (and sets it to null).
    const bool opened = d.format != nullptr &&
                        avformat_open_input(&d.format, path.c_str(), nullptr, nullptr) == 0 &&
                        avformat_find_stream_info(d.format, nullptr) >= 0;
    const int stream =
        opened ? av_find_best_stream(d.format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0) : -1;
    const AVCodec* decoder =
        stream >= 0 ? avcodec_find_decoder(d.format->streams[stream]->codecpar->codec_id) : nullptr;
    if (decoder != nullptr) d.codec = avcodec_alloc_context3(decoder);
    if (d.codec != nullptr) IgnoreDecoderLogsFrom(d.codec, true);
    d.packet = av_packet_alloc();
    d.frame = av_frame_alloc();
    // Each MJPEG packet is one whole JPEG, and its decoder conceals a desynchronised scan
    // without a mark: the packets' entropy-coded data is checked instead of decoded.
    const bool jpeg_packets = decoder != nullptr && decoder->id == AV_CODEC_ID_MJPEG;
    if (jpeg_packets && d.packet != nullptr) check_jpeg_packets(d.format, d.packet, stream);
    bool ok = !jpeg_packets && d.codec != nullptr && d.packet != nullptr && d.frame != nullptr &&
              avcodec_parameters_to_context(d.codec, d.format->streams[stream]->codecpar) >= 0;
    if (ok) {
      d.codec->thread_count = 1;  // Each mark belongs to its frame, the same in every run.
      // The marks come from parsing each frame's slices, not from its pixels: the deblocking
      // filter (about a fifth of an H.264 decoding) changes no mark, so the probe skips it.
      d.codec->skip_loop_filter = AVDISCARD_ALL;
      ok = avcodec_open2(d.codec, decoder, nullptr) == 0;
    }
    bool draining = false;
    while (ok && !stop_) {
      if (!draining) {
        const int read = av_read_frame(d.format, d.packet);
        if (read < 0) {
          draining = true;
          avcodec_send_packet(d.codec, nullptr);
        } else {
          if (d.packet->stream_index == stream) avcodec_send_packet(d.codec, d.packet);
          av_packet_unref(d.packet);
        }
      }
      int received = 0;
      while ((received = avcodec_receive_frame(d.codec, d.frame)) == 0) {
        const bool concealed =
            d.frame->decode_error_flags != 0 || (d.frame->flags & AV_FRAME_FLAG_CORRUPT) != 0;
        av_frame_unref(d.frame);
        std::lock_guard<std::mutex> lock(mutex_);
        concealed_.push_back(concealed);
        progressed_.notify_all();
      }
      if (draining && received != AVERROR(EAGAIN)) break;  // AVERROR_EOF: all frames are out.
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ended_ = true;
  progressed_.notify_all();
}

}  // namespace softsight
