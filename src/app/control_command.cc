#include "app/control_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "app/capture_options.h"
#include "app/commands.h"
#include "app/control_parts.h"
#include "app/control_stereo.h"
#include "app/publish_options.h"
#include "app/shared_flags.h"
#include "app/target_feed.h"
#include "app/stop_request.h"
#include "softsight/control/board_link.h"
#include "softsight/control/rig.h"
#include "softsight/control/transport.h"
#include "softsight/core/error.h"
#include "softsight/config/config.h"
#include "softsight/core/format.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/run_source.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using control_parts::ControlSink;
using control_parts::RigClockSink;
using control_parts::RigFileSource;
using control_parts::SimulatedRigSource;
using control_parts::OpenStereoPairs;
using control_parts::OpenStereoSession;
using control_parts::SimulatedStereoRigInput;
using control_parts::StereoControlSink;
using control_parts::StereoHookSink;
using control_parts::StereoControlColumns;
using control_parts::StereoControlFrames;

// The longest identification experiment: far more than the steps and the PRBS take.
constexpr double kMaxIdentifyS = 600.0;

// The one check of every number from the command line: finite and in [lo, hi] (or (lo, hi] with
// `lo_open`), else one error naming the option. CLI11 reads "nan" and "inf" as numbers, and every
// comparison with NaN is false, so the test is for the good range.
void CheckOption(const char* option, const std::optional<double>& value, double lo, double hi,
                 bool lo_open = false) {
  if (!value) return;
  const double v = *value;
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi;
  if (!ok) {
    throw InputError(std::string(option) + " " + ShortNumber(v) + ": must be a number in " +
                     (lo_open ? "(" : "[") + ShortNumber(lo) + ", " + ShortNumber(hi) + "]");
  }
}

void CheckOptions(const ControlOptions& o) {
  CheckOption("--target-deg", o.target_deg, 0.0, 180.0);  // 180 = straight.
  CheckOption("--pressure-kpa", o.pressure_kpa, 0.0, kMaxBoardPressureLimitKpa);
  CheckOption("--pwm", o.pwm, -1.0, 1.0);
  CheckOption("--duration-s", o.duration_s, 0.0, 7 * 86400.0, /*lo_open=*/true);  // A week.
  CheckOption("--fps", o.fps, 0.0, 1000.0, /*lo_open=*/true);
  CheckOption("--closed-loop-s", o.identify_options.closed_loop_s, 0.0, 100.0, /*lo_open=*/true);
  CheckOption("--target-wait-s", o.target_wait_s, 0.0, 86400.0, /*lo_open=*/true);
  if (o.sim_supersample < 1 || o.sim_supersample > 8) {
    throw InputError("sim_supersample " + std::to_string(o.sim_supersample) + ": must be in 1..8");
  }
}

