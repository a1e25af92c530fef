// End-to-end tests of `softsight control` and `softsight rig`: the whole loop, rig -> rendered
// frames -> tracker -> controller -> serial (a real pseudo-terminal) -> rig.
#include "app/control_command.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/syscall.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/program_test_util.h"
#include "app/stop_request.h"
#include "app/scene_markers_test_util.h"
#include "core/test_util.h"
#include "control/protocol.h"
#include "softsight/core/error.h"
#include "softsight/config/control_config.h"

namespace softsight {
namespace {

using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using testing::ReadLines;
using testing::ReadTextFile;
using testing::SplitCsv;
using testing::TempDir;
using testing::WriteTextFile;

// The markers of examples/rig.yaml (the synthetic scene's); the control section stays at its
// defaults, which are the example's values.
const char* const kMarkers = testing::kSceneMarkersYaml;

TEST(ControlConfig, ReadsTheExampleAndRejectsBadKeys) {
  const ControlConfig config = LoadControlConfig(testing::RigExample());
  EXPECT_DOUBLE_EQ(config.controller.kp_kpa_per_deg, 0.25);
  EXPECT_DOUBLE_EQ(config.controller.hold_s, 0.5);
  EXPECT_EQ(config.link.baud, 115200);
  EXPECT_EQ(config.rig.board.pressure_limit_pa, 50000);
  EXPECT_EQ(config.rig.board.deadband_pa, 150);
  EXPECT_DOUBLE_EQ(config.rig.plant.chamber_volume_ml, 20.0);

  TempDir dir;
  auto error_of = [&](const std::string& text) {
    WriteTextFile(dir.file("c.yaml"), text);
    try {
      LoadControlConfig(dir.file("c.yaml"));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(error_of("control:\n  controller:\n    kp: 1\n"),
              HasSubstr("c.yaml:3: control.controller.kp"));
  EXPECT_THAT(error_of("control:\n  controller:\n    kp_kpa_per_deg: -1\n"),
              HasSubstr("control.controller.kp_kpa_per_deg: -1 must lie within 0..100"));
  EXPECT_THAT(error_of("control:\n  controller:\n    min_kpa: 10\n    max_kpa: 5\n"),
              HasSubstr("control.controller.max_kpa: 5 must be above min_kpa (10)"));
  EXPECT_THAT(error_of("control:\n  link:\n    baud: 12345\n"), HasSubstr("control.link.baud"));
  EXPECT_THAT(error_of("control:\n  rig:\n    board:\n      loop_hz: 100\n"),
              HasSubstr("control.rig.board.loop_hz: 100 must lie within 200..5000"));
  EXPECT_THAT(error_of("control:\n  rig:\n    plant: {chamber_volume_ml: 0}\n"),
              HasSubstr("chamber_volume_ml"));
}

// The simulated rig's step from straight (180 deg) to 120 deg over 4 s, its CSV in `dir`.
ControlOptions SimulatedStepTo120(const TempDir& dir) {
  WriteTextFile(dir.file("rig.yaml"), kMarkers);
  ControlOptions options;
  options.config_file = dir.file("rig.yaml");
  options.simulate = true;
  options.target_deg = 120.0;
  options.duration_s = 4.0;
  options.csv_file = dir.file("run.csv");
  options.quiet = true;
  return options;
}

TEST(ControlCommand, SimulatedRigStepTo120DegreesThroughTheTracker) {
  TempDir dir;
  const ControlOptions options = SimulatedStepTo120(dir);
  const ControlSummary summary = RunControl(options);
  EXPECT_EQ(summary.run.frames, 121);
  EXPECT_EQ(summary.run.measured, 121);
  ASSERT_TRUE(summary.final_error_deg);
  EXPECT_LT(std::abs(*summary.final_error_deg), 2.0);
  EXPECT_EQ(summary.link_rejected, 0u);

  const std::vector<std::string> lines = ReadLines(options.csv_file);
  ASSERT_EQ(lines.size(), 122u);
  const std::vector<std::string> header = SplitCsv(lines[0]);
  auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name;
    return static_cast<size_t>(it - header.begin());
  };
  const size_t angle = column("angle_deg"), truth = column("rig_true_angle_deg"),
               target = column("target_deg"), pressure = column("board_pressure_kpa");
  // Capture -> result -> serial command -> CSV row, in that order, every frame.
  const size_t to_result = column("latency_result_ms"), to_command = column("latency_command_ms"),
               to_row = column("latency_row_ms");
  EXPECT_LT(to_result, to_command);
  EXPECT_LT(to_command, to_row);
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> row = SplitCsv(lines[i]);
    ASSERT_GT(row.size(), to_row);
    EXPECT_GE(std::stod(row[to_result]), 0.0) << "row " << i;
    EXPECT_LE(std::stod(row[to_result]), std::stod(row[to_command])) << "row " << i;
    EXPECT_LE(std::stod(row[to_command]), std::stod(row[to_row])) << "row " << i;
  }
  // The tracker's angle against the rig's truth, and the settled result.
  double worst_tracking_deg = 0.0;
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> row = SplitCsv(lines[i]);
    ASSERT_GT(row.size(), pressure);
    worst_tracking_deg =
        std::max(worst_tracking_deg, std::abs(std::stod(row[angle]) - std::stod(row[truth])));
    EXPECT_DOUBLE_EQ(std::stod(row[target]), 120.0);
  }
  const std::vector<std::string> last = SplitCsv(lines.back());
  std::printf("simulated loop through the tracker: final true angle %.2f deg, worst tracking "
              "error %.2f deg\n", std::stod(last[truth]), worst_tracking_deg);
  EXPECT_NEAR(std::stod(last[truth]), 120.0, 2.0);
  EXPECT_LT(worst_tracking_deg, 1.5);
  EXPECT_GT(std::stod(last[pressure]), 20.0);
}

// The summary's step figures (rise, settling +-1 / +-2 deg, overshoot, steady-state error, RMS
// error) are those of the run's own angle: recomputed from the CSV they agree, they are printed,
// and --metrics-csv writes them.
TEST(ControlCommand, SimulatedStepSummaryGivesRiseSettlingOvershootSteadyStateAndRms) {
  TempDir dir;
  ControlOptions options = SimulatedStepTo120(dir);
  options.metrics_csv_file = dir.file("metrics.csv");
  const ControlSummary summary = RunControl(options);
  const StepMetrics& m = summary.metrics;
  ASSERT_TRUE(m.rise_time_s && m.settling_1deg_s && m.settling_2deg_s && m.overshoot_percent &&
              m.steady_state_error_deg && m.rms_error_deg)
      << FormatStepMetrics(m);
  std::printf("simulated step 180 -> 120 deg: %s\n", FormatStepMetrics(m).c_str());
  // A step from straight: rises, settles within +-2 deg no later than within +-1 deg, under 3 s.
  EXPECT_NEAR(*m.step_to_deg, 120.0, 1e-9);
  EXPECT_GT(*m.step_from_deg, 170.0);
  EXPECT_GT(*m.rise_time_s, 0.0);
  EXPECT_LE(*m.settling_2deg_s, *m.settling_1deg_s);
  EXPECT_LT(*m.settling_1deg_s, 3.0);
  EXPECT_LT(*m.overshoot_percent, 10.0);
  EXPECT_LT(std::abs(*m.steady_state_error_deg), 1.0);

  // The same figures from the CSV's columns.
  const std::vector<std::string> lines = ReadLines(options.csv_file);
  const std::vector<std::string> header = SplitCsv(lines[0]);
  auto column = [&](const std::string& name) {
    return static_cast<size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const size_t time = column("time_s"), angle = column("angle_deg"), target = column("target_deg");
  std::vector<TrackingPoint> points;
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> row = SplitCsv(lines[i]);
    TrackingPoint p;
    p.time_s = std::stod(row[time]);
    p.target_deg = std::stod(row[target]);
    if (!row[angle].empty()) p.measured_deg = std::stod(row[angle]);
    points.push_back(p);
  }
  const StepMetrics again = ComputeStepMetrics(points);
  // The CSV's numbers are rounded: figures agree to the CSV's precision (times to a frame).
  EXPECT_NEAR(*again.rise_time_s, *m.rise_time_s, 1e-3);
  EXPECT_NEAR(*again.settling_1deg_s, *m.settling_1deg_s, 1.0 / 30);
  EXPECT_NEAR(*again.settling_2deg_s, *m.settling_2deg_s, 1.0 / 30);
  EXPECT_NEAR(*again.overshoot_percent, *m.overshoot_percent, 1e-2);
  EXPECT_NEAR(*again.steady_state_error_deg, *m.steady_state_error_deg, 1e-3);
  EXPECT_NEAR(*again.rms_error_deg, *m.rms_error_deg, 1e-3);

  const std::string printed = FormatControlSummary(summary);
  // The rendered rig ends at the duration: the run's own stop, in the loop's words.
  EXPECT_EQ(summary.run.stop_reason, StopReason::kEndOfInput);
  EXPECT_EQ(summary.run.stop_text(), "duration reached");
  EXPECT_THAT(printed, HasSubstr(" s (duration reached), angle measured in "));
  for (const char* figure : {"rise (10-90 %)", "settling +-1 deg", "+-2 deg", "overshoot",
                             "steady-state error", "RMS error"}) {
    EXPECT_NE(printed.find(figure), std::string::npos) << figure << " in\n" << printed;
  }
  const std::vector<std::string> metrics = ReadLines(options.metrics_csv_file);
  ASSERT_EQ(metrics.size(), 2u);
  EXPECT_EQ(metrics[0].rfind("step_time_s,", 0), 0u);
}

// Why a control run stopped is its RunSummary's (no second copy in ControlSummary): the printed
// summary says the run's stop, an error with the frame it stopped at, and an identification
// stopped by a signal is told from one that finished by the run's stop and its missing model.
TEST(ControlSummary, SaysWhyTheRunStoppedFromTheRunsOwnStop) {
  ControlSummary s;
  s.run.frames = 7;
  s.duration_s = 0.25;
  s.run.stop_reason = StopReason::kStopRequested;
  s.run.stop_detail = StopSignalReason(SIGTERM);
  EXPECT_THAT(FormatControlSummary(s), HasSubstr("frames: 7 over 0.25 s (stopped by SIGTERM)"));
  EXPECT_TRUE(IdentificationStoppedBySignal(s));
  s.identified.emplace();  // The experiment finished: its controller stopped the run.
  s.run.stop_detail = "duration reached";
  EXPECT_FALSE(IdentificationStoppedBySignal(s));
  EXPECT_THAT(FormatControlSummary(s), HasSubstr("frames: 7 over 0.25 s (duration reached)"));
  s.identified.reset();
  s.run.stop_reason = StopReason::kError;
  s.run.stop_detail.clear();
  s.run.error = "/dev/ttyACM0: the port disappeared";
  EXPECT_FALSE(IdentificationStoppedBySignal(s));
  EXPECT_THAT(FormatControlSummary(s),
              HasSubstr("frames: 7 over 0.25 s (stopped by an error at frame 7)"));
  s.run.stop_reason = StopReason::kEndOfInput;
  s.run.error.clear();
  EXPECT_FALSE(IdentificationStoppedBySignal(s));
  EXPECT_THAT(FormatControlSummary(s), HasSubstr("(end of input)"));
}

TEST(ControlCommand, RefusesAmbiguousTargetsAndSources) {
  ControlOptions options;
  options.config_file = testing::RigExample();
  options.simulate = true;
  options.csv_file = "/nonexistent/x.csv";
  EXPECT_THROW(RunControl(options), InputError);  // No target.
  options.target_deg = 120.0;
  options.pwm = 0.5;
  EXPECT_THROW(RunControl(options), InputError);  // Two targets.
  options.pwm.reset();
  options.port = "/dev/ttyACM0";
  EXPECT_THROW(RunControl(options), InputError);  // Board and simulation.
}

// Camera settings for frames that come from no camera cannot be carried out: refused, naming the
// option and where the frames come from, before a port is opened or a file written.
TEST(ControlCommand, RefusesCameraSettingsWithoutACamera) {
  ControlOptions options;
  options.config_file = testing::RigExample();
  options.simulate = true;
  options.target_deg = 120.0;
  options.csv_file = "/nonexistent/x.csv";
  options.capture_args["fps"] = "30";
  try {
    RunControl(options);
    FAIL() << "camera settings for the simulated rig were accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--camera-fps 30: camera settings apply to a camera "
                                    "(--camera N), and the frames come from the simulated rig"));
  }
}

