// FFmpeg's decoders say when a frame's data is broken ("huffman table decode error", "overread
// 8") only through av_log, which OpenCV's VideoCapture neither returns nor exposes. This captures
// those messages for the video sources instead of letting them print mid-progress-bar, so a frame
// the decoder complained about is known as damaged. (Which frame a complaint belongs to is
// uncertain when the decoder runs frame threads; io/decode_probe.h gives exact per-frame marks.)
#pragma once

#include <cstdint>
#include <string>

namespace softsight {

// Installs the capturing av_log callback (once per process; later calls do nothing). Messages
// at error level or worse are counted, and error concealment's "concealing ... errors in P frame"
// (info level: the frame was concealed); all others are dropped, as OpenCV's AV_LOG_ERROR level
// did.
void CaptureDecoderErrors();

// How many error messages the decoders have logged so far in this process (any thread: FFmpeg's
// frame threads log from their own). A rise across one VideoCapture::read() marks that frame.
uint64_t DecoderErrorCount();

// The last error message (one line, escaped), for reports.
std::string LastDecoderError();

// Messages logged with `context` (an AVFormatContext or AVCodecContext of a DecodeProbe) are not
// counted (ignore = true) from now on, or counted again (false, before the context is freed).
void IgnoreDecoderLogsFrom(const void* context, bool ignore);

}  // namespace softsight
