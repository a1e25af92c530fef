// End-to-end: the real `softsight live` window on a virtual X server (Xvfb), fed a rendered video.
// The screenshot is Xvfb's own framebuffer (-fbdir writes the screen as an XWD file), so no
// screenshot tool is needed; keys reach the window through xdotool (XTEST), as a person's would.
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/test_util.h"
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

#include "app/scene_markers_test_util.h"
#include "app/stereo_test_util.h"
#include "calib/stereo_test_util.h"
#include "gui/live_layout.h"
#include "gui/live_test_util.h"
#include "gui/live_view.h"  // StatusBandHeight
#include "gui/overlay.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/config/config.h"
#include "softsight/io/csv_reader.h"
#include "softsight/io/frame_writer.h"
#include "softsight/sim/scene.h"
#include "softsight/sim/stereo_scene.h"
#include "softsight/track/colour_tracker.h"

extern char** environ;

namespace softsight {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// A child process with its stdout (and optionally stderr) on a pipe.
struct Child {
  pid_t pid = -1;
  int out = -1;
};

Child Spawn(const std::vector<std::string>& argv, const std::vector<std::string>& extra_env,
            bool capture_stderr = false) {
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    bool overridden = false;
    for (const std::string& x : extra_env) {
      overridden |= entry.substr(0, entry.find('=') + 1) == x.substr(0, x.find('=') + 1);
    }
    if (!overridden) env_strings.push_back(entry);
  }
  for (const std::string& x : extra_env) {
    if (x.back() != '=') env_strings.push_back(x);  // "NAME=" removes NAME.
  }
  std::vector<char*> args, envp;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  for (std::string& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) return {};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 1);
  if (capture_stderr) posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  Child child;
  if (posix_spawnp(&child.pid, args[0], &actions, nullptr, args.data(), envp.data()) != 0) {
    child.pid = -1;
  }
  posix_spawn_file_actions_destroy(&actions);
  close(pipe_fds[1]);
  child.out = pipe_fds[0];
  fcntl(child.out, F_SETFL, O_NONBLOCK);
  return child;
}

// Reads the child's output until `needle` appears or `timeout` passes.
bool WaitForOutput(const Child& child, const std::string& needle, std::chrono::seconds timeout,
                   std::string* seen) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  char buffer[4096];
  while (std::chrono::steady_clock::now() < deadline) {
    const ssize_t n = read(child.out, buffer, sizeof(buffer));
    if (n > 0) {
      seen->append(buffer, n);
      if (seen->find(needle) != std::string::npos) return true;
    } else if (n == 0) {
      return seen->find(needle) != std::string::npos;  // EOF: the child exited.
    } else {
      std::this_thread::sleep_for(20ms);
    }
  }
  return false;
}

// Exit status of the child, or -1 if it did not exit within `timeout` (then it is killed).
int WaitExit(Child& child, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (waitpid(child.pid, &status, WNOHANG) == child.pid) {
      close(child.out);
      child.pid = -1;
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    std::this_thread::sleep_for(20ms);
  }
  kill(child.pid, SIGKILL);
  waitpid(child.pid, &status, 0);
  close(child.out);
  child.pid = -1;
  return -1;
}

int RunProcess(const std::vector<std::string>& argv, const std::vector<std::string>& env,
               std::string* output) {
  Child child = Spawn(argv, env, true);
  if (child.pid < 0) return -2;
  WaitForOutput(child, "\x01never", 30s, output);
  return WaitExit(child, 10s);
}

// Gives the live window the keyboard once it is mapped (xdotool waits for it), so the keys and
// clicks that follow reach it. Returns xdotool's exit code.
int FocusLiveWindow(const std::vector<std::string>& env, std::string* output) {
  return RunProcess({"xdotool", "search", "--sync", "--onlyvisible", "--name", "softsight live",
                     "windowfocus", "--sync"},
                    env, output);
}

uint32_t ReadU32(const std::string& data, size_t offset, bool big_endian) {
  const auto* b = reinterpret_cast<const unsigned char*>(data.data() + offset);
  return big_endian ? (uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | b[3])
                    : (uint32_t(b[3]) << 24 | uint32_t(b[2]) << 16 | uint32_t(b[1]) << 8 | b[0]);
}

