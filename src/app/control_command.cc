#include "app/control_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "app/commands.h"
#include "app/stop_request.h"
#include "softsight/control/board_link.h"
#include "softsight/control/rig.h"
#include "softsight/control/transport.h"
#include "softsight/core/error.h"
#include "softsight/io/config.h"
#include "softsight/io/csv_writer.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

// Frames of a rig running in another process (`softsight rig --pty --frames FILE`), which
// rewrites FILE atomically (write + rename) at its frame rate: read it at `fps`, wall clock.
class RigFileSource : public FrameSource {
 public:
  RigFileSource(std::string file, double fps) : file_(std::move(file)), fps_(fps) {}
  bool read(Frame& frame) override {
    const auto period = std::chrono::duration<double>(1.0 / fps_);
    if (index_ == 0) start_ = std::chrono::steady_clock::now();
    std::this_thread::sleep_until(start_ + std::chrono::duration_cast<
                                               std::chrono::steady_clock::duration>(period * index_));
    cv::Mat image = cv::imread(file_, cv::IMREAD_COLOR);
    if (image.empty()) {
      throw InputError(file_ + ": cannot read the rig's frame at frame " + std::to_string(index_) +
                       " (is `softsight rig --frames " + file_ + "` running?)");
    }
    frame.image = image;
    frame.index = index_;
    frame.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    ++index_;
    return true;
  }
  std::string description() const override { return "rig frames " + file_; }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override { return fps_; }
  bool is_live() const override { return true; }

 private:
  std::string file_;
  double fps_;
  int64_t index_ = 0;
  std::chrono::steady_clock::time_point start_;
};

std::string FormatNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", v);
  return text;
}

// The one check of every number from the command line: finite and in [lo, hi] (or (lo, hi] with
// `lo_open`), else one error naming the option. CLI11 reads "nan" and "inf" as numbers, and every
// comparison with NaN is false, so the test is for the good range.
void CheckOption(const char* option, const std::optional<double>& value, double lo, double hi,
                 bool lo_open = false) {
  if (!value) return;
  const double v = *value;
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi;
  if (!ok) {
    throw InputError(std::string(option) + " " + FormatNumber(v) + ": must be a number in " +
                     (lo_open ? "(" : "[") + FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
  }
}

void CheckOptions(const ControlOptions& o) {
  CheckOption("--target-deg", o.target_deg, 0.0, 180.0);  // 180 = straight.
  CheckOption("--pressure-kpa", o.pressure_kpa, 0.0, kMaxBoardPressureLimitKpa);
  CheckOption("--pwm", o.pwm, -1.0, 1.0);
  CheckOption("--duration-s", o.duration_s, 0.0, 7 * 86400.0, /*lo_open=*/true);  // A week.
  CheckOption("--fps", o.fps, 0.0, 1000.0, /*lo_open=*/true);
  if (o.sim_supersample < 1 || o.sim_supersample > 8) {
    throw InputError("sim_supersample " + std::to_string(o.sim_supersample) + ": must be in 1..8");
  }
}

ControlTarget MakeTarget(const ControlOptions& o) {
  const int chosen = (o.target_deg ? 1 : 0) + (o.profile_file ? 1 : 0) + (o.pressure_kpa ? 1 : 0) +
                     (o.pwm ? 1 : 0);
  if (chosen != 1) {
    throw InputError(
        "control: give exactly one of --target-deg, --profile, --pressure-kpa or --pwm");
  }
  ControlTarget target;
  if (o.target_deg) {
    target.profile = TargetProfile::Constant(*o.target_deg);
  } else if (o.profile_file) {
    target.profile = TargetProfile::Load(*o.profile_file);
  } else if (o.pressure_kpa) {
    target.mode = ControlMode::kPressure;
    target.pressure_kpa = *o.pressure_kpa;
  } else {
    target.mode = ControlMode::kDuty;
    target.duty = *o.pwm;
  }
  return target;
}

}  // namespace