ControlTarget MakeTarget(const ControlOptions& o) {
  const int chosen = (o.target_deg ? 1 : 0) + (o.profile_file ? 1 : 0) + (o.pressure_kpa ? 1 : 0) +
                     (o.pwm ? 1 : 0) + (o.target_from ? 1 : 0);
  if (chosen != 1) {
    throw InputError("control: give exactly one of --target-deg, --profile, --target-from, "
                     "--pressure-kpa or --pwm");
  }
  ControlTarget target;
  if (o.target_from) {
    // Replaced by the first target received (TargetFeed::wait_first) before the board opens.
    target.profile = TargetProfile::Constant(180.0);
  } else if (o.target_deg) {
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

// What the command line asks, checked before anything is opened: one frame source, a board or
// the simulation, every number, and the target (none for an identification, which runs open
// loop at the experiment's pressures for as long as it takes, bounded by --duration-s).
ControlTarget CheckedTarget(const ControlOptions& options) {
  const int sources =
      (options.camera ? 1 : 0) + (options.rig_frames ? 1 : 0) + (options.input ? 1 : 0);
  if (options.stereo && sources > 0) {
    throw InputError("control --stereo: the frames come from --left-camera and --right-camera "
                     "(or the simulated rig with --simulate), not --camera, --rig-frames or "
                     "--input");
  }
  if (!options.stereo && (sources > 1 || (sources == 0 && !options.simulate))) {
    throw InputError("control: give one frame source: --camera, --rig-frames or --input (or "
                     "none with --simulate, which renders the simulated rig)");
  }
  if (options.simulate == options.port.has_value()) {
    throw InputError("control: give --port DEVICE for a board, or --simulate (not both)");
  }
  CheckOptions(options);
  if (!options.identify) return MakeTarget(options);
  if (options.target_deg || options.profile_file || options.pressure_kpa || options.pwm ||
      options.target_from) {
    throw InputError("identify: no target option (--target-deg, --profile, --target-from, "
                     "--pressure-kpa, --pwm): the experiment chooses the pressures");
  }
  ControlTarget target;
  target.mode = ControlMode::kPressure;
  return target;
}

// The config's `control:` section (checked by LoadTrackingConfig; defaults without one), with
// the command line's controller and model over it.
ControlConfig ControlConfigFor(const ControlOptions& options, const TrackingConfig& tracking) {
  ControlConfig config = tracking.control.value_or(ControlConfig{});
  if (options.controller) {
    std::string problem;
    if (!options.controller->Check(&problem)) throw InputError("control.controller: " + problem);
    config.controller = *options.controller;
  }
  if (options.model) config.model = *options.model;
  if (options.inner_loop) config.inner_loop = *options.inner_loop;
  return config;
}

// Reach, before the board is opened: a target the identified actuator cannot hold would run the
// whole duration at the output limit, "not settled". Refused, or with --allow-saturation limited
// to the reach (the returned note says so).
std::optional<std::string> KeepTargetInReach(const ControlOptions& options,
                                             const ControlConfig& config, ControlTarget* target) {
  // Targets from outside are checked one by one as they arrive (TargetFeed).
  if (target->mode != ControlMode::kAngle || options.identify || options.target_from) {
    return std::nullopt;
  }
  const std::string what = options.profile_file
                               ? "--profile " + EscapeForMessage(*options.profile_file)
                               : "--target-deg " + ShortNumber(target->profile.at(0.0));
  std::vector<std::string> notes;
  // Too fast (a ramp or sine the pump cannot follow): refused the same way; run as given with
  // --allow-saturation, the actuator falling behind (docs/control.md, "Reach").
  if (const std::optional<std::string> too_fast = OutsideRateReach(config.model, target->profile)) {
    if (!options.allow_saturation) {
      throw InputError(what + ": " + *too_fast +
                       "; nothing sent (--allow-saturation runs it as given, the actuator "
                       "falling behind)");
    }
    notes.push_back(what + ": " + *too_fast + "; run as given (--allow-saturation)");
  }
  if (const std::optional<std::string> problem =
          OutsideReach(config.model, target->profile.lowest_deg(), target->profile.highest_deg(),
                       config.controller.max_kpa)) {
    if (!options.allow_saturation) {
      throw InputError(what + ": " + *problem +
                       "; nothing sent (--allow-saturation runs it with the target limited to the "
                       "reach)");
    }
    const ActuatorReach reach = ReachOf(config.model, config.controller.max_kpa);
    target->profile = target->profile.ClampedTo(reach.most_bent_deg, reach.straightest_deg);
    notes.push_back(what + ": " + *problem + "; the target was limited to " +
                    FixedNumber(reach.most_bent_deg, 1) + ".." +
                    FixedNumber(reach.straightest_deg, 1) + " deg (--allow-saturation)");
  }
  if (notes.empty()) return std::nullopt;
  std::string note = notes.front();
  for (size_t i = 1; i < notes.size(); ++i) note += "; " + notes[i];
  if (!options.quiet) {
    for (const std::string& n : notes) std::fprintf(stderr, "control: %s\n", n.c_str());
  }
  return note;
}

// The checks of a target from outside: the controller's silence and rate settings, the model's
// reach (as KeepTargetInReach's for a profile).
TargetFeedOptions TargetFeedOptionsFor(const ControlConfig& config, bool allow_saturation) {
  TargetFeedOptions feed;
  feed.silence_s = config.controller.target_silence_s;
  feed.max_rate_deg_per_s = config.controller.target_max_rate_deg_per_s;
  feed.allow_saturation = allow_saturation;
  feed.model = config.model;
  feed.max_kpa = config.controller.max_kpa;
  return feed;
}

double RunDuration(const ControlOptions& options, const ControlTarget& target) {
  if (options.duration_s) return *options.duration_s;
  if (options.identify) return kMaxIdentifyS;
  if (target.mode == ControlMode::kAngle && target.profile.duration_s() > 0.0) {
    return target.profile.duration_s() + 2.0;
  }
  return 10.0;
}

// The frames: a camera (newest frame wins), the rig's frame file, a video or image sequence
// (each of whose files is an input no output may overwrite), or the simulated rig rendered in
// lock-step (`rendered`, which also gives the rig's truth columns).
struct ControlFrames {
  std::unique_ptr<FrameSource> source;
  std::unique_ptr<SyntheticScene> scene;  // The simulated rig's renderer.
  SimulatedRigSource* rendered = nullptr;
};

ControlFrames OpenControlFrames(const ControlOptions& options, const TrackingConfig& tracking,
                                SimulatedRig* rig, double duration_s,
                                const std::vector<PathRole>& outputs, std::vector<PathRole> inputs) {
  ControlFrames frames;
  if (options.camera) {
    FrameSourceSpec spec;
    spec.camera = options.camera;
    spec.capture =
        MergeCaptureOptions(options.capture_args, tracking.capture.value_or(CameraSettings{}));
    CameraSettingsReport accepted;
    spec.capture_report = &accepted;
    frames.source = SourceForRun(OpenFrameSource(spec), FilePacing::kInCallersThread);
    PrintCaptureReport(accepted);
  } else if (options.rig_frames) {
    frames.source = std::make_unique<RigFileSource>(*options.rig_frames, options.fps);
  } else if (options.input) {
    FrameSourceSpec spec;
    spec.input = *options.input;
    spec.sequence_fps = options.fps;
    frames.source = OpenFrameSource(spec);
    for (const std::string& file : frames.source->files()) inputs.push_back({"--input", file});
    CheckOutputsAreNotInputs(outputs, inputs);
  } else {
    SceneOptions scene_options;
    scene_options.fps = options.fps;
    RenderOptions render;
    render.supersample = options.sim_supersample;
    frames.scene = std::make_unique<SyntheticScene>(scene_options, NoiseOptions{}, render);
    auto rig_source = std::make_unique<SimulatedRigSource>(*rig, *frames.scene, options.fps, duration_s);
    frames.rendered = rig_source.get();
    // With targets from another program the simulation keeps the real time's pace: that
    // program's messages come in real time, and their silence is judged on the frames' clock.
    frames.source = SourceForRun(std::move(rig_source), options.target_from
                                                            ? FilePacing::kRealTime
                                                            : FilePacing::kInCallersThread);
  }
  return frames;
}

// The CSV's columns beyond tracking: the controller's, the experiment's phase, and the
// simulated rig's truth (what the actuator really did; `truth` the rendering source's, null
// for frames from elsewhere). Rows of one camera (FrameResult) or two (StereoFrameResult).
template <typename Row>
std::vector<BasicCsvColumn<Row>> ControlColumns(
    const ControlSink& control, const std::optional<IdentificationExperiment>& experiment,
    bool identify, const std::optional<RigSnapshot>* truth) {
  std::vector<BasicCsvColumn<Row>> extra = control.columns<Row>();
  if (identify) {
    extra.push_back(NumberColumn<Row>("identify_phase", [&experiment](const Row&) {
      return experiment && !experiment->samples().empty()
                 ? std::optional<double>(experiment->samples().back().phase)
                 : std::nullopt;
    }));
  }
  if (truth != nullptr) {
    extra.push_back(NumberColumn<Row>("rig_true_angle_deg", [truth](const Row&) {
      return *truth ? std::optional<double>((*truth)->angle_deg) : std::nullopt;
    }));
    extra.push_back(NumberColumn<Row>("rig_pressure_kpa", [truth](const Row&) {
      return *truth ? std::optional<double>((*truth)->pressure_kpa) : std::nullopt;
    }));
  }
  return extra;
}

// Two cameras' CSV (control_stereo.h): the stereo columns, then the angle the loop was given
// (measured_deg: the 3D angle_deg, or one camera's with --stereo-angle), the controller's, and
// with the simulated pair the true bending plane's tilt out of the first camera's image plane.
BasicCsvColumnTable<StereoFrameResult> StereoCsvColumns(
    const ControlSink& control, const std::optional<IdentificationExperiment>& experiment,
    bool identify, const StereoControlFrames& pairs,
    std::vector<BasicCsvColumn<StereoFrameResult>> hook_columns = {}) {
  using Row = StereoFrameResult;
  std::vector<BasicCsvColumn<Row>> extra{NumberColumn<Row>(
      "measured_deg", [&control](const Row&) { return control.measured_deg(); })};
  const std::optional<RigSnapshot>* truth =
      pairs.rendered != nullptr ? &pairs.rendered->truth() : nullptr;
  for (BasicCsvColumn<Row>& column : ControlColumns<Row>(control, experiment, identify, truth)) {
    extra.push_back(std::move(column));
  }
  if (const SimulatedStereoRigInput* rendered = pairs.rendered) {
    extra.push_back(NumberColumn<Row>("rig_true_out_of_plane_deg", [rendered](const Row&) {
      const std::optional<StereoSceneTruth>& scene = rendered->scene_truth();
      return scene ? std::optional<double>(scene->plane_tilt_deg) : std::nullopt;
    }));
  }
  for (BasicCsvColumn<Row>& column : hook_columns) extra.push_back(std::move(column));
  return StereoControlColumns(*pairs.session, std::move(extra), control.latency_column<Row>());
}

// Every frame carries one command; frames further apart than the board's watchdog allows would
// have the actuator vented between any two of them, silently. Refused, naming the rate.
void CheckFrameRateAgainstWatchdog(const std::optional<double>& fps, const BoardInfo& info) {
  if (!fps || !(*fps > 0.0)) return;
  const double period_ms = 1000.0 / *fps;
  // A fifth of the watchdog's time is left for the frame's own jitter and the answer.
  const double longest_period_ms = 0.8 * info.watchdog_ms;
  if (period_ms > longest_period_ms * (1.0 + 1e-9)) {
    throw InputError("control: frames every " + ShortNumber(period_ms) + " ms (" +
                     ShortNumber(*fps) + " fps) but the board's watchdog vents after " +
                     std::to_string(info.watchdog_ms) + " ms without a command: use at least " +
                     ShortNumber(1000.0 / longest_period_ms) +
                     " fps; nothing sent but the handshake, vented");
  }
}

// The identification experiment, once the board's pressure limit is known.
void StartIdentification(const ControlOptions& options, const ControlSession& session,
                         const BoardInfo& info, std::optional<IdentificationExperiment>* experiment,
                         ControlSink* control) {
  const double ceiling_kpa =
      IdentificationCeiling(session.controller().options(), info.pressure_limit_kpa);
  const double min_kpa = session.controller().options().min_kpa;
  if (!(min_kpa < ceiling_kpa)) {
    // Every setpoint would be raised to min_kpa, above the ceiling the experiment announces.
    throw InputError("identify: control.controller.min_kpa " + ShortNumber(min_kpa) +
                     " kPa is not below the experiment's ceiling of " + ShortNumber(ceiling_kpa) +
                     " kPa (control.controller.max_kpa and the board's limit); vented");
  }
  experiment->emplace(options.identify_options, ceiling_kpa);
  control->identify(&**experiment);
  if (!options.quiet) {
    std::fprintf(stderr,
                 "identify: steps of %.3g kPa up to %.3g kPa and back, then a PRBS around a "
                 "working point; vents and stops on lost markers, no response or a pressure "
                 "above the ceiling\n",
                 (*experiment)->ceiling_kpa() / options.identify_options.levels,
                 (*experiment)->ceiling_kpa());
  }
}

// What the run is about to do: a pressure asked above the limit (said even with --quiet: the
// run does not do what the command line says), the board, and the outer loop's gains.
void AnnounceRun(const ControlOptions& options, const Transport& transport, const BoardInfo& info,
                 const ControlSession& session, const InnerLoopGains& config_inner_loop) {
  if (const std::optional<double> asked = session.pressure_clamped_from()) {
    std::fprintf(stderr,
                 "control: --pressure-kpa %s is above the limit of %s kPa (control.controller."
                 "max_kpa, at most the board's limit); sending %s kPa\n",
                 ShortNumber(*asked).c_str(),
                 ShortNumber(session.controller().options().max_kpa).c_str(),
                 ShortNumber(session.pressure_target_kpa()).c_str());
  }
  if (options.quiet) return;
  std::fprintf(stderr,
               "control: %s: board protocol %d, pressure limit %.1f kPa, inner loop %d Hz, "
               "watchdog %d ms\n",
               transport.name().c_str(), info.protocol_version, info.pressure_limit_kpa,
               info.loop_hz, info.watchdog_ms);
  if (options.identify) return;  // The experiment runs open loop: the gains play no part.
  const InnerLoopGains& inner = config_inner_loop;
  if (inner.given()) {
    std::fprintf(stderr,
                 "control: inner loop gains sent: kp %.3g duty/kPa, ki %.3g duty/(kPa s), "
                 "venting x %.3g (control.inner_loop)\n",
                 inner.kp_per_kpa, inner.ki_per_kpa_s, inner.vent_scale);
  }
  const ControllerOptions& c = session.controller().options();
  if (session.controller().model_based()) {
    std::fprintf(stderr,
                 "control: outer loop model-based (control.model inverted, its error low-passed "
                 "over %.3g s), output %.3g..%.3g kPa, slew %.3g kPa/s, hold %.3g s\n",
                 c.model_correction_s, c.min_kpa, c.max_kpa, c.max_rate_kpa_per_s, c.hold_s);
    return;
  }
  std::fprintf(stderr,
               "control: outer loop kp %.3g kPa/deg, ki %.3g kPa/(deg s), kd %.3g kPa s/deg, "
               "bias %.3g kPa, ff %.3g kPa/deg, hysteresis %.3g kPa, lead %.3g s, output "
               "%.3g..%.3g kPa, slew %.3g kPa/s, hold %.3g s\n",
               c.kp_kpa_per_deg, c.ki_kpa_per_deg_s, c.kd_kpa_s_per_deg, c.bias_kpa,
               c.ff_kpa_per_deg, c.hysteresis_kpa, c.ff_lead_s, c.min_kpa, c.max_kpa,
               c.max_rate_kpa_per_s, c.hold_s);
}

// The controller's figures, the link's counts, and a note for each thing the run did other than
// asked.
void CollectControlSummary(const ControlSink& control, const BoardLink& link,
                           const ControlSession& session,
                           const std::optional<std::string>& limited_to_reach,
                           ControlSummary* summary) {
  *summary = control.summary();
  summary->link_rejected = link.stats().rejected_lines;
  summary->resends = link.stats().resends;
  if (limited_to_reach) summary->notes.push_back(*limited_to_reach);
  if (control.stale_frames() > 0) {
    summary->notes.push_back(
        "the camera repeated its last picture in " + std::to_string(control.stale_frames()) +
        " of " + std::to_string(summary->run.frames) +
        " frames (markers `stale`: a frozen camera or a stalled frame relay): no new measurement "
        "there, so the loop held, then vented");
  }
  const double max_kpa = session.controller().options().max_kpa;
  if (control.longest_at_output_limit_s() > 1.0) {
    summary->notes.push_back(
        "the outer loop's output stayed at its limit (" + ShortNumber(max_kpa) + " kPa) for " +
        FixedNumber(control.longest_at_output_limit_s(), 1) +
        " s: the target may be beyond the actuator's reach (`softsight identify` measures it)");
  }
  if (session.duty_held_at_limit() > 0) {
    summary->notes.push_back("valves held closed (duty 0) in " +
                             std::to_string(session.duty_held_at_limit()) +
                             " frames: the pressure had reached control.controller.max_kpa (" +
                             ShortNumber(max_kpa) + " kPa)");
  }
  if (session.watchdog_answers() > 0) {
    summary->notes.push_back(
        "the board's watchdog had vented in " + std::to_string(session.watchdog_answers()) +
        " answers: commands came too far apart (a camera slower than the watchdog?)");
  }
  if (session.limit_answers() > 0) {
    summary->notes.push_back("the board's pressure guard overrode the outputs in " +
                             std::to_string(session.limit_answers()) +
                             " answers: the pressure reached the board's limit");
  }
}

// The identified model and the gains tuned from it.
IdentifyOutcome IdentifiedFrom(const IdentificationExperiment& experiment,
                               const ControlConfig& config, const ControlOptions& options) {
  IdentifyOutcome outcome;
  outcome.model = FitActuatorModel(experiment);
  const std::vector<IdentifySample>& samples = experiment.samples();
  const double frame_period_s = (samples.back().time_s - samples.front().time_s) /
                                static_cast<double>(std::max<size_t>(1, samples.size() - 1));
  outcome.tuned = TuneController(&outcome.model, config.controller, frame_period_s,
                                 options.identify_options.closed_loop_s);
  outcome.inner_loop = experiment.inner_loop_gains();
  outcome.samples = samples;
  return outcome;
}

// A signal stopped the run (before its loop, or in a wait for the board): the run's stop, in the
// words RunOptions::describe_stop gives a signal inside the loop.
void StoppedBySignal(const StopRequest& stop, ControlSummary* summary) {
  summary->run.stop_reason = StopReason::kStopRequested;
  summary->run.stop_detail = StopSignalReason(stop.signal());
  summary->run.error.clear();
}

// One camera's frames, or (two cameras) the pairs opened; `frames` stays empty then.
ControlFrames OpenFrames(const ControlOptions& options, const TrackingConfig& tracking_config,
                         SimulatedRig* rig, double duration_s, const std::vector<PathRole>& outputs,
                         const std::vector<PathRole>& inputs,
                         std::optional<StereoControlFrames>& pairs) {
  if (pairs) {
    OpenStereoPairs(options, tracking_config, rig, duration_s, &*pairs);
    return {};
  }
  return OpenControlFrames(options, tracking_config, rig, duration_s, outputs, inputs);
}

// The handshake; nothing when a signal stopped it.
std::optional<BoardInfo> StartUnlessStopped(ControlSession& session) {
  try {
    return session.start();
  } catch (const StopRequested&) {
    return std::nullopt;
  }
}

// With no camera, the capture settings of the options or the config are refused (named).
void RefuseCaptureWithoutACamera(const ControlOptions& options,
                                 const TrackingConfig& tracking_config) {
  if (!options.camera && !(options.stereo && options.stereo->left_camera)) {
    RefuseCaptureWithoutCamera(options.capture_args, tracking_config.capture, options.config_file,
                               options.input        ? "the file " + *options.input
                               : options.rig_frames ? "the rig's frames " + *options.rig_frames
                                                    : std::string("the simulated rig"),
                               std::cerr);
  }
}

// The files and the socket this command writes.
std::vector<PathRole> ControlOutputs(const ControlOptions& options) {
  std::vector<PathRole> outputs{{"--csv", options.csv_file},
                                {"--metrics-csv", options.metrics_csv_file}};
  outputs.insert(outputs.end(), options.other_outputs.begin(), options.other_outputs.end());
  if (const std::optional<PathRole> socket = PublishOutput(options.publish)) outputs.push_back(*socket);
  return outputs;
}

// The files this command reads (the stereo calibration's are added when it is opened).
std::vector<PathRole> ControlInputs(const ControlOptions& options,
                                    const TrackingConfig& tracking_config) {
  std::vector<PathRole> inputs = ConfigInputs(tracking_config);
  if (options.profile_file) inputs.push_back({"--profile", *options.profile_file});
  if (options.input) inputs.push_back({"--input", *options.input});
  if (options.rig_frames) inputs.push_back({"--rig-frames", *options.rig_frames});
  return inputs;
}

// --target-from: subscribes and waits for the first target, which becomes the run's constant
// target. False when a signal stopped the wait.
bool FollowTargetStream(const ControlOptions& options, const ControlConfig& config,
                        const StopRequest& stop, std::optional<TargetSubscriber>* target_source,
                        std::optional<TargetFeed>* feed, ControlTarget* target) {
  target_source->emplace(*options.target_from);
  feed->emplace(*options.target_from, TargetFeedOptionsFor(config, options.allow_saturation));
  const ReceivedTargets arrived =
      (*target_source)->wait(options.target_wait_s, [&stop] { return stop.requested(); });
  if (stop.requested()) return false;
  target->profile = TargetProfile::Constant((*feed)->first(arrived, options.target_wait_s));
  return true;
}

// The sinks of the run and what they own, in the order each frame reaches them.
struct ControlSinks {
  std::optional<CsvSink> csv;
  std::unique_ptr<CommandHook> hook;  // --hook: after the controller, before the CSV.
  // Two cameras: the same sinks over the pairs' rows (the stereo columns and the controller's).
  std::optional<StereoControlSink> stereo_control;
  std::optional<BasicCsvSink<FramePair, StereoFrameResult>> stereo_csv;
  std::optional<PublishRowsSink<FramePair, StereoFrameResult>> stereo_publish;
  std::optional<StereoHookSink> stereo_hook;
  std::optional<RigClockSink> rig_clock;
  std::vector<FrameSink*> sinks;
  std::vector<PairSink*> pair_sinks;  // In the same order.
};

// Two cameras: the hook, the stream and the CSV over the pairs' rows.
void OpenStereoRowSinks(const ControlOptions& options, const StereoControlFrames& pairs,
                        const ControlSink& control,
                        const std::optional<IdentificationExperiment>& experiment,
                        PublishSink* publish, bool write_csv, ControlSinks* out) {
  // As for one camera: a camera's hook beside the loop, a rendered rig's in it.
  out->hook = CommandHook::Open(
      options.hook, pairs.input->is_live(),
      StereoCsvColumns(control, experiment, options.identify, pairs).names(), std::cerr);
  std::vector<BasicCsvColumn<StereoFrameResult>> hook_columns;
  if (out->hook) hook_columns = out->stereo_hook.emplace(out->hook->sink()).columns();
  BasicCsvColumnTable<StereoFrameResult> columns = StereoCsvColumns(
      control, experiment, options.identify, pairs, std::move(hook_columns));
  if (publish) out->stereo_publish.emplace(*publish, columns, StereoMarkerSuffixes());
  if (write_csv) out->stereo_csv.emplace(options.csv_file, std::move(columns));
}

// One camera: the hook, the stream and the CSV over the frames' rows.
void OpenFrameRowSinks(const ControlOptions& options, const TrackingConfig& tracking_config,
                       const ControlFrames& frames, ControlSink& control,
                       const std::optional<IdentificationExperiment>& experiment,
                       PublishSink* publish, bool write_csv, ControlSinks* out) {
  std::vector<CsvColumn> extra =
      ControlColumns<FrameResult>(control, experiment, options.identify,
                                  frames.rendered ? &frames.rendered->truth() : nullptr);
  // A camera's hook runs beside the loop (the board's watchdog waits for nobody); a rendered
  // rig or a file's runs in it, every frame.
  out->hook = CommandHook::Open(options.hook, frames.source->is_live(),
                                TrackingColumns(tracking_config, extra), std::cerr);
  if (out->hook) {
    for (CsvColumn& column : out->hook->columns()) extra.push_back(std::move(column));
  }
  CsvColumnTable columns = TrackingColumns(tracking_config, extra);
  columns.insert_before("latency_row_ms", control.latency_column());
  if (publish) publish->set_columns(columns);
  if (write_csv) out->csv.emplace(options.csv_file, std::move(columns));
}

// The hook, the stream and the CSV over the rows of the pairs or of the frames.
void OpenRowSinks(const ControlOptions& options, const TrackingConfig& tracking_config,
                  const ControlFrames& frames, const std::optional<StereoControlFrames>& pairs,
                  ControlSink& control, const std::optional<IdentificationExperiment>& experiment,
                  PublishSink* publish, ControlSinks* out) {
  // Optional for an identification (`softsight identify` without --csv).
  const bool write_csv = !options.csv_file.empty() || !options.identify;
  if (pairs) {
    OpenStereoRowSinks(options, *pairs, control, experiment, publish, write_csv, out);
  } else {
    OpenFrameRowSinks(options, tracking_config, frames, control, experiment, publish, write_csv,
                      out);
  }
}

// The order of the sinks: the rig's clock, the controller, the hook, the CSV, the stream.
void OrderControlSinks(SimulatedRig* rig, bool rendered, ControlSink& control,
                       PublishSink* publish, std::optional<StereoControlFrames>& pairs,
                       ControlSinks* out) {
  if (rig && !rendered) out->sinks.push_back(&out->rig_clock.emplace(*rig));
  // Before the CSV and the stream: their columns read this frame's step.
  out->sinks.push_back(&control);
  // The hook sees the step too; before the columns it fills.
  if (out->hook) out->sinks.push_back(&out->hook->sink());
  if (out->csv) out->sinks.push_back(&*out->csv);
  if (publish) out->sinks.push_back(publish);
  if (pairs) {
    out->pair_sinks.push_back(&out->stereo_control.emplace(control, pairs->angle));
    if (out->stereo_hook) out->pair_sinks.push_back(&*out->stereo_hook);
    if (out->stereo_csv) out->pair_sinks.push_back(&*out->stereo_csv);
    if (out->stereo_publish) out->pair_sinks.push_back(&*out->stereo_publish);
  }
}

// The controller's summary with what the stream and the target's source add to its notes.
void CollectRunSummary(const ControlSink& control, const BoardLink& link,
                       const ControlSession& session,
                       const std::optional<std::string>& limited_to_reach,
                       std::optional<TargetFeed>& feed, PublishSink* publish,
                       ControlSummary* summary) {
  CollectControlSummary(control, link, session, limited_to_reach, summary);
  if (feed) {
    for (std::string& note : feed->notes()) summary->notes.push_back(std::move(note));
  }
  if (publish) {
    RunSummary published;
    publish->report(published);
    for (std::string& note : published.notes) summary->notes.push_back(std::move(note));
  }
}

// The loop stops when the user or the controller (its duration) says so; why, in the summary's
// words: the stream's end record says the same.
RunOptions ControlRunOptions(const StopRequest& stop, const ControlSink& control, bool rendered) {
  RunOptions run;
  run.stop_requested = [&stop, &control] { return stop.requested() || control.done(); };
  run.check_key_frame_groups = false;  // The loop acts on each frame as it comes.
  run.describe_stop = [&stop, &control, rendered](StopReason reason) -> std::string {
    switch (reason) {
      case StopReason::kEndOfInput:
        return rendered ? "duration reached" : "end of input";
      case StopReason::kMaxFrames:
      case StopReason::kStopRequested:
        if (control.done()) return "duration reached";
        return stop.signal() != 0 ? StopSignalReason(stop.signal()) : std::string();
      case StopReason::kError:
        return "";
    }
    return "";
  };
  return run;
}

// After a loop that returned: an identification the frames cut short, the run's error, the
// vent, the model identified and the step metrics.
void FinishControlRun(const ControlOptions& options, const ControlConfig& config,
                      const StopRequest& stop, ControlSession& session,
                      const std::optional<IdentificationExperiment>& experiment,
                      ControlSummary* summary) {
  const RunSummary& ran = summary->run;
  if (experiment && !experiment->done() && ran.stop_reason != StopReason::kError) {
    session.stop();
    if (stop.requested()) {  // Not a failure: the caller says which signal and exits 130/143.
      StoppedBySignal(stop, summary);
      return;
    }
    throw IdentifyAbort("identify: the experiment did not finish (the frames ran out at " +
                        ShortNumber(summary->duration_s) + " s); vented");
  }
  // The run's stop_detail already says why in the loop's words (describe_stop: the end of the
  // input, the duration reached, the signal).
  // The session's destructor sends STOP on the way out.
  if (ran.stop_reason == StopReason::kError) throw InputError(ran.error);
  session.stop();  // Vent at the end of the run.
  if (experiment) summary->identified = IdentifiedFrom(*experiment, config, options);
  if (!options.metrics_csv_file.empty()) {
    WriteWholeFileOrThrow(options.metrics_csv_file, StepMetricsCsv(summary->steps));
  }
}

}  // namespace

// The wiring: checks, the board (a device, or the simulated rig behind a real pseudo-terminal),
// the frames, the sinks, the handshake, the run, and its summary.
ControlSummary RunControl(const ControlOptions& options, ControlSummary* summary_out) {
  ControlSummary local;
  ControlSummary& summary = summary_out != nullptr ? *summary_out : local;
  summary = ControlSummary{};

  ControlTarget target = CheckedTarget(options);
  const TrackingConfig tracking_config = LoadTrackingConfig(options.config_file);
  RefuseCaptureWithoutACamera(options, tracking_config);
  // Before the board is opened: no output may be an input or another output of this command.
  const std::vector<PathRole> outputs = ControlOutputs(options);
  std::vector<PathRole> inputs = ControlInputs(options, tracking_config);
  // Two cameras: the calibration and both views' markers, checked before the port is opened.
  std::optional<StereoControlFrames> pairs;
  if (options.stereo) pairs = OpenStereoSession(options, tracking_config, &inputs);
  CheckOutputsAreNotInputs(outputs, inputs);
  const ControlConfig config = ControlConfigFor(options, tracking_config);
  const std::optional<std::string> limited_to_reach = KeepTargetInReach(options, config, &target);
  const double duration_s = RunDuration(options, target);
  // The stream's endpoint is taken before anything is written or sent: a bad one ends here.
  const std::unique_ptr<PublishSink> publish = OpenPublishSink(options.publish, options.config_file);
  // Ctrl-C and SIGTERM from here on: polled between frames and inside every wait for the board.
  const StopRequest stop;
  std::optional<TargetSubscriber> target_source;
  std::optional<TargetFeed> feed;
  if (options.target_from &&
      !FollowTargetStream(options, config, stop, &target_source, &feed, &target)) {
    StoppedBySignal(stop, &summary);
    return summary;
  }

  const std::unique_ptr<SimulatedRig> rig =
      options.simulate ? std::make_unique<SimulatedRig>(config.rig) : nullptr;
  const std::unique_ptr<RigServer> rig_server = rig ? std::make_unique<RigServer>(*rig) : nullptr;
  std::unique_ptr<Transport> transport =
      OpenSerialTransport(rig_server ? rig_server->port() : *options.port, config.link.baud);
  LinkEnvironment environment;
  environment.stop_requested = [&stop] { return stop.requested(); };
  // The simulated board of --simulate answers from a thread of this process: see rig.h.
  BoardLink link(*transport, rig_server ? InProcessLinkOptions(config.link) : config.link,
                 environment);
  // Declared after the link, so destroyed before it: from the handshake on, any way out of this
  // function (an error, an exception) sends STOP first.
  ControlSession session(config.controller, link, target);
  // An identification measures the plant first and chooses the board's gains itself.
  if (!options.identify) {
    session.set_inner_loop_gains(config.inner_loop);
    session.set_model(config.model);
  }
  // One camera (a FrameSource through a TrackingSession), or two (pairs through a
  // StereoSession): either way the controller is handed one angle per frame.
  const ControlFrames frames =
      OpenFrames(options, tracking_config, rig.get(), duration_s, outputs, inputs, pairs);
  const bool rendered = frames.rendered != nullptr || (pairs && pairs->rendered != nullptr);

  std::optional<TrackingSession> tracking;  // One camera's (two: the pairs' StereoSession).
  if (!pairs) tracking.emplace(tracking_config);
  ControlSink control(session, link, duration_s,
                      /*stop_at_duration=*/!rendered || options.identify);
  std::optional<IdentificationExperiment> experiment;  // Made once the board's limit is known.
  ControlSinks sinks;
  OpenRowSinks(options, tracking_config, frames, pairs, control, experiment, publish.get(), &sinks);
  if (feed) control.follow(&*target_source, &*feed);
  OrderControlSinks(rig.get(), rendered, control, publish.get(), pairs, &sinks);

  const std::optional<BoardInfo> info = StartUnlessStopped(session);
  if (!info) {
    StoppedBySignal(stop, &summary);
    return summary;
  }
  CheckFrameRateAgainstWatchdog(pairs ? pairs->fps : frames.source->fps(), *info);
  if (options.identify) StartIdentification(options, session, *info, &experiment, &control);
  AnnounceRun(options, *transport, *info, session, config.inner_loop);

  const RunOptions run = ControlRunOptions(stop, control, rendered);
  try {
    summary.run = pairs ? RunPipeline(*pairs->input, *pairs->session, sinks.pair_sinks, run)
                        : RunPipeline(*frames.source, *tracking, sinks.sinks, run);
  } catch (const StopRequested&) {
    // Ctrl-C while waiting for the board: the row of that frame is not written (no answer).
    CollectRunSummary(control, link, session, limited_to_reach, feed, publish.get(), &summary);
    StoppedBySignal(stop, &summary);
    session.stop();
    return summary;
  } catch (const std::exception& e) {
    // The session's destructor sends STOP on the way out.
    CollectRunSummary(control, link, session, limited_to_reach, feed, publish.get(), &summary);
    summary.run.stop_reason = StopReason::kError;
    if (summary.run.error.empty()) summary.run.error = e.what();
    throw;
  }
  const RunSummary ran = summary.run;
  CollectRunSummary(control, link, session, limited_to_reach, feed, publish.get(), &summary);
  summary.run = ran;
  FinishControlRun(options, config, stop, session, experiment, &summary);
  return summary;
}

bool IdentificationStoppedBySignal(const ControlSummary& summary) {
  return !summary.identified && summary.run.stop_reason == StopReason::kStopRequested;
}

std::string FormatControlSummary(const ControlSummary& s) {
  std::ostringstream out;
  char line[256];
  const std::string stopped =
      s.run.stop_reason == StopReason::kError
          ? "stopped by an error at frame " + std::to_string(s.run.frames)
          : s.run.stop_text();
  std::snprintf(line, sizeof(line), "frames: %lld over %.2f s (%s), angle measured in %lld\n",
                static_cast<long long>(s.run.frames), s.duration_s, stopped.c_str(),
                static_cast<long long>(s.run.measured));
  out << line;
  if (s.rms_error_deg) {
    std::snprintf(line, sizeof(line), "angle error: RMS %.2f deg over the run, final %+.2f deg\n",
                  *s.rms_error_deg, s.final_error_deg.value_or(0.0));
    out << line;
  }
  if (s.steps.size() > 1) {
    // A staircase: each step's figures (its RMS error over that step).
    for (size_t i = 0; i < s.steps.size(); ++i) {
      out << "step " << i + 1 << " of " << s.steps.size() << ": "
          << FormatStepMetrics(s.steps[i], "the step") << "\n";
    }
  } else if (s.steps.size() == 1 && s.tracking) {
    out << FormatStepMetrics(s.steps.front(), "the step") << "\n";  // Before the target moves.
  } else if (s.metrics.step_to_deg) {
    out << FormatStepMetrics(s.metrics) << "\n";
  }
  if (s.tracking) out << FormatTrackingMetrics(*s.tracking) << "\n";
  for (const std::string& note : s.notes) out << "note: " << note << "\n";
  std::snprintf(line, sizeof(line),
                "max board pressure %.2f kPa; link: %llu rejected lines from the board, %llu "
                "resends; board rejected %u lines\n",
                s.max_pressure_kpa, static_cast<unsigned long long>(s.link_rejected),
                static_cast<unsigned long long>(s.resends), s.board_rejected);
  out << line;
  if (s.run.frames > 0) {
    std::snprintf(line, sizeof(line),
                  "latency from capture, median / p99: result %.3f / %.3f ms, serial command "
                  "%.3f / %.3f ms, CSV row %.3f / %.3f ms\n",
                  s.run.latency_result_ms_median, s.run.latency_result_ms_p99, s.latency_command_ms_median,
                  s.latency_command_ms_p99, s.run.latency_done_ms_median, s.run.latency_done_ms_p99);
    out << line;
  }
  return out.str();
}

std::string IdentifyCsvBeside(const std::string& csv_file) {
  const size_t dot = csv_file.rfind('.');
  const size_t slash = csv_file.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) {
    return csv_file + "_identify.csv";
  }
  return csv_file.substr(0, dot) + "_identify" + csv_file.substr(dot);
}