// Xvfb's -fbdir screen file: an XWD header, a colour map, then ZPixmap pixels (32 bits each).
cv::Mat ReadXwdScreen(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  const std::string data = s.str();
  if (data.size() < 100) return {};
  const bool big = ReadU32(data, 0, true) < 4096;  // header_size is small in the right order.
  const uint32_t header_size = ReadU32(data, 0, big);
  const uint32_t width = ReadU32(data, 16, big), height = ReadU32(data, 20, big);
  const uint32_t pixel_byte_order = ReadU32(data, 28, big);  // 0 = LSBFirst.
  const uint32_t bits_per_pixel = ReadU32(data, 44, big);
  const uint32_t bytes_per_line = ReadU32(data, 48, big);
  const uint32_t red_mask = ReadU32(data, 56, big), green_mask = ReadU32(data, 60, big),
                 blue_mask = ReadU32(data, 64, big);
  const uint32_t ncolors = ReadU32(data, 76, big);
  const size_t pixels = header_size + 12 * ncolors;
  if (bits_per_pixel != 32 || data.size() < pixels + size_t(bytes_per_line) * height) return {};
  auto shift_of = [](uint32_t mask) {
    int shift = 0;
    while (mask != 0 && (mask & 1) == 0) {
      mask >>= 1;
      ++shift;
    }
    return shift;
  };
  cv::Mat image(height, width, CV_8UC3);
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const uint32_t p = ReadU32(data, pixels + y * bytes_per_line + 4 * x, pixel_byte_order != 0);
      image.at<cv::Vec3b>(y, x) =
          cv::Vec3b((p & blue_mask) >> shift_of(blue_mask),
                    (p & green_mask) >> shift_of(green_mask), (p & red_mask) >> shift_of(red_mask));
    }
  }
  return image;
}

using testing::CsvRowsWithoutTiming;
using testing::RingPoints;

class LiveWindowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    binary_ = softsight::testing::SoftsightBinary();
    ASSERT_TRUE(fs::exists(binary_)) << "no softsight program at " << binary_;
    dir_ = fs::temp_directory_path() /
           ("softsight_live_window_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (live_.pid > 0) {  // A failed assertion left the window open.
      kill(live_.pid, SIGTERM);
      WaitExit(live_, 5s);
    }
    if (xvfb_.pid > 0) {
      kill(xvfb_.pid, SIGTERM);
      WaitExit(xvfb_, 5s);
    }
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  // Starts Xvfb on a free display (-displayfd picks it) writing its screen to dir_.
  std::string StartXvfb(const std::string& screen = "800x720x24") {
    xvfb_ = Spawn({"Xvfb", "-displayfd", "1", "-screen", "0", screen, "-fbdir", dir_.string(),
                   "-nolisten", "tcp"},
                  {});
    if (xvfb_.pid < 0) return "";
    std::string seen;
    if (!WaitForOutput(xvfb_, "\n", 20s, &seen)) return "";
    std::string display = ":";  // (":" + string trips GCC 12's -Wrestrict false positive.)
    display.append(seen, 0, seen.find('\n'));
    return display;
  }

  // The screen once `drawn` holds for it (the window's picture reaches Xvfb's screen file a
  // moment after the program says what it shows, later on a loaded machine), else the last one
  // read when `timeout` runs out, for the assertions to say what is missing.
  cv::Mat ScreenWhen(const std::function<bool(const cv::Mat&)>& drawn,
                     std::chrono::seconds timeout = 20s) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    cv::Mat screen = ReadXwdScreen((dir_ / "Xvfb_screen0").string());
    while (!(!screen.empty() && drawn(screen)) && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(50ms);
      screen = ReadXwdScreen((dir_ / "Xvfb_screen0").string());
    }
    return screen;
  }

  std::string binary_;
  fs::path dir_;
  Child xvfb_;
  Child live_;
};

