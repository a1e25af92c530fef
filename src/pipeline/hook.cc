#include "softsight/pipeline/hook.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <utility>

#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/pipeline/summary.h"

namespace softsight {
namespace {

bool IsColumnWord(const std::string& name) {
  if (name.empty()) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

// The last non-empty line of an error: a Python traceback's "ZeroDivisionError: division by
// zero", the one line a summary or a stopped run shows.
std::string LastLine(const std::string& text) {
  size_t end = text.find_last_not_of("\n ");
  if (end == std::string::npos) return text;
  const size_t begin = text.rfind('\n', end);
  return text.substr(begin == std::string::npos ? 0 : begin + 1, end + 1 - (begin == std::string::npos ? 0 : begin + 1));
}

double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

HookValues::HookValues(std::vector<std::string> names)
    : names_(std::move(names)), values_(names_.size(), 0.0), given_(names_.size(), 0) {}

std::optional<size_t> HookValues::find(std::string_view name) const {
  for (size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == name) return i;
  }
  return std::nullopt;
}

void HookValues::set(size_t column, double value) {
  if (column >= names_.size()) {
    throw InputError("hook value #" + std::to_string(column) + ": the hook has " +
                     std::to_string(names_.size()) + " columns");
  }
  given_[column] = std::isfinite(value) ? 1 : 0;
  values_[column] = value;
}

void HookValues::set(std::string_view name, double value) {
  const std::optional<size_t> column = find(name);
  if (!column) {
    std::string declared;
    for (const std::string& n : names_) declared += (declared.empty() ? "" : ", ") + n;
    throw InputError("'" + std::string(name) + "' is not one of the hook's columns (" +
                     (declared.empty() ? "it declared none" : declared) + ")");
  }
  set(*column, value);
}

std::optional<double> HookValues::get(size_t column) const {
  if (column >= names_.size() || !given_[column]) return std::nullopt;
  return values_[column];
}

void HookValues::clear() { std::fill(given_.begin(), given_.end(), 0); }

void HookValues::assign(const HookValues& other) {
  std::copy(other.values_.begin(), other.values_.end(), values_.begin());
  std::copy(other.given_.begin(), other.given_.end(), given_.begin());
}

// The hook's own thread (HookOptions::wait_ms): one frame at a time, in a slot of its own (the
// frame's pixels copied into a buffer reused from frame to frame), so the run's thread never
// waits for it longer than the budget and never shares a buffer with it while it runs.
class HookSink::Worker {
 public:
  Worker(FrameHook& hook, const std::vector<std::string>& names) : hook_(hook), values_(names) {
    thread_ = std::thread([this] { loop(); });
  }
  ~Worker() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();  // A hook still running is waited for: it holds references into this.
  }

  // False when the hook is still busy with an earlier frame (the frame is skipped).
  bool busy() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return job_;
  }
  // Hands over a frame (the hook is idle) and waits up to `wait_ms` for it to be done. True:
  // done in time (its values, error and time in done_*()); false: still running (late).
  bool run(const Frame& frame, const FrameResult& result, double wait_ms) {
    std::unique_lock<std::mutex> lock(mutex_);
    frame.image.copyTo(frame_.image);  // Into the slot's buffer: no allocation once sized.
    frame_.index = frame.index;
    frame_.time_s = frame.time_s;
    frame_.captured = frame.captured;
    frame_.key_frame = frame.key_frame;
    result_ = result;  // Copy-assigned: the vectors keep their capacity.
    values_.clear();
    error_.reset();
    job_ = true;
    wake_.notify_all();
    return done_.wait_for(lock, std::chrono::duration<double, std::milli>(wait_ms),
                          [this] { return !job_; });
  }
  // Once !busy(): the last frame's outcome. A late frame's outcome is thrown away by the next
  // run() (its row is written); only its error is still taken (take_error()).
  const HookValues& values() const { return values_; }
  double call_ms() const { return call_ms_; }
  int64_t index() const { return frame_.index; }
  // The failure of the last frame run (message, whether it was an InputError), once.
  std::optional<std::pair<std::string, bool>> take_error() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (job_) return std::nullopt;
    std::optional<std::pair<std::string, bool>> error;
    std::swap(error, error_);
    return error;
  }

 private:
  void loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return job_ || stop_; });
      if (!job_) return;  // Stopping, with nothing left to run.
      lock.unlock();
      const auto start = std::chrono::steady_clock::now();
      std::optional<std::pair<std::string, bool>> error;
      try {
        hook_.on_frame(frame_, result_, values_);
      } catch (const InputError& e) {
        error.emplace(e.what(), true);
      } catch (const std::exception& e) {
        error.emplace(e.what(), false);
      } catch (...) {
        error.emplace("an exception that is not a std::exception", false);
      }
      const double ms = MsSince(start);
      lock.lock();
      call_ms_ = ms;
      error_ = std::move(error);
      job_ = false;
      done_.notify_all();
    }
  }

  FrameHook& hook_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  bool job_ = false, stop_ = false;
  Frame frame_;
  FrameResult result_;
  HookValues values_;
  double call_ms_ = 0.0;
  std::optional<std::pair<std::string, bool>> error_;
  std::thread thread_;  // Last: started once everything above exists.
};