std::string FormatIdentifyOutcome(const IdentifyOutcome& found) {
  const ActuatorModel& m = found.model;
  const ControllerOptions& c = found.tuned;
  char saturation[32] = "none seen";
  if (m.saturation_kpa > 0.0) {
    std::snprintf(saturation, sizeof(saturation), "%.2f kPa", m.saturation_kpa);
  }
  char inner[128] = "the board's own gains (a short tube)";
  if (found.inner_loop.given()) {
    std::snprintf(inner, sizeof(inner),
                  "kp %.3g duty/kPa, ki %.3g duty/(kPa s), venting x %.3g for the tube",
                  found.inner_loop.kp_per_kpa, found.inner_loop.ki_per_kpa_s,
                  found.inner_loop.vent_scale);
  }
  char text[1536];
  std::snprintf(
      text, sizeof(text),
      "identify: static map: straight %.1f deg, bend start %.2f kPa, slope %.3f deg/kPa, "
      "saturation %s, hysteresis %.2f deg (RMS residual %.2f deg), valid %.1f..%.1f kPa, "
      "%.1f..%.1f deg\n"
      "identify: dynamics: pressure lag %.3f s + dead time %.3f s (RMS %.2f kPa), as the board "
      "runs it %.3f duty/kPa + dead time %.3f s (RMS %.2f kPa); bending lag %.3f s + dead time "
      "%.3f s (RMS %.2f deg)\n"
      "identify: valves -> sensor: dead time %.3f s, full inflation %.1f kPa/s, full venting "
      "%.1f kPa/s; board's inner loop: %s\n"
      "identify: loop: model-based (model_inverse: %s), its error low-passed over %.3f s; the PI "
      "for model_inverse false (SIMC): kp %.3f kPa/deg, ki %.3f kPa/(deg s), "
      "bias %.2f kPa, ff %.4f kPa/deg, hysteresis %.2f kPa, lead %.3f s, integral band %.1f "
      "deg\n",
      m.straight_deg, m.bend_start_kpa, m.slope_deg_per_kpa,
      saturation,
      m.hysteresis_deg, m.static_rms_deg, m.valid_min_kpa, m.valid_max_kpa, m.valid_min_deg,
      m.valid_max_deg, m.pressure_lag_s, m.pressure_dead_time_s, m.pressure_rms_kpa,
      m.pressure_duty_per_kpa, m.pressure_duty_dead_time_s, m.pressure_duty_rms_kpa, m.lag_s,
      m.dead_time_s, m.dynamic_rms_deg, m.valve_dead_time_s, m.inflate_kpa_per_s,
      m.vent_kpa_per_s, inner, c.model_inverse ? "true" : "false", c.model_correction_s,
      c.kp_kpa_per_deg, c.ki_kpa_per_deg_s,
      c.bias_kpa, c.ff_kpa_per_deg, c.hysteresis_kpa, c.ff_lead_s, c.integral_band_deg);
  return text;
}