TEST(ControlCommand, RefusesNonFiniteAndOutOfRangeNumbersNamingTheOption) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto error_of = [](ControlOptions options) {
    options.config_file = testing::RigExample();
    options.simulate = true;
    options.csv_file = "/nonexistent/never-written.csv";
    try {
      RunControl(options);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  for (double bad : {nan, inf, -inf, -1.0, 181.0}) {
    ControlOptions o;
    o.target_deg = bad;
    EXPECT_THAT(error_of(o), HasSubstr("--target-deg ")) << bad;
  }
  for (double bad : {nan, inf, -1.0, 1e4}) {
    ControlOptions o;
    o.pressure_kpa = bad;
    EXPECT_THAT(error_of(o), HasSubstr("--pressure-kpa ")) << bad;
  }
  for (double bad : {nan, inf, -1.5, 2.0}) {
    ControlOptions o;
    o.pwm = bad;
    EXPECT_THAT(error_of(o), HasSubstr("--pwm ")) << bad;
  }
  for (double bad : {nan, inf, -1.0, 0.0}) {
    ControlOptions o;
    o.target_deg = 120.0;
    o.duration_s = bad;
    EXPECT_THAT(error_of(o), HasSubstr("--duration-s ")) << bad;
  }
  for (double bad : {nan, inf, 0.0}) {
    ControlOptions o;
    o.target_deg = 120.0;
    o.fps = bad;
    EXPECT_THAT(error_of(o), HasSubstr("--fps ")) << bad;
  }
  ControlOptions o;
  o.duration_s = nan;
  o.target_deg = 120.0;
  EXPECT_EQ(error_of(o), "--duration-s nan: must be a number in (0, 604800]");
  // Through the program: one line, exit code 2.
  TempDir dir;
  const std::string command = std::string("\"") + testing::SoftsightBinary() +
                              "\" control --config " + testing::RigExample() + " --simulate --pwm nan --csv " +
                              dir.file("x.csv") + " 2> " + dir.file("err.txt");
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_EQ(ReadTextFile(dir.file("err.txt")),
            "softsight control: error: --pwm nan: must be a number in [-1, 1]\n");
}

TEST(ControlCommand, APressureAboveMaxKpaIsClampedAndSaidOnce) {
  TempDir dir;
  WriteTextFile(dir.file("rig.yaml"),
                std::string(kMarkers) + "control:\n  controller:\n    max_kpa: 45\n");
  ControlOptions options;
  options.config_file = dir.file("rig.yaml");
  options.simulate = true;
  options.pressure_kpa = 49.0;
  options.duration_s = 0.2;
  options.sim_supersample = 1;
  options.csv_file = dir.file("run.csv");
  options.quiet = true;
  ::testing::internal::CaptureStderr();
  RunControl(options);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(err,
            "control: --pressure-kpa 49 is above the limit of 45 kPa (control.controller.max_kpa, "
            "at most the board's limit); sending 45 kPa\n");
  const std::vector<std::string> lines = ReadLines(options.csv_file);
  ASSERT_GT(lines.size(), 2u);
  const std::vector<std::string> header = SplitCsv(lines[0]);
  const size_t setpoint =
      static_cast<size_t>(std::find(header.begin(), header.end(), "setpoint_kpa") - header.begin());
  ASSERT_LT(setpoint, header.size());
  for (size_t i = 1; i < lines.size(); ++i) {
    EXPECT_DOUBLE_EQ(std::stod(SplitCsv(lines[i])[setpoint]), 45.0) << lines[i];
  }
}

// Starts `softsight rig --pty ...`; returns its pid and the pty path it printed. Its stderr goes
// to `stderr_file`, or with `stderr_pipe` to a pipe whose reading end it returns there.
pid_t StartRig(const std::string& args, const std::string& stderr_file, std::string* port,
               int* stderr_pipe = nullptr) {
  int out[2];
  int err_pipe[2] = {-1, -1};
  if (pipe(out) != 0 || (stderr_pipe != nullptr && pipe(err_pipe) != 0)) return -1;
  const std::string command = std::string("exec \"") + testing::SoftsightBinary() +
                              "\" rig --pty " + args;
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(out[1], STDOUT_FILENO);
    const int err = stderr_pipe != nullptr
                        ? err_pipe[1]
                        : open(stderr_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(err, STDERR_FILENO);
    close(out[0]);
    if (stderr_pipe != nullptr) close(err_pipe[0]);
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(out[1]);
  if (stderr_pipe != nullptr) {
    close(err_pipe[1]);
    *stderr_pipe = err_pipe[0];
  }
  std::string line;
  char c;
  while (read(out[0], &c, 1) == 1 && c != '\n') line += c;
  close(out[0]);
  const std::string prefix = "rig: serving on ";
  if (line.rfind(prefix, 0) == 0) *port = line.substr(prefix.size());
  return pid;
}

// Reads `fd` into `text` until it contains `until` (or, with "", until end of file); false when
// nothing came for `timeout_ms`.
bool ReadUntil(int fd, const std::string& until, std::string* text, int timeout_ms = 10000) {
  while (until.empty() || text->find(until) == std::string::npos) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) <= 0) return false;
    char chunk[512];
    const ssize_t n = read(fd, chunk, sizeof(chunk));
    if (n <= 0) return until.empty();
    text->append(chunk, static_cast<size_t>(n));
  }
  return true;
}