HookSink::HookSink(FrameHook& hook, HookOptions options)
    : hook_(hook), options_(std::move(options)), current_(hook.columns()) {
  const std::vector<std::string>& names = current_.names();
  for (size_t i = 0; i < names.size(); ++i) {
    if (!IsColumnWord(names[i])) {
      throw InputError(hook_.name() + ": column '" + names[i] +
                       "' is not a name of letters, digits and _");
    }
    if (std::find(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(i), names[i]) !=
        names.begin() + static_cast<std::ptrdiff_t>(i)) {
      throw InputError(hook_.name() + ": column '" + names[i] + "' is named twice");
    }
  }
  if (options_.wait_ms && !(*options_.wait_ms >= 0.0 && *options_.wait_ms <= 1e6)) {
    throw InputError(hook_.name() + ": its wait per frame must be 0 to 1e6 ms");
  }
}

HookSink::~HookSink() = default;

std::vector<CsvColumn> HookSink::columns() const {
  std::vector<CsvColumn> columns;
  for (size_t i = 0; i < current_.size(); ++i) {
    columns.push_back({current_.names()[i], [this, i](const FrameResult& result, std::string& row) {
                         append(i, result, row);
                       }});
  }
  return columns;
}

void HookSink::check_against(const CsvColumnTable& table) const {
  for (const std::string& name : current_.names()) {
    if (table.find(name)) {
      throw InputError(hook_.name() + ": column '" + name +
                       "' is already a column of the run (choose another name)");
    }
  }
}

void HookSink::append(size_t column, const FrameResult& result, std::string& row) const {
  // Only the values computed on this very frame: a row never carries another frame's.
  if (!current_valid_ || current_index_ != result.frame_index) return;
  AppendCsvNumber(row, current_.get(column), "%.10g");
}

void HookSink::begin(const RunInfo& info) {
  if (info.frame_count) {
    call_ms_.reserve(static_cast<size_t>(std::clamp<int64_t>(*info.frame_count, 0, int64_t{1} << 22)));
  }
  if (options_.wait_ms && !worker_) worker_ = std::make_unique<Worker>(hook_, current_.names());
}

void HookSink::fail(const std::string& message, int64_t index) {
  off_ = true;
  current_valid_ = false;  // Whatever it set before it threw is not this row's.
  if (error_) return;
  error_ = message;
  error_frame_ = index;
  if (options_.on_error) options_.on_error(message);
  if (options_.stop_on_error) {
    throw InputError(hook_.name() + " failed at frame " + std::to_string(index) + ": " +
                     LastLine(message));
  }
}

void HookSink::consume(const Frame& frame, const FrameResult& result) {
  ++frames_;
  current_index_ = result.frame_index;
  current_valid_ = false;
  if (off_) return;
  if (!worker_) {
    // On the run's thread: every frame, its values in its row.
    current_.clear();
    const auto start = std::chrono::steady_clock::now();
    try {
      hook_.on_frame(frame, result, current_);
    } catch (const InputError& e) {
      off_ = true;
      throw InputError(hook_.name() + " at frame " + std::to_string(result.frame_index) + ": " +
                       e.what());
    } catch (const std::exception& e) {
      call_ms_.push_back(MsSince(start));
      return fail(e.what(), result.frame_index);
    }
    call_ms_.push_back(MsSince(start));
    current_valid_ = true;
    ++ran_;
    return;
  }
  // On its own thread: a late frame's error comes first (the hook failed after its row).
  if (worker_->busy()) {
    ++skipped_;
    return;
  }
  const auto take_error = [&]() {
    if (auto error = worker_->take_error()) {
      if (error->second) {
        off_ = true;
        throw InputError(hook_.name() + " at frame " + std::to_string(worker_->index()) + ": " +
                         error->first);
      }
      fail(error->first, worker_->index());
      return true;
    }
    return false;
  };
  if (take_error()) return;
  if (!worker_->run(frame, result, *options_.wait_ms)) {
    ++late_;  // Its values will come after this row: they are dropped, never put in another.
    return;
  }
  call_ms_.push_back(worker_->call_ms());
  if (take_error()) return;
  current_.assign(worker_->values());
  current_valid_ = true;
  ++ran_;
}

void HookSink::end(const RunSummary& summary) {
  (void)summary;
  worker_.reset();  // Joins the thread (a hook still running is waited for).
}

void HookSink::report(RunSummary& summary) const {
  std::string note = hook_.name() + ": ";
  if (error_) {
    note += "failed at frame " + std::to_string(*error_frame_) + " (" + LastLine(*error_) +
            "), switched off; its columns are empty from that frame on; ";
  }
  note += "values in " + std::to_string(ran_) + " of " + std::to_string(frames_) + " rows";
  if (options_.wait_ms) {
    note += "; skipped " + std::to_string(skipped_) + " of " + std::to_string(frames_) +
            " frames (still busy), " + std::to_string(late_) + " late (over " +
            ShortNumber(*options_.wait_ms, 3) + " ms; left empty)";
  }
  if (!call_ms_.empty()) {
    std::vector<double> sorted = call_ms_;
    double median = 0.0, p99 = 0.0;
    SummariseTimes(sorted, &median, &p99);
    note += "; " + ShortNumber(median, 3) + " ms per call (p99 " + ShortNumber(p99, 3) + ")";
  }
  summary.notes.push_back(std::move(note));
}

}  // namespace softsight