namespace {

// What control's flags set until it runs.
struct ControlArgs {
  ControlOptions options;
  bool auto_tune = false;
  std::optional<double> closed_loop_s;  // With --auto-tune.
  PublishArgs publish;
  ControlStereoOptions stereo;
};

const FlagTable<ControlOptions>& ControlRigFlags() {
  static const FlagTable<ControlOptions> table = RigSourceFlags<ControlOptions>(
      "Serial device of the board: /dev/ttyACM0, or the /dev/pts/N `softsight rig --pty` prints",
      "Drive an in-process simulated rig over a real pseudo-terminal, rendering its frames "
      "(simulated time: runs as fast as it can)",
      "Read frames from the file `softsight rig --frames FILE` keeps rewriting");
  return table;
}

const FlagTable<ControlArgs>& ControlFlags() {
  using A = ControlArgs;
  using O = ControlOptions;
  // A field of the options: [](A& a) -> auto& { return a.options.x; } for each row, spelled once.
  auto in = [](auto O::*field) { return [field](A& a) -> auto& { return a.options.*field; }; };
  static const FlagTable<ControlArgs> table = {
      ValueFlag<A>(kConfigFlag, in(&O::config_file))
          .Help("Markers and `control:` section (YAML), see examples/rig.yaml")
          .Required()
          .Check(CLI::ExistingFile),
      ValueFlag<A>(kInputFlag, in(&O::input))
          .Help("Frames from a video or image sequence (a recorded run replayed through the "
                "loop; with --simulate the simulated board follows the frames' timestamps)"),
      ValueFlag<A>("-t,--target-deg", in(&O::target_deg))
          .Help("Target angle at the middle marker, degrees (180 = straight)"),
      ValueFlag<A>("--profile", in(&O::profile_file))
          .Help("Target profile file: steps, ramps, sines (docs/control.md)")
          .Check(CLI::ExistingFile),
      ValueFlag<A>("--pressure-kpa", in(&O::pressure_kpa))
          .Help("Open loop: hold this pressure setpoint (characterise an actuator)"),
      ValueFlag<A>("--pwm", in(&O::pwm))
          .Help("Open loop: this valve duty in -1..1 (> 0 inflate, < 0 vent)"),
      ValueFlag<A>("--target-from", in(&O::target_from))
          .Help("Target angles from another program: a ZeroMQ endpoint it publishes on "
                "(tcp://HOST:5557, ipc://PATH), messages `target {\"angle_deg\": 120}`; checked "
                "as a profile (0..180, the model's reach), followed at most at "
                "controller.target_max_rate_deg_per_s, vented when silent longer than "
                "controller.target_silence_s (docs/stream.md)"),
      ValueFlag<A>("--target-wait-s", in(&O::target_wait_s))
          .Help("With --target-from: the longest wait for the first target before the board is "
                "opened, seconds")
          .ShowDefault(),
      OutputFlag<A>(in(&O::csv_file), "csv", "Where to write the per-frame CSV").Required(),
      ValueFlag<A>("--duration-s", in(&O::duration_s))
          .Help("Run length in seconds (default: the profile's length + 2 s, else 10 s)"),
      ValueFlag<A>("--metrics-csv", in(&O::metrics_csv_file))
          .Help("Write the step-response figures (rise, settling +-1/+-2 deg, overshoot, "
                "steady-state error, RMS error) as a two-line CSV"),
      SwitchFlag<A>("--auto-tune", &A::auto_tune)
          .Help("Identify the actuator first (`softsight identify`: steps and a PRBS, its CSV "
                "beside --csv as *_identify.csv), then run the loop with the gains it found"),
      ValueFlag<A>("--closed-loop-s", &A::closed_loop_s)
          .Help("With --auto-tune: the SIMC closed-loop time (default max(dead time, 3 camera "
                "periods))"),
      SwitchFlag<A>("--allow-saturation", in(&O::allow_saturation))
          .Help("Run a target beyond the identified actuator's reach (control.model) limited to "
                "that reach, instead of refusing it"),
      SwitchFlag<A>(kQuietFlag, in(&O::quiet)).Help("No summary"),
  };
  return table;
}

}  // namespace