TEST_F(LiveWindowTest, OverlayIsDrawnWhereTheMarkersAreAndKeysAndMouseWork) {
  // A short rendered video and a config for its three markers.
  SyntheticScene renderer(testing::LiveTestScene(12, 90));
  const std::string video = (dir_ / "scene.avi").string();
  testing::WriteSceneVideo(renderer, 12, video);
  cv::Mat last;
  const SceneTruth truth = renderer.render(11, last);
  const std::string config = (dir_ / "markers.yaml").string();
  std::ofstream(config) << testing::kLiveTestMarkersYaml;

  const std::string display = StartXvfb();
  ASSERT_FALSE(display.empty()) << "Xvfb did not start";
  Child& live = live_;
  live = Spawn({binary_, "live", "--input", video, "--config", config, "--no-trackbars",
                      "--record-prefix", (dir_ / "rec").string()},
                     {"DISPLAY=" + display}, true);
  ASSERT_GT(live.pid, 0);
  std::string output;
  ASSERT_TRUE(WaitForOutput(live, "end of input", 60s, &output)) << output;
  // The last frame on screen: its pixels where the overlay does not draw (found below).
  const auto last_frame_shown = [&](const cv::Mat& screen) {
    if (screen.cols < last.cols || screen.rows < last.rows) return false;
    cv::Mat score;
    cv::matchTemplate(screen, last, score, cv::TM_CCOEFF_NORMED);
    double best = 0;
    cv::minMaxLoc(score, nullptr, &best);
    return best > 0.9;
  };
  const cv::Mat screen = ScreenWhen(last_frame_shown);
  ASSERT_FALSE(screen.empty()) << "cannot read Xvfb's screen file";
  EXPECT_EQ(screen.size(), cv::Size(800, 720));
  // Where is the window's image? Match the raw last frame: the overlay covers only a little.
  cv::Mat score;
  cv::matchTemplate(screen, last, score, cv::TM_CCOEFF_NORMED);
  double best = 0;
  cv::Point offset;
  cv::minMaxLoc(score, nullptr, &best, nullptr, &offset);
  const cv::Rect shown(offset, last.size());
  ASSERT_TRUE((cv::Rect(0, 0, screen.cols, screen.rows) & shown) == shown);
  // Where the overlay does not draw, the screen shows the frame's pixels exactly (lossless video,
  // 24-bit screen): most of the frame must match there.
  cv::Mat same;
  cv::inRange(cv::abs(cv::Mat(screen(shown)) - last) + cv::abs(last - cv::Mat(screen(shown))),
              cv::Scalar::all(0), cv::Scalar::all(2), same);
  EXPECT_GT(cv::countNonZero(same), 0.5 * last.total())
      << "the frame is not on screen, best " << best << " at " << offset;
  // The frame itself carries no overlay; on screen, each marker has its ring around the truth.
  for (const MarkerTruth& marker : truth.markers) {
    ASSERT_TRUE(marker.centroid_px);
    EXPECT_EQ(RingPoints(last, *marker.centroid_px, 12), 0) << marker.name;
    EXPECT_GE(RingPoints(screen, *marker.centroid_px + cv::Point2d(offset), 12), 20)
        << marker.name << " at " << *marker.centroid_px << " + " << offset;
  }
  // The strip chart is drawn under the image: its dark background.
  const cv::Rect chart(shown.x, shown.y + shown.height, shown.width, 180);
  ASSERT_LE(chart.y + chart.height, screen.rows);
  const cv::Scalar chart_mean = cv::mean(screen(chart));
  EXPECT_LT(chart_mean[0], 70);

  // Keys through the real window: h shows the help over the image, q quits cleanly.
  std::string xdotool_output;
  const std::vector<std::string> env = {"DISPLAY=" + display};
  ASSERT_EQ(FocusLiveWindow(env, &xdotool_output), 0) << xdotool_output;
  ASSERT_EQ(RunProcess({"xdotool", "key", "h"}, env, &xdotool_output), 0) << xdotool_output;
  // The help is a panel right of the image, which stays as it was: no marker is hidden.
  const cv::Rect help_block(shown.x + shown.width + 4, shown.y + 4, 150, 120);
  ASSERT_LE(help_block.x + help_block.width, screen.cols);
  const auto light_in_help_block = [&](const cv::Mat& on_screen) {
    cv::Mat gray;
    cv::cvtColor(on_screen(help_block), gray, cv::COLOR_BGR2GRAY);
    return cv::countNonZero(gray > 200);
  };
  const cv::Mat with_help =
      ScreenWhen([&](const cv::Mat& on_screen) { return light_in_help_block(on_screen) > 200; });
  ASSERT_FALSE(with_help.empty());
  EXPECT_GT(light_in_help_block(with_help), 200) << "no key list right of the image";
  EXPECT_LT(light_in_help_block(with_help), help_block.area() / 3) << "no panel, only light";
  cv::Mat image_diff;
  cv::absdiff(with_help(shown), screen(shown), image_diff);
  EXPECT_EQ(cv::countNonZero(image_diff.reshape(1) > 0) < shown.area() / 20, true)
      << "the help covers the image";

  // The mouse through the real window: choose blue (key 2), click its centre, save (key s). The
  // saved config carries the range picked from the pixels around the click.
  const cv::Point2d blue = *truth.markers[1].centroid_px + cv::Point2d(offset);
  ASSERT_EQ(RunProcess({"xdotool", "key", "2", "mousemove", std::to_string(cvRound(blue.x)),
                        std::to_string(cvRound(blue.y)), "click", "1", "sleep", "0.3", "key", "s"},
                       env, &xdotool_output),
            0)
      << xdotool_output;
  ASSERT_TRUE(WaitForOutput(live, "live: saved", 20s, &output)) << output;
  const TrackingConfig picked = LoadTrackingConfig((dir_ / "markers.live.yaml").string());
  ASSERT_EQ(picked.markers.size(), 3u);
  const HsvRange h = picked.markers[1].params.get<ColourParams>().h;
  EXPECT_TRUE(h.lo != 95 || h.hi != 125) << "the click did not change blue's range";
  EXPECT_LT(h.lo, 107);  // Blue's hue, about 107.
  EXPECT_GT(h.hi, 107);

  ASSERT_EQ(RunProcess({"xdotool", "key", "q"}, env, &xdotool_output), 0) << xdotool_output;
  EXPECT_EQ(WaitExit(live, 20s), 0);
}

