#include "io/decoder_log.h"

#include <algorithm>
#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <vector>

extern "C" {
#include <libavutil/log.h>
}

#include "softsight/core/error.h"

namespace softsight {
namespace {

std::atomic<uint64_t> g_error_count{0};
std::mutex g_last_error_mutex;
std::string g_last_error;
std::mutex g_ignored_mutex;
std::vector<const void*> g_ignored;  // A DecodeProbe's contexts: a few at most.

bool Ignored(const void* context) {
  std::lock_guard<std::mutex> lock(g_ignored_mutex);
  return std::find(g_ignored.begin(), g_ignored.end(), context) != g_ignored.end();
}

// FFmpeg's error concealment (libavcodec/error_resilience.c: H.264, MPEG-4, MPEG-2 ...) says
// "concealing N DC, N AC, N MV errors in P frame" at info level, exactly when it marks the frame
// concealed (decode_error_flags). With frame threads that mark is copied to another thread's
// picture before it is set and often never reaches the frame handed out (FFmpeg 5: H.264 with
// B-frames), while this message always comes, from the thread that conceals: it is counted.
bool ConcealmentMessage(int level, const char* format) {
  return level == AV_LOG_INFO && std::strncmp(format, "concealing ", 11) == 0;
}

extern "C" void OnDecoderLog(void* context, int level, const char* format, va_list args) {
  if ((level > AV_LOG_ERROR && !ConcealmentMessage(level, format)) || Ignored(context)) return;
  char text[256];
  std::vsnprintf(text, sizeof(text), format, args);
  std::string message = text;
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  // The component ("mjpeg", "ffv1") that logged it, as FFmpeg's own log line names it.
  AVClass* const* av_class = static_cast<AVClass* const*>(context);
  if (av_class != nullptr && *av_class != nullptr) {
    message = std::string((*av_class)->item_name(context)) + ": " + message;
  }
  {
    std::lock_guard<std::mutex> lock(g_last_error_mutex);
    g_last_error = EscapeForMessage(message, 160);
  }
  g_error_count.fetch_add(1);
}

}  // namespace

void CaptureDecoderErrors() {
  static std::once_flag installed;
  std::call_once(installed, [] { av_log_set_callback(OnDecoderLog); });
}

uint64_t DecoderErrorCount() { return g_error_count.load(); }

void IgnoreDecoderLogsFrom(const void* context, bool ignore) {
  std::lock_guard<std::mutex> lock(g_ignored_mutex);
  const auto found = std::find(g_ignored.begin(), g_ignored.end(), context);
  if (ignore && found == g_ignored.end()) g_ignored.push_back(context);
  if (!ignore && found != g_ignored.end()) g_ignored.erase(found);
}

std::string LastDecoderError() {
  std::lock_guard<std::mutex> lock(g_last_error_mutex);
  return g_last_error;
}

}  // namespace softsight