TEST(ControlCommand, PortDisappearsMidRunOneErrorExitNonZeroCsvIntactRigVents) {
  TempDir dir;
  // A reply deadline no stall of a loaded machine reaches: a re-send would be answered twice and
  // take one of the rig's 40 answers from the rows counted below.
  WriteTextFile(dir.file("rig.yaml"),
                std::string(kMarkers) + "control:\n  link:\n    reply_timeout_ms: 3000\n");
  std::string port;
  const std::string frames = dir.file("rig.png");
  // The cable is pulled after the rig's 40th answer, when the host asks again (so it has read
  // all 40: a hang-up discards what it has not read): the handshake and 39 frames' exchanges,
  // however loaded the machine; --duration-s only bounds the rig if the test fails.
  int rig_stderr = -1;
  const pid_t rig = StartRig("--frames " + frames + " --fps 20 --disconnect-after-replies 40 "
                             "--duration-s 30",
                             "", &port, &rig_stderr);
  ASSERT_GT(rig, 0);
  ASSERT_THAT(port, HasSubstr("/dev/pts/"));
  const std::string command = std::string("\"") + testing::SoftsightBinary() +
                              "\" control --config " + dir.file("rig.yaml") + " --port " + port +
                              " --rig-frames " + frames + " --fps 20 --target-deg 120 --csv " +
                              dir.file("run.csv") + " --duration-s 10 2> " + dir.file("ctl.err");
  const int status = std::system(command.c_str());
  // The rig saw the port go. The actuator is vented: by the host's last command (on a loaded
  // machine the rig's frames come late, count as stale, and the loop holds then vents), or else
  // by the board's watchdog when the commands stop. Then the rig ends on SIGTERM.
  std::string rig_err;
  ASSERT_TRUE(ReadUntil(rig_stderr, "port closed", &rig_err)) << rig_err;
  const size_t last_state = rig_err.rfind(" s: board ", rig_err.find("port closed"));
  ASSERT_NE(last_state, std::string::npos) << rig_err;
  const bool vented_by_host =
      rig_err.compare(last_state, std::strlen(" s: board stopped (vented)"),
                      " s: board stopped (vented)") == 0;
  if (!vented_by_host) {
    EXPECT_TRUE(ReadUntil(rig_stderr, "board watchdog (vented)", &rig_err)) << rig_err;
  }
  kill(rig, SIGTERM);
  ReadUntil(rig_stderr, "", &rig_err);
  close(rig_stderr);
  int rig_status = 0;
  waitpid(rig, &rig_status, 0);

  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  const std::string ctl_err = ReadTextFile(dir.file("ctl.err"));
  const std::vector<std::string> err_lines = ReadLines(dir.file("ctl.err"));
  int error_lines = 0;
  for (const std::string& l : err_lines) error_lines += l.find("error") != std::string::npos;
  EXPECT_EQ(error_lines, 1) << ctl_err;
  EXPECT_THAT(ctl_err, HasSubstr("serial port " + port + ": "));
  EXPECT_THAT(ctl_err, HasSubstr("disconnected"));

  // Every row written before the error is complete.
  const std::vector<std::string> lines = ReadLines(dir.file("run.csv"));
  // The point does not depend on timing: one answer for the handshake, one per frame, so 39 rows
  // after the header.
  ASSERT_EQ(lines.size(), 40u);
  const size_t columns = SplitCsv(lines[0]).size();
  for (size_t i = 1; i < lines.size(); ++i) {
    EXPECT_EQ(SplitCsv(lines[i] + ",x").size(), columns + 1) << "row " << i << ": " << lines[i];
  }
  if (!vented_by_host) {
    EXPECT_THAT(rig_err, HasSubstr("board watchdog (vented)"));
  }
  EXPECT_THAT(rig_err, ContainsRegex("rig: stopped by SIGTERM after [0-9.]+ s; board [a-z]+ "
                                     "\\(vented\\)"));
  // After its summary: 128 + SIGTERM, as for a process the signal killed.
  EXPECT_TRUE(WIFEXITED(rig_status) && WEXITSTATUS(rig_status) == 143) << rig_err;
}