// A 720p video on a 1366x768 laptop screen: the window fits, stepping back lands on the right
// frame (the rings on screen on that frame's truth, scaled), and a click at a scaled position
// picks the colours of the image pixel under it.
TEST_F(LiveWindowTest, A720pVideoFitsALaptopScreenStepsBackAndClicksPickTheRightPixels) {
  const SceneOptions scene = testing::LiveTest720pScene(12);
  SyntheticScene renderer(scene);
  const std::string video = (dir_ / "scene.avi").string();
  std::vector<SceneTruth> truth;
  testing::WriteSceneVideo(renderer, scene.frame_count, video, &truth);
  const std::string config = (dir_ / "markers.yaml").string();
  std::ofstream(config) << "markers:\n"
                           "  - name: red\n    hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}\n"
                           "  - name: blue\n    hsv: {h: [95, 125], s: [80, 255], v: [40, 255]}\n";
  const std::string display = StartXvfb("1366x768x24");
  ASSERT_FALSE(display.empty()) << "Xvfb did not start";
  live_ = Spawn({binary_, "live", "--input", video, "--config", config, "--no-trackbars"},
                {"DISPLAY=" + display}, true);
  ASSERT_GT(live_.pid, 0);
  std::string output;
  ASSERT_TRUE(WaitForOutput(live_, "end of input", 60s, &output)) << output;
  const std::vector<std::string> env = {"DISPLAY=" + display};
  std::string out;
  ASSERT_EQ(FocusLiveWindow(env, &out), 0) << out;
  // The layout the window uses for this frame on this screen (Xvfb puts the window at 0,0).
  // A file: the status band and the timeline under the image.
  const LiveLayout layout = ComputeLiveLayout(scene.size, 180, 0, MaxCanvasForScreen({1366, 768}),
                                              StatusBandHeight(), /*timeline=*/true);
  ASSERT_LE(layout.canvas.width, 1366);
  ASSERT_LE(layout.canvas.height, 768);
  const auto rings_on = [&](const cv::Mat& screen, int index, int m) {
    const cv::Point2d at = layout.to_view(*truth[index].markers[m].centroid_px);
    return RingPoints(screen, at, cvRound(12 * layout.scale_x()));
  };
  const auto expect_rings_on = [&](int index) {
    const cv::Mat screen = ScreenWhen([&](const cv::Mat& on_screen) {
      return rings_on(on_screen, index, 0) >= 18 && rings_on(on_screen, index, 1) >= 18;
    });
    ASSERT_FALSE(screen.empty());
    // The strip chart's dark background is on screen, under the scaled image.
    const cv::Rect chart = layout.chart & cv::Rect(0, 0, screen.cols, screen.rows);
    EXPECT_EQ(chart, layout.chart);
    EXPECT_LT(cv::mean(screen(chart))[0], 70);
    for (int m = 0; m < 2; ++m) {
      EXPECT_GE(rings_on(screen, index, m), 18) << truth[index].markers[m].name << " frame " << index;
    }
  };
  expect_rings_on(11);
  // Two steps back: frame 9, said on stdout and shown.
  ASSERT_EQ(RunProcess({"xdotool", "key", "comma"}, env, &out), 0) << out;
  ASSERT_TRUE(WaitForOutput(live_, "live: frame 10 ", 20s, &output)) << output;
  ASSERT_EQ(RunProcess({"xdotool", "key", "comma"}, env, &out), 0) << out;
  ASSERT_TRUE(WaitForOutput(live_, "live: frame 9 ", 20s, &output)) << output;
  expect_rings_on(9);
  // A click at blue's scaled place picks blue's colours around that image pixel.
  const cv::Point2d blue = layout.to_view(*truth[9].markers[1].centroid_px);
  ASSERT_EQ(RunProcess({"xdotool", "key", "2", "mousemove", std::to_string(cvRound(blue.x)),
                        std::to_string(cvRound(blue.y)), "click", "1", "sleep", "0.3", "key", "s"},
                       env, &out),
            0)
      << out;
  ASSERT_TRUE(WaitForOutput(live_, "live: saved", 20s, &output)) << output;
  const TrackingConfig picked = LoadTrackingConfig((dir_ / "markers.live.yaml").string());
  const MarkerSpec& spec = picked.markers[1];
  ASSERT_TRUE(spec.params.get<ColourParams>().roi);
  const cv::Point2d centre(spec.params.get<ColourParams>().roi->x + spec.params.get<ColourParams>().roi->width / 2.0,
                           spec.params.get<ColourParams>().roi->y + spec.params.get<ColourParams>().roi->height / 2.0);
  EXPECT_NEAR(centre.x, truth[9].markers[1].centroid_px->x, 0.5 / layout.scale_x() + 1.0);
  EXPECT_NEAR(centre.y, truth[9].markers[1].centroid_px->y, 0.5 / layout.scale_y() + 1.0);
  ASSERT_EQ(RunProcess({"xdotool", "key", "q"}, env, &out), 0) << out;
  EXPECT_EQ(WaitExit(live_, 20s), 0);
  live_.pid = -1;
}

