#include "app/progress.h"

#include <unistd.h>

#include <cstdio>

namespace softsight {

ProgressBar::ProgressBar(std::string label, std::optional<int64_t> total, bool enabled)
    : label_(std::move(label)), total_(total), enabled_(enabled),
      terminal_(isatty(STDERR_FILENO) != 0), start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

void ProgressBar::update(int64_t done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed_s > 0 ? done / elapsed_s : 0.0;
  if (!terminal_) {
    if (!total_ || *total_ <= 0) return;
    const int quarter = static_cast<int>(4 * done / *total_);
    if (quarter > last_quarter_ && quarter < 4) {
      last_quarter_ = quarter;
      std::fprintf(stderr, "%s: %lld/%lld frames (%d%%), %.0f fps\n", label_.c_str(),
                   static_cast<long long>(done), static_cast<long long>(*total_), 25 * quarter,
                   rate);
    }
    return;
  }
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  if (total_ && *total_ > 0) {
    constexpr int kWidth = 30;
    const double fraction = std::min(1.0, static_cast<double>(done) / *total_);
    const int filled = static_cast<int>(fraction * kWidth);
    char bar[kWidth + 1];
    for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '=' : (i == filled ? '>' : ' ');
    bar[kWidth] = '\0';
    const double eta_s = rate > 0 ? (*total_ - done) / rate : 0.0;
    std::fprintf(stderr, "\r%s [%s] %lld/%lld  %.0f fps  ETA %.0f s   ", label_.c_str(), bar,
                 static_cast<long long>(done), static_cast<long long>(*total_), rate, eta_s);
  } else {
    std::fprintf(stderr, "\r%s %lld frames  %.0f fps   ", label_.c_str(),
                 static_cast<long long>(done), rate);
  }
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (enabled_ && terminal_) std::fprintf(stderr, "\r\033[K");
}

void ProgressSink::begin(const RunInfo& info) {
  bar_.emplace(label_, info.frame_count, enabled_);
  done_ = 0;
}

void ProgressSink::consume(const Frame& frame, const FrameResult& result) {
  (void)frame;
  (void)result;
  bar_->update(++done_);
}

void ProgressSink::end(const RunSummary& summary) {
  (void)summary;
  if (bar_) bar_->finish();
}

}  // namespace softsight