CommandRunner SetupControlCommand(CLI::App& sub) {
  auto args = std::make_shared<ControlArgs>();
  AddFlags(sub, CaptureFlags(), &args->options.capture_args);
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
      "--csv run.csv\n"
      "Two cameras (--stereo): the loop closes on the 3D angle, a pair not verified in both views\n"
      "counting as a lost marker; the CSV has the track-stereo columns and the controller's:\n"
      "  softsight control --config examples/rig_stereo.yaml --simulate --stereo builtin "
      "--target-deg 120 --csv run3d.csv\n"
      "  softsight control --config rig.yaml --stereo stereo.yaml --left-camera 0 --right-camera 2 "
      "--port /dev/ttyACM0 --target-deg 120 --csv run3d.csv");
  AddFlags(sub, ControlRigFlags(), &args->options);
  AddFlags(sub, ControlFlags(), args.get());
  AddFlags(sub, PublishFlags(), &args->publish);
  AddFlags(sub, HookFlags(), &args->options.hook);
  AddFlags(sub, control_parts::ControlStereoFlags(), &args->stereo);
  // The run's parts, each keeping `args` alive.
  const std::shared_ptr<ControlOptions> o(args, &args->options);
  const std::shared_ptr<bool> auto_tune(args, &args->auto_tune);
  const std::shared_ptr<std::optional<double>> closed_loop_s(args, &args->closed_loop_s);
  const std::shared_ptr<PublishArgs> publish(args, &args->publish);
  const std::shared_ptr<ControlStereoOptions> stereo(args, &args->stereo);
  return [o, auto_tune, closed_loop_s, publish, stereo, &sub] {
    o->publish = publish->resolved();
    o->stereo = control_parts::StereoOptionsGiven(sub, *stereo);
    ControlOptions run = *o;
    if (*auto_tune) {
      ControlOptions identify = *o;
      identify.identify = true;
      identify.target_deg.reset();
      identify.profile_file.reset();
      identify.pressure_kpa.reset();
      identify.pwm.reset();
      identify.target_from.reset();
      identify.duration_s.reset();
      identify.metrics_csv_file.clear();
      identify.identify_options.closed_loop_s = *closed_loop_s;
      identify.csv_file = IdentifyCsvBeside(o->csv_file);
      identify.other_outputs = {{"--csv", o->csv_file}, {"--metrics-csv", o->metrics_csv_file}};
      const ControlSummary found = RunControl(identify);
      if (IdentificationStoppedBySignal(found)) {
        // Vented; the loop never starts. Said even with --quiet: nothing was tuned.
        std::cerr << "control --auto-tune: " << found.run.stop_text()
                  << " during the identification at "
                  << ShortNumber(found.duration_s) << " s; vented, the loop not started\n";
        return ExitCodeAfterStop(0);  // 130 / 143.
      }
      if (!found.identified) throw InputError("control --auto-tune: the identification stopped");
      if (!o->quiet) std::cerr << FormatIdentifyOutcome(*found.identified);
      run.controller = found.identified->tuned;
      run.model = found.identified->model;  // Its reach is checked before the loop starts.
      run.inner_loop = found.identified->inner_loop;
    } else if (closed_loop_s->has_value()) {
      throw InputError("control: --closed-loop-s needs --auto-tune");
    }
    const ControlSummary summary = RunControl(run);
    if (!o->quiet) std::cerr << FormatControlSummary(summary);
    // 130 / 143 after Ctrl-C / SIGTERM (the actuator vented, the summary printed): a script
    // can tell an interrupted run from a complete one.
    return ExitCodeAfterStop(0);
  };
}

}  // namespace softsight
