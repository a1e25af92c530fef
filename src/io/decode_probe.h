// FFmpeg's decoders mark each frame whose damage they had to conceal (AVFrame's
// decode_error_flags), but OpenCV's VideoCapture does not pass the mark on, and its frame
// threads log their complaints a few frames away from the frame they belong to (and differently
// from run to run). A DecodeProbe decodes the same file a second time, on its own thread, with
// one decoder thread and nothing but those marks kept: for every frame, in the order the decoder
// returns them, whether it was concealed. The same file gives the same marks every time, and a
// damaged key frame the decoder concealed without a word in the log is marked too.
//
// For codecs that predict frames from earlier ones (MPEG-4, H.264), where one damaged frame
// spoils every frame up to the next key frame; it costs a second decoding of the file (on
// another core), no images. Its own log messages are not counted as the reader's
// (decoder_log.h). And for Motion JPEG, whose decoder marks nothing when a flipped bit
// desynchronised a frame's Huffman codes (the picture shifted by an MCU from there on): its
// packets are not decoded but their entropy-coded data checked (io/jpeg_scan.h), which costs
// about a tenth of a decoding, on another core.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

struct AVFormatContext;
struct AVPacket;

namespace softsight {

class DecodeProbe {
 public:
  // Starts decoding `path` on the probe's thread.
  explicit DecodeProbe(const std::string& path);
  // Stops the thread between two packets.
  ~DecodeProbe();
  DecodeProbe(const DecodeProbe&) = delete;
  DecodeProbe& operator=(const DecodeProbe&) = delete;

  // Whether the decoder concealed damage in frame `index` (counted from 0 in the order the
  // decoder returns frames); waits for the probe to get there. Nothing when the probe cannot
  // say: it could not open the file, or the file ended (or broke off) before that frame.
  std::optional<bool> concealed(int64_t index);

 private:
  void run(const std::string& path);
  // Marks each packet of `stream` whose JPEG data JpegScanCheck finds damaged.
  void check_jpeg_packets(AVFormatContext* format, AVPacket* packet, int stream);

  std::mutex mutex_;
  std::condition_variable progressed_;
  std::vector<bool> concealed_;  // Per frame decoded so far.
  bool ended_ = false;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace softsight
