#include "gui/live_window.h"

#include <X11/Xlib.h>

#include <cstdlib>
#include <iostream>
#include <opencv2/highgui.hpp>

#include "gui/live_controller.h"
#include "gui/live_feed.h"
#include "gui/live_layout.h"
#include "gui/seekable_source.h"
#include "softsight/io/run_source.h"

namespace softsight {
namespace {

struct CallbackContext {
  LiveController* controller;
};

void OnMouse(int event, int x, int y, int flags, void* user) {
  auto* context = static_cast<CallbackContext*>(user);
  UiEvent::Type type;
  switch (event) {
    // The wheel is not taken: OpenCV's Qt windows zoom their own view with it (and map the
    // mouse through that zoom), which would zoom twice. + and - zoom the picture itself.
    case cv::EVENT_RBUTTONDOWN:
      type = UiEvent::Type::kPanDown;
      break;
    case cv::EVENT_LBUTTONDOWN:
      type = UiEvent::Type::kMouseDown;
      break;
    case cv::EVENT_MOUSEMOVE:
      type = (flags & cv::EVENT_FLAG_RBUTTON) != 0 ? UiEvent::Type::kPanMove
                                                   : UiEvent::Type::kMouseMove;
      break;
    case cv::EVENT_LBUTTONUP:
      type = UiEvent::Type::kMouseUp;
      break;
    default:
      return;
  }
  context->controller->on_event(
      UiEvent::Mouse(type, x, y, (flags & cv::EVENT_FLAG_SHIFTKEY) != 0));
}

struct TrackbarContext {
  LiveController* controller;
  int index;
};

void OnTrackbar(int value, void* user) {
  auto* context = static_cast<TrackbarContext*>(user);
  context->controller->on_event(UiEvent::Trackbar(context->index, value));
}

}  // namespace

bool HaveDisplay(std::string* why) {
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if (wayland != nullptr && *wayland != '\0') return true;
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    *why = "no display (DISPLAY is not set)";
    return false;
  }
  // Ask the X server itself: a stale DISPLAY would otherwise abort inside the GUI toolkit.
  Display* connection = XOpenDisplay(nullptr);
  if (connection == nullptr) {
    *why = std::string("cannot open display '") + display + "'";
    return false;
  }
  XCloseDisplay(connection);
  return true;
}

// The default screen's size in pixels, when an X server answers (XWayland too).
cv::Size ScreenSize() {
  Display* connection = XOpenDisplay(nullptr);
  if (connection == nullptr) return {};
  const int screen = DefaultScreen(connection);
  const cv::Size size(DisplayWidth(connection, screen), DisplayHeight(connection, screen));
  XCloseDisplay(connection);
  return size;
}