TEST(ControlCommand, AFrozenCameraIsNoMeasurementTheLoopHoldsThenVents) {
  // Hostile trial D18: the rig's frames file stops changing (a copy of one frame: a camera whose
  // driver hands out its last buffer, a relay that stalled). Every repeated picture is `stale`,
  // not a measurement: the loop holds, then vents, and says why; it never pumps to max_kpa on the
  // frozen angle.
  TempDir dir;
  WriteTextFile(dir.file("rig.yaml"), kMarkers);
  std::string port;
  const std::string live = dir.file("live.png"), frozen = dir.file("frozen.png");
  int rig_stderr = -1;
  const pid_t rig = StartRig("--frames " + live + " --fps 20 --duration-s 30", "", &port,
                             &rig_stderr);
  ASSERT_GT(rig, 0);
  std::filesystem::copy_file(live, frozen);  // Written before the rig serves.
  const std::string command = std::string("\"") + testing::SoftsightBinary() +
                              "\" control --config " + dir.file("rig.yaml") + " --port " + port +
                              " --rig-frames " + frozen + " --fps 20 --target-deg 120 --csv " +
                              dir.file("run.csv") + " --duration-s 1.5 2> " + dir.file("ctl.err");
  const int status = std::system(command.c_str());
  kill(rig, SIGTERM);
  std::string rig_err;
  ReadUntil(rig_stderr, "", &rig_err);
  close(rig_stderr);
  int rig_status = 0;
  waitpid(rig, &rig_status, 0);

  const std::string err = ReadTextFile(dir.file("ctl.err"));
  ASSERT_TRUE(WIFEXITED(status)) << err;
  EXPECT_THAT(err, HasSubstr("the camera repeated its last picture in "));
  EXPECT_THAT(err, HasSubstr("held, then vented"));
  // The board never pressurised on the frozen angle (the rest of the run: the rig vented).
  const size_t at = err.find("max board pressure ");
  ASSERT_NE(at, std::string::npos) << err;
  EXPECT_LT(std::stod(err.substr(at + std::strlen("max board pressure "))), 5.0) << err;
  const std::vector<std::string> lines = ReadLines(dir.file("run.csv"));
  ASSERT_GT(lines.size(), 3u);
  EXPECT_THAT(lines[0], HasSubstr("red_status"));
  EXPECT_THAT(lines.back(), HasSubstr("stale"));
}