ControlSummary RunControl(const ControlOptions& options, ControlSummary* summary_out) {
  ControlSummary local;
  ControlSummary& summary = summary_out != nullptr ? *summary_out : local;
  summary = ControlSummary{};

  const int sources = (options.simulate ? 1 : 0) + (options.camera ? 1 : 0) +
                      (options.rig_frames ? 1 : 0);
  if (sources != 1) {
    throw InputError("control: give exactly one frame source: --simulate, --camera or --rig-frames");
  }
  if (options.simulate == options.port.has_value()) {
    throw InputError("control: give --port DEVICE for a board, or --simulate (not both)");
  }
  CheckOptions(options);
  const ControlTarget target = MakeTarget(options);
  const TrackingConfig tracking_config = LoadTrackingConfig(options.config_file);
  // LoadTrackingConfig has read and checked the `control:` section; defaults without one.
  const ControlConfig config = tracking_config.control.value_or(ControlConfig{});
  const double duration_s =
      options.duration_s.value_or(target.mode == ControlMode::kAngle &&
                                          target.profile.duration_s() > 0.0
                                      ? target.profile.duration_s() + 2.0
                                      : 10.0);

  // The board: a device, or the simulated rig behind a real pseudo-terminal.
  std::unique_ptr<SimulatedRig> rig;
  std::unique_ptr<RigServer> rig_server;
  std::string port;
  if (options.simulate) {
    rig = std::make_unique<SimulatedRig>(config.rig);
    rig_server = std::make_unique<RigServer>(*rig);
    port = rig_server->port();
  } else {
    port = *options.port;
  }
  // Ctrl-C and SIGTERM from here on: polled between frames and inside every wait for the board.
  const StopRequest stop;
  std::unique_ptr<Transport> transport = OpenSerialTransport(port, config.link.baud);
  LinkEnvironment environment;
  environment.stop_requested = [&stop] { return stop.requested(); };
  BoardLink link(*transport, config.link, environment);
  // Declared after the link, so destroyed before it: from the handshake on, any way out of this
  // function (an error, an exception) sends STOP first.
  ControlSession session(config.controller, link, target);

  // Frames.
  std::unique_ptr<FrameSource> source;
  std::unique_ptr<SyntheticScene> scene;
  if (options.camera) {
    FrameSourceSpec spec;
    spec.camera = options.camera;
    source = OpenFrameSource(spec);
  } else if (options.rig_frames) {
    source = std::make_unique<RigFileSource>(*options.rig_frames, options.fps);
  } else {
    SceneOptions scene_options;
    scene_options.fps = options.fps;
    RenderOptions render;
    render.supersample = options.sim_supersample;
    scene = std::make_unique<SyntheticScene>(scene_options, NoiseOptions{}, render);
  }

  TrackingSession tracking(tracking_config);
  std::vector<std::string> names;
  for (const MarkerSpec& spec : tracking_config.markers) names.push_back(spec.name);
  // The controller's columns, by name, read from this frame's sample (and the rig's truth).
  ControlSample sample;
  std::optional<RigSnapshot> truth;
  const auto sample_column = [&sample](const char* name, auto value) {
    return NumberColumn(name, [&sample, value](const FrameResult&) -> std::optional<double> {
      return value(sample);
    });
  };
  std::vector<CsvColumn> extra = {
      sample_column("target_deg", [](const ControlSample& s) { return s.target_deg; }),
      sample_column("setpoint_kpa", [](const ControlSample& s) { return s.setpoint_kpa; }),
      sample_column("board_pressure_kpa",
                    [](const ControlSample& s) { return s.board.pressure_kpa; }),
      sample_column("board_setpoint_kpa",
                    [](const ControlSample& s) { return s.board.setpoint_kpa; }),
      sample_column("duty", [](const ControlSample& s) { return s.board.duty; }),
      sample_column("board_flags",
                    [](const ControlSample& s) { return static_cast<double>(s.board.flags); }),
      sample_column("control_action",
                    [](const ControlSample& s) {
                      return static_cast<double>(static_cast<int>(s.action));
                    }),
      NumberColumn("link_rejected",
                   [&link](const FrameResult&) -> std::optional<double> {
                     return static_cast<double>(link.stats().rejected_lines);
                   }),
      sample_column("board_rejected",
                    [](const ControlSample& s) {
                      return static_cast<double>(s.board.board_rejected);
                    }),
  };
  if (options.simulate) {
    extra.push_back(NumberColumn("rig_true_angle_deg", [&truth](const FrameResult&) {
      return truth ? std::optional<double>(truth->angle_deg) : std::nullopt;
    }));
    extra.push_back(NumberColumn("rig_pressure_kpa", [&truth](const FrameResult&) {
      return truth ? std::optional<double>(truth->pressure_kpa) : std::nullopt;
    }));
  }
  const MetricModel& metric = tracking_config.measure.metric;
  CsvWriter csv(options.csv_file,
                TrackingColumns(names, metric.scale_mm_per_px || metric.plane_mm_from_image,
                                extra));

  BoardInfo info;
  try {
    info = session.start();
  } catch (const StopRequested&) {
    summary.stop_reason = "interrupted";
    return summary;
  }
  if (const std::optional<double> asked = session.pressure_clamped_from()) {
    // Said once, even with --quiet: the run does not do what the command line says.
    std::fprintf(stderr,
                 "control: --pressure-kpa %s is above the limit of %s kPa (control.controller."
                 "max_kpa, at most the board's limit); sending %s kPa\n",
                 FormatNumber(*asked).c_str(),
                 FormatNumber(session.controller().options().max_kpa).c_str(),
                 FormatNumber(session.pressure_target_kpa()).c_str());
  }
  if (!options.quiet) {
    std::fprintf(stderr,
                 "control: %s: board protocol %d, pressure limit %.1f kPa, inner loop %d Hz, "
                 "watchdog %d ms\n",
                 transport->name().c_str(), info.protocol_version, info.pressure_limit_kpa,
                 info.loop_hz, info.watchdog_ms);
    const ControllerOptions& c = session.controller().options();
    std::fprintf(stderr,
                 "control: outer loop kp %.3g kPa/deg, ki %.3g kPa/(deg s), kd %.3g kPa s/deg, "
                 "bias %.3g kPa, ff %.3g kPa/deg, output %.3g..%.3g kPa, slew %.3g kPa/s, "
                 "hold %.3g s\n",
                 c.kp_kpa_per_deg, c.ki_kpa_per_deg_s, c.kd_kpa_s_per_deg, c.bias_kpa,
                 c.ff_kpa_per_deg, c.min_kpa, c.max_kpa, c.max_rate_kpa_per_s, c.hold_s);
  }

  double sum_sq = 0.0;
  int64_t errors = 0;
  Frame frame;
  try {
    for (int64_t k = 0;; ++k) {
      if (stop.requested()) {
        summary.stop_reason = "interrupted";
        break;
      }
      truth.reset();
      if (scene) {
        const double t = static_cast<double>(k) / options.fps;
        if (t > duration_s + 1e-9) break;
        if (k > 0) rig->advance(1.0 / options.fps);
        truth = rig->snapshot();
        scene->render_at_bend(truth->bend_deg, t, static_cast<int>(k), frame.image);
        frame.index = k;
        frame.time_s = t;
      } else {
        if (!source->read(frame)) {
          summary.stop_reason = "end of input";
          break;
        }
      }
      const FrameResult& result = tracking.process(frame);
      sample = session.step(frame.time_s, result.measurement.angle_deg);
      csv.write(result);

      ++summary.frames;
      summary.duration_s = sample.time_s;
      summary.max_pressure_kpa = std::max(summary.max_pressure_kpa, sample.board.pressure_kpa);
      summary.board_rejected = sample.board.board_rejected;
      if (sample.measured_deg) ++summary.measured;
      if (sample.measured_deg && sample.target_deg) {
        const double e = *sample.measured_deg - *sample.target_deg;
        sum_sq += e * e;
        ++errors;
        summary.final_error_deg = e;
      }
      if (!scene && sample.time_s >= duration_s) break;
    }
    if (summary.stop_reason.empty()) summary.stop_reason = "duration reached";
    session.stop();  // Vent at the end of the run.
  } catch (const StopRequested&) {
    // Ctrl-C while waiting for the board: the row of that frame is not written (no answer).
    summary.stop_reason = "interrupted";
    session.stop();
  } catch (const std::exception&) {
    // The session's destructor sends STOP on the way out.
    summary.stop_reason = "stopped by an error at frame " + std::to_string(summary.frames);
    summary.link_rejected = link.stats().rejected_lines;
    summary.resends = link.stats().resends;
    throw;
  }
  if (errors > 0) summary.rms_error_deg = std::sqrt(sum_sq / static_cast<double>(errors));
  summary.link_rejected = link.stats().rejected_lines;
  summary.resends = link.stats().resends;
  return summary;
}