namespace {

// The window's loop: one window, its mouse callback, six trackbars and the keys. Everything it
// decides is the controller's; this only moves events in and images out. `seekable`: the source
// under `source`'s pacing when the transport keys can seek in it; null for a camera.
int RunLiveLoop(LiveController& controller, FrameSource& source, const LiveWindowOptions& options,
                SeekableSource* seekable) {
  const std::string& title = options.title;
  // The canvas is scaled to the screen (a 720p frame with its chart is taller than a laptop's
  // screen); mouse positions come back in canvas pixels and the controller maps them.
  const cv::Size screen = options.screen_px.area() > 0 ? options.screen_px : ScreenSize();
  controller.set_screen(screen);
  cv::Size placed_for;  // The canvas size the trackbar window was placed beside.
  // GUI_NORMAL: no toolbar or status bar, so image pixels are canvas pixels.
  cv::namedWindow(title, cv::WINDOW_AUTOSIZE | cv::WINDOW_GUI_NORMAL);
  CallbackContext mouse{&controller};
  cv::setMouseCallback(title, OnMouse, &mouse);
  std::array<TrackbarContext, kHsvTrackbars.size()> trackbars;
  int shown_revision = -1;
  // The trackbars have a window of their own: in the image's window they would take six rows
  // of the screen's height from the image.
  const std::string sliders = options.trackbar_title;
  if (options.trackbars) {
    cv::namedWindow(sliders, cv::WINDOW_AUTOSIZE | cv::WINDOW_GUI_NORMAL);
    const std::array<int, 6> hsv = controller.active_hsv();
    for (size_t i = 0; i < kHsvTrackbars.size(); ++i) {
      trackbars[i] = {&controller, static_cast<int>(i)};
      cv::createTrackbar(kHsvTrackbars[i].name, sliders, nullptr, kHsvTrackbars[i].max, OnTrackbar,
                         &trackbars[i]);
      cv::setTrackbarPos(kHsvTrackbars[i].name, sliders, hsv[i]);
    }
    shown_revision = controller.hsv_revision();
  }

  bool end_announced = false;
  controller.take_messages();  // Said while setting up: the terminal has the start-up lines.
  LiveFeed feed(source, seekable);
  const auto forward_key = [&controller](int key) {
    if (key < 0) return;
    const int code = key & 0xFFFF;
    if (code < 0x100 || code == kKeyLeft || code == kKeyRight || code == kKeyHome ||
        code == kKeyEnd) {
      controller.on_event(UiEvent::Key(code));
    }
  };
  while (!controller.quit_requested()) {
    if (controller.jump_pending()) {
      // A seek may decode for a while (a file without an index): say so on screen first. A key
      // pressed meanwhile queues behind it.
      controller.show_seeking();
      cv::imshow(title, controller.canvas());
      forward_key(cv::pollKey());
    }
    // A paced file waits in read() until its frame is due (at most one frame period); a camera
    // returns its newest frame.
    const bool got = feed.step(controller);
    const bool end_shown = feed.ended();
    cv::imshow(title, controller.canvas());
    const int key = cv::waitKeyEx(got ? 1 : 15);
    if (!end_shown) end_announced = false;  // Stepped back from the end: announce the next.
    if (end_shown && !end_announced) {
      // The last frame has been shown and the window has processed its events: tell whoever
      // watches stdout (scripts, the test under Xvfb) that the picture is final.
      std::cout << "end of input" << std::endl;
      end_announced = true;
    }
    forward_key(key);
    // What the window said (recording started, paused, saved ...) also goes to stdout, one
    // line each, for the terminal's scrollback and for scripts that drive the window.
    for (const std::string& said : controller.take_messages()) {
      std::cout << "live: " << said << std::endl;
    }
    if (options.trackbars && controller.hsv_revision() != shown_revision) {
      const std::array<int, 6> hsv = controller.active_hsv();
      for (size_t i = 0; i < kHsvTrackbars.size(); ++i) {
        cv::setTrackbarPos(kHsvTrackbars[i].name, sliders, hsv[i]);
      }
      // The window says whose ranges it edits.
      const int active = controller.active_marker();
      cv::setWindowTitle(sliders, "HSV of " + controller.config().markers[active].name +
                                      " (1-9 chooses)");
      shown_revision = controller.hsv_revision();
    }
    if (options.trackbars && controller.canvas().size() != placed_for) {
      // Beside the canvas, not over it (without a window manager every window opens at 0,0,
      // over the text block); again when the canvas grows (the help panel).
      placed_for = controller.canvas().size();
      cv::moveWindow(title, 0, 0);
      const cv::Point at = TrackbarWindowPlace(screen, placed_for);
      cv::moveWindow(sliders, at.x, at.y);
    }
    if (cv::getWindowProperty(title, cv::WND_PROP_VISIBLE) < 1) break;  // Closed by the user.
  }
  cv::destroyWindow(title);
  if (options.trackbars) cv::destroyWindow(sliders);
  cv::waitKey(1);
  return 0;
}

}  // namespace

LiveRunResult RunLiveWindow(const TrackingConfig& config, std::unique_ptr<FrameSource> source,
                            LiveOptions options, const LiveWindowOptions& window,
                            FrameSourceOpener reopen) {
  SeekableSource* seekable = nullptr;
  if (!source->is_live() && reopen) {
    // The transport keys (step, seek, loop) read the file again from its start when they go
    // back further than the frames kept in memory.
    auto playable = std::make_unique<SeekableSource>(std::move(source), std::move(reopen));
    seekable = playable.get();
    source = std::move(playable);
  }
  if (!options.record_fps) options.record_fps = source->fps();
  LiveController controller(config, std::move(options));
  controller.describe_source(*source);
  // Pacing belongs to the source: a camera keeps only its newest frame (drops are counted and
  // shown); a file or image sequence plays every frame at its own rate and pauses with the
  // window (or, unpaced, as fast as it decodes).
  source = SourceForRun(std::move(source),
                        window.pace_files ? FilePacing::kRealTime : FilePacing::kInCallersThread);
  LiveRunResult result;
  result.exit_code = RunLiveLoop(controller, *source, window, seekable);
  result.last_recording = controller.last_recording();
  result.summary = controller.run_summary();
  return result;
}

}  // namespace softsight