// Record, pause, switch every marker to template matching and drag a new template for blue on
// the paused frame, resume, stop: the CSV names the source's frames, and `track` on the raw
// recording with its saved config (which keeps the edits) gives the same rows.
TEST_F(LiveWindowTest, RecordingAPausedVideoWithEditsKeepsTheSourcesFramesAndTrackReproducesIt) {
  // A 3 s rendered video at 30 fps, played by the real window.
  SyntheticScene renderer(testing::LiveTestScene(90, 90));
  const std::string video = (dir_ / "scene.avi").string();
  testing::WriteSceneVideo(renderer, 90, video);
  const std::string config = (dir_ / "markers.yaml").string();
  std::ofstream(config) << testing::kLiveTestMarkersYaml;
  const std::string display = StartXvfb();
  ASSERT_FALSE(display.empty()) << "Xvfb did not start";
  live_ = Spawn({binary_, "live", "--input", video, "--config", config, "--no-trackbars",
                 "--record-prefix", (dir_ / "rec").string()},
                {"DISPLAY=" + display}, true);
  ASSERT_GT(live_.pid, 0);
  const std::vector<std::string> env = {"DISPLAY=" + display};
  std::string out;
  ASSERT_EQ(FocusLiveWindow(env, &out), 0) << out;
  // Record, pause, resume, stop: each key once the window has said it handled the one before
  // (its messages on stdout), so no key waits on a clock. How many frames fall between the keys
  // depends on the machine; what is checked below holds for any number (the window reads keys
  // only after a frame is on screen, so `r` always has a frame to start with).
  std::string output;
  const auto key_then = [&](const std::string& key, const std::string& said) {
    ASSERT_EQ(RunProcess({"xdotool", "key", key}, env, &out), 0) << out;
    ASSERT_TRUE(WaitForOutput(live_, said, 60s, &output)) << key << ": " << output;
  };
  key_then("r", "live: recording to ");
  key_then("space", "live: paused");
  // One step: the window says which frame is on screen, so the drag can be put around blue.
  key_then("period", "live: frame ");
  const size_t said = output.rfind("live: frame ") + std::string("live: frame ").size();
  ASSERT_TRUE(output.find(" s)\n", said) != std::string::npos ||
              WaitForOutput(live_, " s)\n", 20s, &output))
      << output;
  const int on_screen = std::stoi(output.substr(said));
  key_then("m", "live: method: sad");
  cv::Mat image;
  // The window is at 0,0 and the 320x240 frame is not scaled on this screen.
  const cv::Point2d blue = *renderer.render(on_screen, image).markers[1].centroid_px;
  const cv::Point from(cvRound(blue.x) - 10, cvRound(blue.y) - 12);
  const cv::Point to(cvRound(blue.x) + 13, cvRound(blue.y) + 10);
  ASSERT_EQ(RunProcess({"xdotool", "mousemove", std::to_string(from.x), std::to_string(from.y),
                        "mousedown", "1", "mousemove", std::to_string(from.x + 5),
                        std::to_string(from.y + 5), "mousemove", std::to_string(to.x),
                        std::to_string(to.y), "mouseup", "1"},
                       env, &out),
            0)
      << out;
  ASSERT_TRUE(WaitForOutput(live_, "live: blue: reselected", 20s, &output)) << output;
  key_then("space", "live: running");
  key_then("r", "live: recorded ");
  ASSERT_TRUE(WaitForOutput(live_, "end of input", 60s, &output)) << output;
  ASSERT_EQ(RunProcess({"xdotool", "key", "q"}, env, &out), 0) << out;
  EXPECT_EQ(WaitExit(live_, 20s), 0);

  // Every row is a source frame: consecutive indices, the file's timestamps.
  const std::string prefix = (dir_ / "rec-001").string();
  std::vector<std::string> rows = CsvRowsWithoutTiming(prefix + ".csv");
  ASSERT_GE(rows.size(), 2u) << "no recording: " << output;
  const CsvTable table = ReadCsvTable(prefix + ".csv");
  const size_t frame = *table.find("frame"), time = *table.find("time_s");
  const double first = *table.values[frame][0];
  for (size_t row = 0; row < table.row_count(); ++row) {
    EXPECT_EQ(*table.values[frame][row], first + row) << "row " << row;
    EXPECT_NEAR(*table.values[time][row], (first + row) / 30.0, 1e-6) << "row " << row;
  }
  // `softsight track` on the raw recording with the saved config: the same rows.
  const std::string again = (dir_ / "again.csv").string();
  ASSERT_EQ(RunProcess({binary_, "track", "--config", prefix + ".yaml", "--input",
                        prefix + ".raw.avi", "--csv", again},
                       {}, &out),
            0)
      << out;
  EXPECT_EQ(CsvRowsWithoutTiming(again), rows);
  // The edits are in the recording's config, after the frame they were made on.
  const TrackingConfig recorded = LoadTrackingConfig(prefix + ".yaml");
  ASSERT_FALSE(recorded.changes.empty());
  EXPECT_EQ(recorded.changes.back().kind, ConfigChange::Kind::kReselect);
  EXPECT_EQ(recorded.changes.back().marker, "blue");
  EXPECT_EQ(recorded.changes.back().after_frame, on_screen - static_cast<int64_t>(first));
}