std::string FormatControlSummary(const ControlSummary& s) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof(line), "frames: %lld over %.2f s (%s), angle measured in %lld\n",
                static_cast<long long>(s.frames), s.duration_s, s.stop_reason.c_str(),
                static_cast<long long>(s.measured));
  out << line;
  if (s.rms_error_deg) {
    std::snprintf(line, sizeof(line), "angle error: RMS %.2f deg over the run, final %+.2f deg\n",
                  *s.rms_error_deg, s.final_error_deg.value_or(0.0));
    out << line;
  }
  std::snprintf(line, sizeof(line),
                "max board pressure %.2f kPa; link: %llu rejected lines from the board, %llu "
                "resends; board rejected %u lines\n",
                s.max_pressure_kpa, static_cast<unsigned long long>(s.link_rejected),
                static_cast<unsigned long long>(s.resends), s.board_rejected);
  out << line;
  return out.str();
}

CommandRunner SetupControlCommand(CLI::App& sub) {
  auto o = std::make_shared<ControlOptions>();
  sub.description(
      "Close the loop: track the markers, turn the bending-angle error into a pressure setpoint\n"
      "(the outer loop) and send it over the serial link to the board, whose inner loop holds\n"
      "the pressure. One CSV row per frame: the tracking columns, then target_deg, setpoint_kpa,\n"
      "board_pressure_kpa, board_setpoint_kpa, duty, board_flags, control_action (0 track,\n"
      "1 hold, 2 vent), link_rejected, board_rejected. The actuator is vented at the end, on\n"
      "Ctrl-C, and by the board's watchdog if this program stops talking. See docs/control.md.\n"
      "Examples:\n"
      "  softsight control --config examples/rig.yaml --simulate --target-deg 120 --csv run.csv\n"
      "  softsight control --config rig.yaml --port /dev/ttyACM0 --camera 0 --profile steps.txt "
      "--csv run.csv");
  sub.add_option("-c,--config", o->config_file, "Markers and `control:` section (YAML), see "
                 "examples/rig.yaml")
      ->required()
      ->check(CLI::ExistingFile);
  sub.add_option("-p,--port", o->port,
                 "Serial device of the board: /dev/ttyACM0, or the /dev/pts/N `softsight rig "
                 "--pty` prints");
  sub.add_flag("--simulate", o->simulate,
               "Drive an in-process simulated rig over a real pseudo-terminal, rendering its "
               "frames (simulated time: runs as fast as it can)");
  sub.add_option("--camera", o->camera, "Camera index for the frames (live)");
  sub.add_option("--rig-frames", o->rig_frames,
                 "Read frames from the file `softsight rig --frames FILE` keeps rewriting");
  sub.add_option("-t,--target-deg", o->target_deg,
                 "Target angle at the middle marker, degrees (180 = straight)");
  sub.add_option("--profile", o->profile_file,
                 "Target profile file: steps, ramps, sines (docs/control.md)")
      ->check(CLI::ExistingFile);
  sub.add_option("--pressure-kpa", o->pressure_kpa,
                 "Open loop: hold this pressure setpoint (characterise an actuator)");
  sub.add_option("--pwm", o->pwm, "Open loop: this valve duty in -1..1 (> 0 inflate, < 0 vent)");
  sub.add_option("-o,--csv", o->csv_file, "Where to write the per-frame CSV")->required();
  sub.add_option("--duration-s", o->duration_s,
                 "Run length in seconds (default: the profile's length + 2 s, else 10 s)");
  sub.add_option("--fps", o->fps, "Frame rate of --simulate and --rig-frames")
      ->capture_default_str();
  sub.add_flag("-q,--quiet", o->quiet, "No summary");
  return [o] {
    const ControlSummary summary = RunControl(*o);
    if (!o->quiet) std::cerr << FormatControlSummary(summary);
    return 0;
  };
}

}  // namespace softsight
