#include "app/identify_command.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "app/capture_options.h"
#include "app/commands.h"
#include "app/control_stereo.h"
#include "app/publish_options.h"
#include "app/shared_flags.h"
#include "app/stop_request.h"
#include "softsight/core/error.h"
#include "softsight/config/config.h"
#include "softsight/io/output_guard.h"

namespace softsight {

std::string ModelCsv(const IdentifyOutcome& found) {
  const std::vector<double> angles = PredictAngles(found.model, found.samples);
  const std::vector<double> pressures = PredictPressures(found.model, found.samples);
  std::string out =
      "time_s,identify_phase,setpoint_kpa,board_pressure_kpa,model_pressure_kpa,angle_deg,"
      "model_angle_deg\n";
  char line[256];
  for (size_t k = 0; k < found.samples.size(); ++k) {
    const IdentifySample& s = found.samples[k];
    char angle[32] = "";
    if (s.angle_deg) std::snprintf(angle, sizeof(angle), "%.3f", *s.angle_deg);
    char pressure[32] = "";
    if (std::isfinite(s.pressure_kpa)) std::snprintf(pressure, sizeof(pressure), "%.3f", s.pressure_kpa);
    std::snprintf(line, sizeof(line), "%.4f,%d,%.3f,%s,%.3f,%s,%.3f\n", s.time_s, s.phase,
                  s.setpoint_kpa, pressure, pressures[k], angle, angles[k]);
    out += line;
  }
  return out;
}

std::optional<IdentifyOutcome> RunIdentify(const IdentifyCommandOptions& options,
                                           ControlSummary* stopped_out) {
  if (options.output_file.empty()) throw InputError("identify: give the config to write (-o)");
  // The input as it is, read (and checked) before the actuator moves.
  TrackingConfig config = LoadTrackingConfig(options.config_file);

  ControlOptions run;
  run.config_file = options.config_file;
  run.simulate = options.simulate;
  run.port = options.port;
  run.camera = options.camera;
  run.rig_frames = options.rig_frames;
  run.stereo = options.stereo;
  run.csv_file = options.csv_file;
  run.publish = options.publish;
  run.fps = options.fps;
  run.sim_supersample = options.sim_supersample;
  run.duration_s = options.max_s;
  run.quiet = options.quiet;
  run.identify = true;
  run.identify_options.closed_loop_s = options.closed_loop_s;
  // Checked with the experiment's CSV before the actuator moves: minutes of experiment are not
  // lost to an output that cannot be written, nor is the input config written over.
  run.other_outputs = {{"-o", options.output_file}, {"--model-csv", options.model_csv_file}};
  ControlSummary summary = RunControl(run);
  if (IdentificationStoppedBySignal(summary)) {
    if (stopped_out != nullptr) *stopped_out = summary;
    return std::nullopt;
  }
  if (!summary.identified) {
    throw IdentifyAbort("identify: the experiment stopped (" + summary.run.stop_text() +
                        "); vented, nothing written");
  }
  IdentifyOutcome found = std::move(*summary.identified);

  if (!config.control) config.control.emplace();
  config.control->controller = found.tuned;
  config.control->inner_loop = found.inner_loop;  // Also drops gains an older identify chose.
  config.control->model = found.model;
  std::string problem;
  if (!config.control->Check(&problem)) {
    throw InputError("identify: the gains found are outside the allowed ranges (control." +
                     problem + "); nothing written");
  }
  if (!options.model_csv_file.empty()) WriteWholeFileOrThrow(options.model_csv_file, ModelCsv(found));
  SaveTrackingConfig(config, options.output_file);
  return found;
}

namespace {

const FlagTable<IdentifyCommandOptions>& IdentifyFlags() {
  using A = IdentifyCommandOptions;
  static const FlagTable<IdentifyCommandOptions> table = {
      ValueFlag<A>(kConfigFlag, &A::config_file)
          .Help("Markers and `control:` section (YAML), read only")
          .Required()
          .Check(CLI::ExistingFile),
      OutputFlag<A>(&A::output_file, "",
                    "The config to write (the input's with the gains and model:); not the input")
          .Required(),
      ValueFlag<A>("--csv", &A::csv_file)
          .Help("Every frame of the experiment (tracking and board)"),
      ValueFlag<A>("--model-csv", &A::model_csv_file)
          .Help("Measured against the fitted model per frame, for `softsight plot`"),
      ValueFlag<A>("--closed-loop-s", &A::closed_loop_s)
          .Help("SIMC closed-loop time constant (default max(dead time, 3 camera periods)); "
                "larger: gentler gains"),
      ValueFlag<A>("--max-s", &A::max_s).Help("Longest the experiment may take (default 600 s)"),
      SwitchFlag<A>(kQuietFlag, &A::quiet).Help("Only errors"),
  };
  return table;
}

const FlagTable<IdentifyCommandOptions>& IdentifyRigFlags() {
  static const FlagTable<IdentifyCommandOptions> table = RigSourceFlags<IdentifyCommandOptions>(
      "Serial device of the board (/dev/ttyACM0, /dev/pts/N)",
      "The in-process simulated rig, its frames rendered and tracked (simulated time)",
      "Frames from the file `softsight rig --frames FILE` keeps rewriting");
  return table;
}

}  // namespace

CommandRunner SetupIdentifyCommand(CLI::App& sub) {
  auto o = std::make_shared<IdentifyCommandOptions>();
  sub.description(
      "Identify the actuator and tune the loop: a safe automatic experiment within the\n"
      "configured pressure limits (a valve probe, pressure steps up and down, then a PRBS\n"
      "around a working point), open loop, the camera measuring the angle. The probe times the\n"
      "valves: behind a tube (over 15 ms) the board's pressure loop gets gains for it (sent\n"
      "with GAIN, written as control.inner_loop). Fits the static map (bend start,\n"
      "slope, saturation, hysteresis) and the dynamics (inner pressure loop and bending: lag +\n"
      "dead time), computes the outer-loop gains (SIMC PI, feed-forward from the static map,\n"
      "hysteresis compensation) and writes them with a `control: model:` section into a new\n"
      "config. Vents and stops with one error line when the markers are lost, the angle does\n"
      "not respond or the pressure goes above the ceiling. See docs/control.md.\n"
      "Examples:\n"
      "  softsight identify --config examples/rig.yaml --simulate -o tuned.yaml --csv ident.csv\n"
      "  softsight identify --config rig.yaml --port /dev/ttyACM0 --camera 0 -o tuned.yaml\n"
      "  softsight identify --config rig.yaml --port /dev/ttyACM0 --stereo stereo.yaml "
      "--left-camera 0 --right-camera 2 -o tuned.yaml   (the 3D angle)");
  AddFlags(sub, IdentifyFlags(), o.get());
  AddFlags(sub, IdentifyRigFlags(), o.get());
  auto publish = std::make_shared<PublishArgs>();
  AddFlags(sub, PublishFlags(), publish.get());
  auto stereo = std::make_shared<ControlStereoOptions>();
  AddFlags(sub, control_parts::ControlStereoFlags(), stereo.get());
  return [o, publish, stereo, &sub] {
    o->publish = publish->resolved();
    o->stereo = control_parts::StereoOptionsGiven(sub, *stereo);
    if (o->closed_loop_s && !(*o->closed_loop_s > 0.0 && *o->closed_loop_s <= 100.0)) {
      throw InputError("--closed-loop-s " + std::to_string(*o->closed_loop_s) +
                       ": must be a number in (0, 100]");
    }
    ControlSummary stopped;
    const std::optional<IdentifyOutcome> found = RunIdentify(*o, &stopped);
    if (!found) {
      // Said even with --quiet: nothing was written.
      std::fprintf(stderr, "identify: %s during the experiment at %.2f s; vented, nothing written\n",
                   stopped.run.stop_text().c_str(), stopped.duration_s);
      return ExitCodeAfterStop(0);  // 130 / 143, as for a process the signal killed.
    }
    if (!o->quiet) {
      std::cerr << FormatIdentifyOutcome(*found);
      std::cerr << "identify: wrote " << o->output_file << "\n";
    }
    return 0;
  };
}

}  // namespace softsight