TEST_F(LiveWindowTest, WithoutADisplayOneErrorSuggestsTrack) {
  std::string output;
  const int code = RunProcess({binary_, "live", "--input", "x.avi", "--config", "markers.yaml"},
                              {"DISPLAY=", "WAYLAND_DISPLAY="}, &output);
  EXPECT_EQ(code, 2) << output;
  EXPECT_NE(output.find("softsight track"), std::string::npos) << output;
  EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;

  output.clear();
  EXPECT_EQ(RunProcess({binary_, "live", "--input", "x.avi", "--config", "markers.yaml"},
                       {"DISPLAY=:59999", "WAYLAND_DISPLAY="}, &output),
            2)
      << output;
  EXPECT_NE(output.find("cannot open display ':59999'"), std::string::npos) << output;
}

// Issue 47's done line: a Python hook in `live --input synth:bending` adds its own column to the
// CSV and the stream, with the values it computed (the markers' x summed, checked against the
// CSV's own columns); `listen` gets the same column and values.
TEST_F(LiveWindowTest, APythonHookAddsItsColumnToTheCsvAndTheStream) {
  const std::string config = (dir_ / "markers.yaml").string();
  std::ofstream(config) << testing::kScaledSceneMarkersYaml;
  const std::string hook = (dir_ / "h.py").string();
  std::ofstream(hook) << "columns = ['x_sum']\n"
                         "def on_frame(frame, result):\n"
                         "    if all(m.found for m in result.markers):\n"
                         "        return {'x_sum': sum(m.x for m in result.markers)}\n";
  const std::string csv = (dir_ / "out.csv").string(), heard = (dir_ / "heard.csv").string();
  const std::string endpoint = "ipc://" + (dir_ / "s.ipc").string();
  const std::string display = StartXvfb();
  ASSERT_FALSE(display.empty()) << "Xvfb did not start";
  Child listen = Spawn({binary_, "listen", endpoint, "--csv", heard, "--quiet", "--timeout-s", "60"},
                       {}, true);
  ASSERT_GT(listen.pid, 0);
  live_ = Spawn({binary_, "live", "--input", "synth:bending", "--config", config, "--no-trackbars",
                 "--no-pace", "--hook", hook, "--csv", csv, "--publish", endpoint,
                 "--publish-wait", "1"},
                {"DISPLAY=" + display}, true);
  ASSERT_GT(live_.pid, 0);
  std::string output;
  ASSERT_TRUE(WaitForOutput(live_, "end of input", 60s, &output)) << output;
  const std::vector<std::string> env = {"DISPLAY=" + display};
  std::string out;
  ASSERT_EQ(FocusLiveWindow(env, &out), 0) << out;
  ASSERT_EQ(RunProcess({"xdotool", "key", "q"}, env, &out), 0) << out;
  WaitForOutput(live_, "\x01never", 20s, &output);  // The summary, until it exits.
  EXPECT_EQ(WaitExit(live_, 20s), 0) << output;
  live_.pid = -1;
  EXPECT_THAT(output, ::testing::HasSubstr("hook " + hook + ": values in 300 of 300 rows"));
  std::string listened;
  WaitForOutput(listen, "\x01never", 20s, &listened);
  EXPECT_EQ(WaitExit(listen, 20s), 0) << listened;

  const CsvTable table = ReadCsvTable(csv);
  ASSERT_EQ(table.row_count(), 300u);
  const size_t sum = table.find("x_sum").value();
  int summed = 0;
  for (size_t r = 0; r < table.row_count(); ++r) {
    const auto x = [&](const char* name) { return table.values[table.find(name).value()][r]; };
    if (x("red_x") && x("blue_x") && x("green_x")) {
      ASSERT_TRUE(table.values[sum][r]) << r;
      EXPECT_NEAR(*table.values[sum][r], *x("red_x") + *x("blue_x") + *x("green_x"), 1e-3) << r;
      ++summed;
    } else {
      EXPECT_FALSE(table.values[sum][r]) << r;
    }
  }
  EXPECT_GT(summed, 250);
  const CsvTable stream = ReadCsvTable(heard);
  EXPECT_EQ(stream.columns, table.columns);
  ASSERT_EQ(stream.row_count(), table.row_count());
  EXPECT_EQ(stream.values[sum], table.values[sum]) << "the stream has the hook's values";
}