TEST(ControlCommand, RigFramesThatAreAPipeAreOneErrorNotAHang) {
  // Hostile trial D8: a FIFO as --rig-frames blocked open() deaf to Ctrl-C and SIGTERM.
  TempDir dir;
  WriteTextFile(dir.file("rig.yaml"), kMarkers);
  ASSERT_EQ(::mkfifo(dir.file("fifo.png").c_str(), 0600), 0);
  std::string port;
  int rig_stderr = -1;
  const pid_t rig = StartRig("--frames " + dir.file("live.png") + " --duration-s 30", "", &port,
                             &rig_stderr);
  ASSERT_GT(rig, 0);
  const testing::ProgramRun run = testing::RunProgram(
      "control --config " + dir.file("rig.yaml") + " --port " + port + " --rig-frames " +
          dir.file("fifo.png") + " --target-deg 120 --csv " + dir.file("x.csv"),
      dir);
  kill(rig, SIGTERM);
  std::string rig_err;
  ReadUntil(rig_stderr, "", &rig_err);
  close(rig_stderr);
  waitpid(rig, nullptr, 0);
  EXPECT_EQ(run.exit_code, 2) << run.stderr_text;
  EXPECT_THAT(run.stderr_text, HasSubstr("fifo.png: not a regular file"));
}

