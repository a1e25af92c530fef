#include "web/serve_run.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <ostream>

#include "gui/live_controller.h"
#include "gui/live_feed.h"
#include "gui/seekable_source.h"
#include "softsight/core/error.h"
#include "softsight/io/run_source.h"
#include "softsight/pipeline/sinks.h"
#include "stream/stream_format.h"
#include "web/page_messages.h"
#include "web/rig_panel.h"

namespace softsight {
namespace {

using Kind = PageCommand::Kind;

// Pages' messages, from the server's thread to the run's. Bounded: a page that floods the run
// loses its oldest messages, never the run its memory.
class PageInbox {
 public:
  struct Message {
    uint64_t page;
    bool controls;
    std::string text;
  };
  void push(Message message) {
    std::lock_guard lock(mutex_);
    if (queue_.size() >= kMaxWaiting) queue_.pop_front();
    queue_.push_back(std::move(message));
    ready_.notify_one();
  }
  bool pop(Message* message) {
    std::lock_guard lock(mutex_);
    if (queue_.empty()) return false;
    *message = std::move(queue_.front());
    queue_.pop_front();
    return true;
  }
  void wait(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    ready_.wait_for(lock, timeout, [this] {
      return !queue_.empty() || !departed_.empty() || stops_.load() > 0;
    });
  }
  // A page's STOP of the rig: never queued behind (or dropped with) other messages, so a page
  // flooding the inbox cannot delay or lose it. Presses before the run sees them count as one.
  void press_stop() {
    stops_.fetch_add(1);
    std::lock_guard lock(mutex_);
    ready_.notify_one();
  }
  bool take_stop() { return stops_.exchange(0) > 0; }
  // A page that left: kept apart from the bounded queue too (each page leaves once).
  void depart(uint64_t page) {
    std::lock_guard lock(mutex_);
    departed_.push_back(page);
    ready_.notify_one();
  }
  bool pop_departure(uint64_t* page) {
    std::lock_guard lock(mutex_);
    if (departed_.empty()) return false;
    *page = departed_.front();
    departed_.pop_front();
    return true;
  }