TEST_F(LiveWindowTest, PlotCommandWritesTheFigure) {
  const std::string csv = (dir_ / "run.csv").string();
  {
    std::ofstream out(csv);
    out << "frame,time_s,angle_deg,chord_px,sagitta_px,radius_px,arc_length_px,tip_disp_px,proc_"
           "ms\n";
    for (int i = 0; i < 50; ++i) {
      out << i << "," << i / 25.0 << "," << 180 - i << ",100,5,80," << 120 + i << ",";
      if (i % 10 != 5) out << i * 0.5;  // A few empty fields.
      out << ",1.0\n";
    }
  }
  std::string output;
  EXPECT_EQ(RunProcess({binary_, "plot", csv, "-o", (dir_ / "run.png").string()}, {}, &output), 0)
      << output;
  EXPECT_TRUE(fs::exists(dir_ / "run.png"));
  EXPECT_EQ(RunProcess({binary_, "plot", csv, "-o", (dir_ / "run.svg").string(), "--width", "600"},
                       {}, &output),
            0)
      << output;
  std::ifstream svg(dir_ / "run.svg");
  std::stringstream text;
  text << svg.rdbuf();
  EXPECT_NE(text.str().find("width=\"600\""), std::string::npos);
  output.clear();
  EXPECT_EQ(
      RunProcess({binary_, "plot", (dir_ / "missing.csv").string(), "-o", "x.png"}, {}, &output),
      2);
  EXPECT_NE(output.find("missing.csv"), std::string::npos) << output;
}

// `track-stereo --window` on a pair of rendered videos: both views side by side with their
// overlay on the real screen, space pauses (the run waits), q stops; at the end of the input or
// --max-frames the window closes by itself, and the CSV is the one written without the window.
class TrackStereoWindowTest : public LiveWindowTest {
 protected:
  static constexpr int kFrames = 12;
  void SetUp() override {
    LiveWindowTest::SetUp();
    StereoSceneOptions options;
    options.frame_count = kFrames;
    options.max_bend_deg = 90.0;
    scene_ = std::make_unique<StereoScene>(MakeStereoRig(), options);
    // 1 fps: played at its pace, the window is on screen for 12 s, time to press keys on a
    // loaded machine too (the pause ends the wait; at 2 fps a clean-clone CI run beside the
    // sanitizer build ended before xdotool's key arrived).
    FrameWriterOptions left_video, right_video;
    left_video.path = (dir_ / "left.avi").string();
    right_video.path = (dir_ / "right.avi").string();
    left_video.fps = right_video.fps = 1.0;
    FrameWriter left_writer(left_video), right_writer(right_video);
    cv::Mat left, right;
    for (int i = 0; i < kFrames; ++i) {
      truths_.push_back(scene_->render(i, left, right));
      left_writer.write(left, i);
      right_writer.write(right, i);
    }
    left_writer.close();
    right_writer.close();
    StereoCalibrationResult rig;
    rig.stereo = testing::CalibrationOfRig(scene_->rig());
    SaveStereoCalibration(rig, ChessboardSpec{}, (dir_ / "stereo.yaml").string());
    std::ofstream((dir_ / "markers.yaml").string()) << testing::StereoMarkersYaml();
  }
  std::vector<std::string> Command(const std::string& csv) const {
    return {binary_,          "track-stereo",  "-c",
            (dir_ / "markers.yaml").string(), "--left", (dir_ / "left.avi").string(),
            "--right",        (dir_ / "right.avi").string(), "--stereo",
            (dir_ / "stereo.yaml").string(),  "--frame-offset", "0",
            "--csv",          (dir_ / csv).string()};
  }
  // The CSV's rows without proc_ms (the last column: timing).
  std::vector<std::string> Rows(const std::string& csv) const {
    std::ifstream in(dir_ / csv);
    std::vector<std::string> rows;
    for (std::string line; std::getline(in, line);) rows.push_back(line.substr(0, line.rfind(',')));
    return rows;
  }
  std::unique_ptr<StereoScene> scene_;
  std::vector<StereoSceneTruth> truths_;
};