TEST(ControlCommand, CtrlCVentsPrintsTheSummaryAndExits130) {
  TempDir dir;
  WriteTextFile(dir.file("rig.yaml"), kMarkers);
  const std::string csv = dir.file("run.csv");
  const int status = testing::RunAndSignalOnceRowsAreWritten(
      "control --config " + dir.file("rig.yaml") +
          " --simulate --target-deg 120 --duration-s 600 --csv " + csv,
      csv, 4, SIGINT, dir.file("ctl.err"));
  const std::string err = ReadTextFile(dir.file("ctl.err"));
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping cleanly: " << err;
  EXPECT_EQ(WEXITSTATUS(status), 130) << "128 + SIGINT, after the summary: " << err;
  EXPECT_THAT(err, HasSubstr("(stopped by Ctrl-C (SIGINT))"));
  EXPECT_THAT(err, HasSubstr("max board pressure")) << "the summary comes before the exit";
  const std::vector<std::string> lines = ReadLines(csv);
  ASSERT_GE(lines.size(), 4u);
  const size_t columns = SplitCsv(lines[0]).size();
  for (size_t i = 1; i < lines.size(); ++i) {
    EXPECT_EQ(SplitCsv(lines[i] + ",x").size(), columns + 1) << "row " << i << ": " << lines[i];
  }
}