 private:
  static constexpr size_t kMaxWaiting = 256;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Message> queue_;
  std::deque<uint64_t> departed_;
  std::atomic<int> stops_{0};
};

double UnixMs(SteadyClock::time_point steady) {
  // The page compares it with its own clock (Date.now(), offset by the ping's estimate).
  const auto now_system = std::chrono::system_clock::now();
  const auto since = SteadyClock::now() - steady;
  return std::chrono::duration<double, std::milli>(
             (now_system - std::chrono::duration_cast<std::chrono::system_clock::duration>(since))
                 .time_since_epoch())
      .count();
}

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", value);
  return text;
}

// A scale (mm per px) to six significant digits.
std::string Number6(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// The answer to a page's ping: its own time back, and the server's clock now.
std::string Pong(double page_time_ms) {
  const double now_ms = std::chrono::duration<double, std::milli>(
                            std::chrono::system_clock::now().time_since_epoch())
                            .count();
  return "{\"type\":\"pong\",\"t\":" + Number(page_time_ms) + ",\"server_ms\":" +
         Number(now_ms) + "}";
}

std::string TextMessage(const char* type, const std::string& text) {
  std::string json = std::string("{\"type\":\"") + type + "\",\"message\":";
  AppendJsonString(text, json);
  return json + "}";
}

// The browser as a sink of the run: each frame's CSV row (the column table every CSV and the
// stream use) as a text message, and its picture as a binary one, to every page.
class WebSink : public FrameSink {
 public:
  WebSink(WebServer& server, CsvColumnTable table, const std::vector<std::string>& markers,
          int jpeg_quality)
      : server_(server), table_(std::move(table)), formatter_(table_),
        topic_(StreamTopics(table_, markers).front()), markers_(markers), quality_(jpeg_quality) {}

  void set_controller(const LiveController* controller) { controller_ = controller; }
  // The second video, sent with each picture at the same position (its frame there).
  void set_compare(SeekableSource* compare) { compare_ = compare; }

  // The rows' columns from now on (a scale set from a page adds the _mm ones).
  void set_columns(CsvColumnTable table) {
    table_ = std::move(table);  // formatter_ reads table_ (a reference to this member).
    topic_ = StreamTopics(table_, markers_).front();
  }

  void consume(const Frame& frame, const FrameResult& result) override {
    send_result(result, /*edit=*/false);
    send_picture(frame.image, result, /*replay=*/false);
  }

  // The frame on screen again, for a page that just connected (a paused run sends no other).
  // `replay`: the page does not count its capture-to-page latency.
  void resend(const cv::Mat& image, const FrameResult& result) {
    send_result(result, /*edit=*/true);
    send_picture(image, result, /*replay=*/true);
  }

  void send_picture(const cv::Mat& image, const FrameResult& result, bool replay) {
    if (server_.pages() == 0 || image.empty()) return;  // Nobody watches: nothing to encode.
    const bool mask = controller_ != nullptr && controller_->mask_view();
    cv::imencode(".jpg", mask ? masked(image) : image, jpeg_, jpeg_params_);
    header_.clear();
    AppendFrameFields(result, header_);
    header_ += mask ? ",\"mask\":true" : ",\"mask\":false";
    header_ += replay ? ",\"replay\":true" : ",\"replay\":false";
    if (mask) send_candidates(result);
    // With a second video, its frame at this position travels in the same message (after the
    // picture, compare_bytes long): a page too slow for a frame skips both, never one of them.
    const bool compared = encode_compare();
    if (compared) {
      header_ += ",\"compare_frame\":" + std::to_string(compare_frame_.index) +
                 ",\"compare_bytes\":" + std::to_string(compare_jpeg_.size());
    }
    header_ += '}';
    // [header length, 4 bytes little-endian][header JSON][JPEG][its JPEG]: the page pairs the
    // picture with its result by frame number. The message is new each frame (the server's
    // thread writes it to every page after this returns); everything else here is reused.
    std::string bytes;
    bytes.reserve(4 + header_.size() + jpeg_.size() + (compared ? compare_jpeg_.size() : 0));
    const uint32_t size = static_cast<uint32_t>(header_.size());
    for (int i = 0; i < 4; ++i) bytes += static_cast<char>((size >> (8 * i)) & 0xFF);
    bytes += header_;
    bytes.append(reinterpret_cast<const char*>(jpeg_.data()), jpeg_.size());
    if (compared) bytes.append(reinterpret_cast<const char*>(compare_jpeg_.data()), compare_jpeg_.size());
    server_.broadcast_frame(std::move(bytes));
  }

  // The mask view (as the window's `v`): the active marker's member pixels in their own
  // colours, the rest dimmed to a quarter. The buffers are reused.
  const cv::Mat& masked(const cv::Mat& image) {
    const bool has_mask = controller_->active_tracker().membership(image, mask_);
    image.convertTo(mask_image_, -1, 0.25, 0);
    if (has_mask) image.copyTo(mask_image_, mask_);
    return mask_image_;
  }

  // The active marker's candidate blobs with their verdicts and its search region, for the
  // page to draw over the mask (text crisp at any zoom): why a marker is or is not found.
  void send_candidates(const FrameResult& result) {
    const Tracker& tracker = controller_->active_tracker();
    mask_json_.assign("{\"type\":\"mask\",\"frame\":");
    mask_json_ += std::to_string(result.frame_index);
    mask_json_ += ",\"marker\":" + std::to_string(controller_->active_marker());
    mask_json_ += ",\"region\":";
    if (const std::optional<cv::Rect> region = tracker.search_region()) {
      mask_json_ += "[" + std::to_string(region->x) + "," + std::to_string(region->y) + "," +
                    std::to_string(region->width) + "," + std::to_string(region->height) + "]";
    } else {
      mask_json_ += "null";
    }
    mask_json_ += ",\"candidates\":[";
    char item[200];
    bool first = true;
    for (const MarkerCandidate& c : tracker.candidates()) {
      std::snprintf(item, sizeof item,
                    "%s{\"x\":%.2f,\"y\":%.2f,\"area\":%.1f,\"circularity\":%.3f,"
                    "\"misfit\":%.3f,\"verdict\":\"%s\"}",
                    first ? "" : ",", c.position_px.x, c.position_px.y, c.area_px, c.circularity,
                    c.misfit, CandidateVerdictName(c.verdict));
      mask_json_ += item;
      first = false;
    }
    mask_json_ += "]}";
    server_.broadcast_text(mask_json_);
  }

  // The second video's frame at the position of the frame on screen, encoded into
  // compare_jpeg_; false when there is none (no second video, a camera, past its end: the page
  // keeps its last). A video that fails to read is dropped, once, saying why on stderr.
  bool encode_compare() {
    if (compare_ == nullptr || position() < 0) return false;
    try {
      if (compare_->position() != position()) compare_->seek(position());
      if (!compare_->read(compare_frame_)) return false;
    } catch (const std::exception& failed) {
      std::fprintf(stderr, "serve: --compare dropped: %s\n", failed.what());
      compare_ = nullptr;
      return false;
    }
    cv::imencode(".jpg", compare_frame_.image, compare_jpeg_, jpeg_params_);
    return true;
  }

  // A result with no new picture (an edit re-tracked the frame on screen): `edit` says so.
  void send_result(const FrameResult& result, bool edit) {
    if (server_.pages() == 0) return;  // Nobody watches (a page that joins gets the frame on screen).
    formatter_.format(topic_, result, record_);
    json_.assign("{\"type\":\"result\",");
    AppendFrameFields(result, json_);
    json_ += edit ? ",\"edit\":true,\"row\":" : ",\"edit\":false,\"row\":";
    json_.append(record_, topic_.topic.size() + 1);  // The record without its topic word.
    json_ += '}';
    server_.broadcast_text(json_);  // One copy: the message the server's thread sends.
  }

 private:
  int64_t position() const { return controller_ ? controller_->position() : -1; }

  // Appends "frame": .., "position": .., "captured_ms": .. (opening the object when `out` is
  // empty: the picture's header; the result's has its "type" before).
  void AppendFrameFields(const FrameResult& result, std::string& out) const {
    if (out.empty()) out += '{';
    out += "\"frame\":";
    out += std::to_string(result.frame_index);  // Short: in the string's own buffer.
    out += ",\"position\":";
    out += std::to_string(position());
    out += ",\"captured_ms\":";
    char number[32];
    std::snprintf(number, sizeof number, "%.3f", UnixMs(result.captured));
    out += number;
  }

  WebServer& server_;
  CsvColumnTable table_;
  RecordFormatter formatter_;
  TopicColumns topic_;
  std::vector<std::string> markers_;
  int quality_;
  const LiveController* controller_ = nullptr;
  SeekableSource* compare_ = nullptr;
  Frame compare_frame_;
  std::vector<uchar> compare_jpeg_;
  // Reused per frame; only the messages handed to the server's thread are new each time.
  std::vector<uchar> jpeg_;
  std::string header_, record_, json_, mask_json_;
  cv::Mat mask_, mask_image_;
  const std::vector<int> jpeg_params_{cv::IMWRITE_JPEG_QUALITY, quality_};
};

std::string Greeting(const TrackingConfig& config, const FrameSource& source, bool seekable,
                     const RigPanel* rig, const FrameSource* compare) {
  std::string json = "{\"type\":\"hello\",\"source\":";
  AppendJsonString(source.description(), json);
  json += ",\"markers\":[";
  for (size_t i = 0; i < config.markers.size(); ++i) {
    if (i > 0) json += ',';
    AppendJsonString(config.markers[i].name, json);
  }
  json += "],\"triple\":[";
  AppendJsonString(config.measure.base, json);
  json += ',';
  AppendJsonString(config.measure.middle, json);
  json += ',';
  AppendJsonString(config.measure.tip, json);
  json += "],\"seekable\":";
  json += seekable ? "true" : "false";
  json += ",\"live\":";
  json += source.is_live() ? "true" : "false";
  json += ",\"fps\":" + Number(source.fps().value_or(0.0));
  const std::optional<int64_t> count = source.frame_count();
  json += ",\"length\":" + (count ? std::to_string(*count) : std::string("null"));
  json += ",\"rig\":" + (rig ? rig->limits_json() : std::string("null"));
  json += ",\"compare\":";
  if (compare != nullptr) {
    AppendJsonString(compare->description(), json);
  } else {
    json += "null";
  }
  return json + "}";
}

// The run's side of the pages: their commands carried out on the controller, what the run says
// and how it goes sent back.
class ServeLoop {
 public:
  ServeLoop(LiveController& controller, WebServer& server, WebSink& sink, const ServeOptions& options,
            bool seekable, std::ostream& out)
      : controller_(controller), server_(server), sink_(sink), options_(options),
        seekable_(seekable), out_(out) {}

  void handle(const PageInbox::Message& message);
  // Everything the controller said since the last call, to every page and to `out`.
  void relay_messages();
  void send_status(bool force);
  // The rig's state to every page when it changed (a step, a STOP), or `force`d.
  void send_rig(bool force);
  // The rig's STOP, from any page: vents at once.
  void stop_rig();

 private:
  void apply(const PageCommand& command, uint64_t page);
  void save(const std::string& name, uint64_t page);
  void load(const std::string& name, uint64_t page);
  // The configs a page may load: plain names (ValidConfigName) of regular files in the folder.
  void list_configs(uint64_t page);
  PageLimits limits() const;

  LiveController& controller_;
  WebServer& server_;
  WebSink& sink_;
  const ServeOptions& options_;
  bool seekable_;
  std::ostream& out_;
  std::string last_status_;
  SteadyClock::time_point status_sent_{};
  int64_t rig_sent_ = -1;
};

PageLimits ServeLoop::limits() const {
  PageLimits limits;
  limits.frame_size = controller_.frame_on_screen().size();
  limits.seekable = seekable_;
  limits.length = controller_.timeline().length();
  limits.markers = static_cast<int>(controller_.config().markers.size());
  limits.rig = options_.rig != nullptr;
  return limits;
}

void ServeLoop::handle(const PageInbox::Message& message) {
  std::string error;
  const std::optional<PageCommand> command = ParsePageCommand(message.text, limits(), &error);
  if (!command) {
    server_.send_text(message.page, TextMessage("error", error));
    return;
  }
  if (ChangesTheRun(command->kind) && !message.controls) {
    server_.send_text(message.page,
                      TextMessage("error", "read-only: another page controls the run (take "
                                           "control to change it)"));
    return;
  }
  apply(*command, message.page);
}

void ServeLoop::apply(const PageCommand& command, uint64_t page) {
  const auto key = [this](int key) { controller_.on_event(UiEvent::Key(key)); };
  switch (command.kind) {
    case Kind::kPlay:
      if (controller_.paused() || controller_.ended()) key(' ');
      break;
    case Kind::kPause:
      // At the end the key would play from the start: a pause there leaves it as it is.
      if (!controller_.paused() && !controller_.ended()) key(' ');
      break;
    case Kind::kStep: key(command.delta > 0 ? '.' : ','); break;
    case Kind::kSeek: controller_.seek_to(command.position); break;
    case Kind::kSpeed: controller_.set_speed(command.speed); break;
    case Kind::kPick: controller_.pick_colour_at(command.point_px); break;
    case Kind::kSelect: controller_.reselect(command.box_px); break;
    case Kind::kMethod: key('m'); break;
    case Kind::kUndo: key('u'); break;
    case Kind::kMarker: key('1' + command.marker); break;
    case Kind::kRecord: key('r'); break;
    case Kind::kResetReference: key('b'); break;
    case Kind::kSave: save(command.name, page); break;
    case Kind::kLoad: load(command.name, page); break;
    case Kind::kListConfigs: list_configs(page); return;
    case Kind::kTakeControl: server_.give_control(page); break;
    case Kind::kPing:
      server_.send_text(page, Pong(command.page_time_ms));
      return;
    case Kind::kRigRun:
    case Kind::kRigProfile: {
      const std::string refused =
          command.kind == Kind::kRigRun ? options_.rig->run_target(command.target_deg, page)
                                        : options_.rig->run_profile(command.profile, page);
      if (!refused.empty()) server_.send_text(page, TextMessage("error", refused));
      relay_messages();
      return;
    }
    case Kind::kRigStop:
      stop_rig();
      return;
    case Kind::kHsv:
      controller_.on_event(UiEvent::Trackbar(command.hsv_index, command.hsv_value));
      break;
    case Kind::kMaskView:
      if (controller_.mask_view() != command.on) key('v');
      break;
    case Kind::kRange: controller_.edit_range_at(command.point_px, command.grow); break;
    case Kind::kScale:
      controller_.set_scale_from_points(command.point_px, command.point_b_px, command.distance_mm);
      // The rows have the _mm columns from now on (the frame on screen's too).
      sink_.set_columns(TrackingColumns(controller_.config(), options_.live.extra_columns));
      break;
  }
  if (command.kind == Kind::kSave) list_configs(0);  // Every page's list has the new name.
  // An edit re-tracks the frame on screen (or the next one shows it): every page sees its
  // result now, also while paused.
  const bool edit = command.kind == Kind::kPick || command.kind == Kind::kSelect ||
                    command.kind == Kind::kMethod || command.kind == Kind::kUndo ||
                    command.kind == Kind::kHsv || command.kind == Kind::kLoad ||
                    command.kind == Kind::kRange || command.kind == Kind::kScale;
  // The picture itself changes when the mask view is turned on or off, and in it with the
  // ranges and the active marker: sent again at once (also paused).
  const bool picture = command.kind == Kind::kMaskView ||
                       (controller_.mask_view() && (edit || command.kind == Kind::kMarker));
  if (controller_.last_result()) {
    if (picture) {
      sink_.resend(controller_.frame_on_screen(), *controller_.last_result());
    } else if (edit) {
      sink_.send_result(*controller_.last_result(), true);
    }
  }
  send_status(/*force=*/true);
}

void ServeLoop::save(const std::string& name, uint64_t page) {
  namespace fs = std::filesystem;
  // The name is a plain file name (ParsePageCommand): joined to the folder it stays in it. A
  // symbolic link of that name could still point out: refused, as the started config is.
  const fs::path path = options_.folder / name;
  std::error_code error;
  std::string refusal;
  if (fs::is_symlink(fs::symlink_status(path, error))) {
    refusal = "save: " + name + " is a symbolic link in " + options_.folder.string() + "; choose another name";
  } else if (!options_.config_path.empty() && fs::equivalent(path, options_.config_path, error)) {
    refusal = "save: " + name + " is the config the server started with; choose another name";
  }
  if (!refusal.empty()) {
    server_.send_text(page, TextMessage("error", refusal));
    return;
  }
  controller_.save_config_to(path.string());
}

void ServeLoop::load(const std::string& name, uint64_t page) {
  namespace fs = std::filesystem;
  // A plain name (ParsePageCommand) joined to the folder stays in it; a symbolic link of that
  // name could point out of it, and is refused as save() refuses it.
  const fs::path path = options_.folder / name;
  std::error_code error;
  const fs::file_status status = fs::symlink_status(path, error);
  std::string refusal;
  if (fs::is_symlink(status)) {
    refusal = "load: " + name + " is a symbolic link in " + options_.folder.string();
  } else if (!fs::is_regular_file(status)) {
    refusal = "load: no config " + name + " in " + options_.folder.string();
  }
  if (!refusal.empty()) {
    server_.send_text(page, TextMessage("error", refusal));
    return;
  }
  controller_.load_markers_from(path.string());
}

void ServeLoop::list_configs(uint64_t page) {
  namespace fs = std::filesystem;
  std::vector<std::string> names;
  std::error_code error;
  for (fs::directory_iterator it(options_.folder, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    std::string ignored;
    if (it->is_symlink(error) || !it->is_regular_file(error) || !ValidConfigName(name, &ignored)) continue;
    names.push_back(name);
    if (names.size() >= 500) break;  // A folder of thousands: the first 500 are a long list already.
  }
  std::sort(names.begin(), names.end());
  std::string json = "{\"type\":\"configs\",\"names\":[";
  for (size_t i = 0; i < names.size(); ++i) {
    if (i > 0) json += ',';
    AppendJsonString(names[i], json);
  }
  json += "]}";
  if (page == 0) {
    server_.broadcast_text(std::move(json));
  } else {
    server_.send_text(page, std::move(json));
  }
}

void ServeLoop::relay_messages() {
  for (const std::string& said : controller_.take_messages()) {
    out_ << "serve: " << said << std::endl;
    server_.broadcast_text(TextMessage("message", said));
  }
  if (options_.rig == nullptr) return;
  for (const std::string& said : options_.rig->take_messages()) {
    out_ << "serve: " << said << std::endl;
    server_.broadcast_text(TextMessage("message", said));
  }
}

void ServeLoop::stop_rig() {
  if (options_.rig == nullptr) return;
  options_.rig->stop("pressed on a page");
  // Every page sees the vent now, not with the next frame.
  send_rig(/*force=*/true);
  relay_messages();
}

void ServeLoop::send_rig(bool force) {
  if (options_.rig == nullptr) return;
  if (!force && options_.rig->updates() == rig_sent_) return;
  rig_sent_ = options_.rig->updates();
  server_.broadcast_text(options_.rig->status_json());  // A copy: the panel's buffer is reused.
}

void ServeLoop::send_status(bool force) {
  const SteadyClock::time_point now = SteadyClock::now();
  if (!force && now - status_sent_ < std::chrono::milliseconds(250)) return;
  status_sent_ = now;
  const std::array<int, 6> hsv = controller_.active_hsv();
  const TrackingConfig& config = controller_.config();
  const int active = controller_.active_marker();
  std::string json = "{\"type\":\"status\",\"fps\":" + Number(controller_.fps().value_or(0.0)) +
                     ",\"latency_ms\":" + Number(controller_.latency_ms().value_or(0.0)) +
                     ",\"dropped\":" + std::to_string(controller_.dropped_frames()) +
                     ",\"skipped\":" + std::to_string(server_.frames_skipped()) +
                     ",\"paused\":" + (controller_.paused() ? "true" : "false") +
                     ",\"ended\":" + (controller_.ended() ? "true" : "false") +
                     ",\"recording\":" + (controller_.recording() ? "true" : "false") +
                     ",\"speed\":" + Number(controller_.speed()) +
                     ",\"position\":" + std::to_string(controller_.position()) +
                     ",\"length\":" + std::to_string(controller_.timeline().length().value_or(0)) +
                     ",\"pages\":" + std::to_string(server_.pages()) +
                     ",\"undo\":" + std::to_string(controller_.undo_depth()) +
                     ",\"mask_view\":" + (controller_.mask_view() ? "true" : "false") +
                     ",\"active\":" + std::to_string(active) + ",\"mm_per_px\":" +
                     (config.measure.metric.scale_mm_per_px
                          ? Number6(*config.measure.metric.scale_mm_per_px)
                          : std::string("null")) +
                     ",\"method\":";
  AppendJsonString(TrackerMethodName(config.markers[active].params), json);
  json += ",\"hsv\":[";
  for (size_t i = 0; i < hsv.size(); ++i) {
    if (i > 0) json += ',';
    json += std::to_string(hsv[i]);
  }
  json += "]}";
  if (!force && json == last_status_) return;
  last_status_ = json;
  server_.broadcast_text(std::move(json));
}

// A file served with a way to reopen it: seekable (the page's timeline); `source` becomes it.
SeekableSource* MakeSeekable(std::unique_ptr<FrameSource>& source, FrameSourceOpener reopen) {
  if (source->is_live() || !reopen) return nullptr;
  auto playable = std::make_unique<SeekableSource>(std::move(source), std::move(reopen));
  SeekableSource* const seekable = playable.get();
  source = std::move(playable);
  return seekable;
}

// The server's handler of a page's text. A ping is answered here, on the server's thread, at
// once: the page sets its clock by the answer, which must not wait for the run's next frame. A
// STOP of the rig jumps the queue (PageInbox::press_stop). Everything else waits in the inbox.
WebServer::Inbox AnswerOrQueue(PageInbox& inbox, std::atomic<WebServer*>& answering,
                               PageLimits checked_here) {
  return [&inbox, &answering, checked_here](uint64_t page, bool controls, std::string text) {
    std::string ignored;
    WebServer* server = answering.load();
    const auto command = ParsePageCommand(text, checked_here, &ignored);
    if (server && command && command->kind == Kind::kPing) {
      server->send_text(page, Pong(command->page_time_ms));
      return;
    }
    if (command && command->kind == Kind::kRigStop) {
      inbox.press_stop();
      return;
    }
    inbox.push({page, controls, std::move(text)});
  };
}

// What the pages did since the last frame: a STOP, pages that left, their messages, and a page
// that joined (it gets the frame on screen at once, playing or not).
void TakePages(PageInbox& inbox, const ServeOptions& options, const WebServer& server,
               WebSink& sink, LiveController& controller, ServeLoop& loop, int* pages_seen) {
  if (inbox.take_stop()) loop.stop_rig();  // First: nothing the pages sent comes before.
  uint64_t departed = 0;
  while (inbox.pop_departure(&departed)) {
    if (options.rig != nullptr) options.rig->page_left(departed);
  }
  PageInbox::Message message;
  while (inbox.pop(&message)) loop.handle(message);
  if (server.pages() > *pages_seen && controller.last_result()) {
    sink.resend(controller.frame_on_screen(), *controller.last_result());
    loop.send_status(/*force=*/true);
    loop.send_rig(/*force=*/true);
  }
  *pages_seen = server.pages();
}

}  // namespace

LiveRunResult RunServe(const TrackingConfig& config, std::unique_ptr<FrameSource> source,
                       ServeOptions options, FrameSourceOpener reopen,
                       const std::function<bool()>& stop_requested, std::ostream& out) {
  if (options.jpeg_quality < 1 || options.jpeg_quality > 100) {
    throw InputError("--jpeg-quality " + std::to_string(options.jpeg_quality) +
                     " is outside 1..100");
  }
  SeekableSource* const seekable = MakeSeekable(source, std::move(reopen));
  if (!options.live.record_fps) options.live.record_fps = source->fps();
  // With a rig, every row (the page's, a recording's) carries the loop's columns too.
  if (options.rig != nullptr) {
    for (CsvColumn& column : options.rig->columns()) options.live.extra_columns.push_back(std::move(column));
  }
  PageInbox inbox;
  std::atomic<WebServer*> answering{nullptr};
  PageLimits checked_here;  // Pings and STOPs need nothing of the run's state.
  checked_here.rig = options.rig != nullptr;
  WebServer server(options.server, PageAssets(), AnswerOrQueue(inbox, answering, checked_here),
                   [&inbox](uint64_t page, bool) { inbox.depart(page); });
  answering = &server;
  std::vector<std::string> names;
  for (const MarkerSpec& marker : config.markers) names.push_back(marker.name);
  // The page's values: the CSV's columns, a hook's too (after the hook's sink, first in sinks).
  WebSink sink(server, TrackingColumns(config, options.live.extra_columns), names,
               options.jpeg_quality);
  std::unique_ptr<SeekableSource> compare;
  if (options.compare) {
    if (seekable == nullptr) throw InputError("--compare needs a file served (--input), not a camera");
    compare = std::make_unique<SeekableSource>(options.compare(), options.compare);
    sink.set_compare(compare.get());
  }
  // The rig's loop steps on each frame before the frame goes out: its state travels with it.
  if (options.rig != nullptr) options.live.sinks.push_back(options.rig);
  options.live.sinks.push_back(&sink);
  LiveController controller(config, options.live);
  sink.set_controller(&controller);
  controller.describe_source(*source);
  server.set_greeting(Greeting(config, *source, seekable != nullptr, options.rig, compare.get()));
  source = SourceForRun(std::move(source),
                        options.pace_files ? FilePacing::kRealTime : FilePacing::kInCallersThread);
  out << "softsight serve: " << source->description() << ", " << config.markers.size()
      << " markers; open " << server.url() << std::endl;

  ServeLoop loop(controller, server, sink, options, seekable != nullptr, out);
  LiveFeed feed(*source, seekable);
  // A file shows its first frame and waits, paused, for the first page: played to nobody, its
  // start would be gone before anyone saw it (and, paused, its paced clock stops: no burst to
  // catch up when the page comes). A camera runs from the start.
  bool waiting_for_page = !source->is_live() && feed.step(controller) && server.pages() == 0;
  if (waiting_for_page) controller.on_event(UiEvent::Key(' '));
  controller.take_messages();  // The window's start-up hint ("press h") and that pause.
  int pages_seen = 0;
  while (!stop_requested() && !controller.quit_requested()) {
    if (waiting_for_page && server.pages() > 0) {
      waiting_for_page = false;
      if (controller.paused()) controller.on_event(UiEvent::Key(' '));
    }
    TakePages(inbox, options, server, sink, controller, loop, &pages_seen);
    // A paced file waits here until its frame is due (at most a frame period); a camera
    // returns its newest frame.
    const bool got = feed.step(controller);
    loop.send_rig(/*force=*/false);
    loop.relay_messages();
    // A frame stepped or sought to while paused: its position goes out with it (while playing
    // the status follows four times a second).
    loop.send_status(/*force=*/got && controller.paused());
    if (!got) inbox.wait(std::chrono::milliseconds(20));
  }
  LiveRunResult result;
  result.last_recording = controller.last_recording();
  result.summary = controller.run_summary();
  return result;
}

}  // namespace softsight