TEST_F(TrackStereoWindowTest, ClosesByItselfAtTheEndOrMaxFramesWithTheSameCsvAsWithout) {
  std::string output;
  ASSERT_EQ(RunProcess(Command("plain.csv"), {}, &output), 0) << output;
  const std::vector<std::string> plain = Rows("plain.csv");
  ASSERT_EQ(plain.size(), kFrames + 1u) << output;

  // A screen tall enough for two 640x480 views, the status band and the chart at full size.
  const std::string display = StartXvfb("1400x900x24");
  ASSERT_FALSE(display.empty()) << "Xvfb did not start";
  const std::vector<std::string> env = {"DISPLAY=" + display};
  // To the end of the input, unpaced: the window closes by itself, the CSV is the same.
  output.clear();
  std::vector<std::string> windowed = Command("window.csv");
  windowed.insert(windowed.end(), {"--window", "--no-pace"});
  ASSERT_EQ(RunProcess(windowed, env, &output), 0) << output;
  EXPECT_NE(output.find("12 pairs of frames"), std::string::npos) << output;
  EXPECT_EQ(Rows("window.csv"), plain);
  // --max-frames: as many rows, the first ones.
  output.clear();
  windowed = Command("max.csv");
  windowed.insert(windowed.end(), {"--window", "--no-pace", "--max-frames", "5"});
  ASSERT_EQ(RunProcess(windowed, env, &output), 0) << output;
  EXPECT_EQ(Rows("max.csv"), std::vector<std::string>(plain.begin(), plain.begin() + 6));
}

TEST_F(TrackStereoWindowTest, BothViewsOnScreenAndSpacePausesAndQStops) {
  const std::string display = StartXvfb("1400x900x24");
  ASSERT_FALSE(display.empty()) << "Xvfb did not start";
  const std::vector<std::string> env = {"DISPLAY=" + display};
  // Paced at 1 fps: pause once the window is up, look at it, then stop it with q.
  std::vector<std::string> paced = Command("stopped.csv");
  paced.push_back("--window");
  live_ = Spawn(paced, env, true);
  ASSERT_GT(live_.pid, 0);
  std::string output, xdotool_output;
  ASSERT_EQ(RunProcess({"xdotool", "search", "--sync", "--onlyvisible", "--name",
                        "softsight track-stereo", "windowfocus", "--sync", "key", "space"},
                       env, &xdotool_output),
            0)
      << xdotool_output;
  ASSERT_TRUE(WaitForOutput(live_, "window: paused at frame ", 20s, &output)) << output;
  const size_t at = output.find("window: paused at frame ") + 24;
  const int paused = std::stoi(output.substr(at));
  ASSERT_GE(paused, 0);
  ASSERT_LT(paused, kFrames) << "ended before the pause";
  // The window at the screen's top-left (no window manager), the views at full size side by
  // side: each marker's ring around its true position in each view of the paused pair.
  const cv::Mat screen = ScreenWhen([&](const cv::Mat& on_screen) {
    for (const StereoMarkerTruth& m : truths_[paused].markers) {
      if (RingPoints(on_screen, m.left_px) < 20 ||
          RingPoints(on_screen, m.right_px + cv::Point2d(640, 0)) < 20) {
        return false;
      }
    }
    return true;
  });
  ASSERT_FALSE(screen.empty()) << "cannot read Xvfb's screen file";
  for (const StereoMarkerTruth& m : truths_[paused].markers) {
    EXPECT_GE(RingPoints(screen, m.left_px), 20) << m.name << " left, frame " << paused;
    EXPECT_GE(RingPoints(screen, m.right_px + cv::Point2d(640, 0)), 20)
        << m.name << " right, frame " << paused;
  }
  // The chart under the views: its dark background.
  EXPECT_LT(cv::mean(screen(cv::Rect(0, 480 + StatusBandHeight(), 1280, 200)))[0], 70);
  // Paused, the run waited: q stops it after the pair on screen.
  ASSERT_EQ(RunProcess({"xdotool", "key", "q"}, env, &xdotool_output), 0) << xdotool_output;
  WaitForOutput(live_, "stopped from the window", 20s, &output);
  EXPECT_EQ(WaitExit(live_, 20s), 0) << output;
  EXPECT_NE(output.find("stopped from the window"), std::string::npos) << output;
  // The rows up to the pair paused on, each pair's frames, all markers found in 3D.
  const std::vector<std::map<std::string, std::string>> rows =
      testing::ReadRows((dir_ / "stopped.csv").string());
  ASSERT_EQ(rows.size(), paused + 1u);
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].at("frame"), std::to_string(i));
    EXPECT_EQ(rows[i].at("right_frame"), std::to_string(i));
    for (const char* marker : {"red", "blue", "green"}) {
      EXPECT_EQ(rows[i].at(std::string(marker) + "_status"), "found") << marker << " " << i;
    }
  }
}

}  // namespace
}  // namespace softsight