TEST(RigCommand, SigtermEndsItWhileAHostFloodsAndNeverReads) {
  TempDir dir;
  std::string port;
  const pid_t rig = StartRig("--quiet", dir.file("rig.err"), &port);
  ASSERT_GT(rig, 0);
  ASSERT_THAT(port, HasSubstr("/dev/pts/"));
  const int fd = open(port.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  // PINGs (answered with ERR: no handshake) until the pty is full both ways: the rig's answers
  // pile up unread, and it stops taking ours once its own queue is full too.
  const std::string ping = "$PING 1*" + [] {
    char crc[5];
    const char body[] = "PING 1";
    std::snprintf(crc, sizeof(crc), "%04X", wire::Crc16(body, body + 6));
    return std::string(crc);
  }() + "\n";
  std::string batch;
  for (int i = 0; i < 100; ++i) batch += ping;
  size_t written = 0;
  for (int i = 0; i < 1000; ++i) {
    const ssize_t n = write(fd, batch.data(), batch.size());
    if (n > 0) written += static_cast<size_t>(n);
    pollfd p{fd, POLLOUT, 0};
    // The rig stopped reading: flooded. (1 s, not 200 ms: a rig slowed by the sanitizers on a
    // loaded machine paused that long before its queue was full: 56 kB written, not 100 kB.)
    if (n <= 0 && poll(&p, 1, 1000) == 0) break;
  }
  EXPECT_GT(written, 100000u);  // Far more answers than any buffer holds.
  kill(rig, SIGTERM);
  int status = 0;
  const int pidfd = static_cast<int>(syscall(SYS_pidfd_open, rig, 0));
  ASSERT_GE(pidfd, 0);
  pollfd p{pidfd, POLLIN, 0};
  const bool ended = poll(&p, 1, 10000) == 1;  // Generous: it takes ~5 ms.
  close(pidfd);
  if (!ended) kill(rig, SIGKILL);
  waitpid(rig, &status, 0);
  close(fd);
  EXPECT_TRUE(ended) << "the rig ignored SIGTERM while its answers were not read";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 143) << ReadTextFile(dir.file("rig.err"));
}

}  // namespace
}  // namespace softsight
