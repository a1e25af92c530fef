// `softsight control`: closes the loop. Frames -> tracker -> measured angle -> outer loop ->
// pressure setpoint -> serial link -> board (inner loop), one CSV row per frame with the tracking
// columns and the controller's.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "softsight/pipeline/summary.h"

#include "control/identify.h"
#include "control/step_metrics.h"
#include "softsight/control/session.h"
#include "softsight/io/camera_settings.h"
#include "softsight/io/output_guard.h"
#include "softsight/sim/stereo_scene.h"
#include "app/python_hook.h"
#include "stream/publish_sink.h"

namespace softsight {

// Two cameras: the loop closes on the angle measured in 3D (docs/control.md "Two cameras").
struct ControlStereoOptions {
  // The pair's calibration (`softsight calibrate --left ... --right ...`), or "builtin" with
  // `simulate`: the simulated pair's own (sim/stereo_scene.h MakeStereoRig, exact).
  std::string stereo_file;
  std::optional<std::string> right_config_file;  // The right view's markers when its rois differ.
  // Two live cameras (V4L2 indices), paired by capture time; none with `simulate`, which renders
  // both views of the simulated rig through the simulated pair.
  std::optional<CameraId> left_camera, right_camera;
  // The angle the loop is given: "3d" (default: from the markers verified in both views), or
  // "left" / "right", what that camera alone measures on its image (to compare, not to use).
  std::string angle = "3d";
  double max_epipolar_px = 2.0;  // A pair farther from its epipolar line is not believed.
  // The simulated actuator's bending plane, turned this far out of the first camera's image
  // plane (deg, 0..80): what one camera's angle gets wrong.
  double sim_tilt_deg = 30.0;
  // Markers the simulated pair does not see in one view for a stretch of frames (tests).
  std::vector<StereoHiddenMarker> sim_hidden;
};

struct ControlOptions {
  std::string config_file;              // Markers + `control:` section (examples/rig.yaml).
  // Where the board is: a serial device (/dev/ttyACM0, /dev/pts/N); or, with `simulate` (and no
  // port), an in-process simulated rig behind a real pseudo-terminal, advanced in lock-step with
  // the frames.
  std::optional<std::string> port;
  bool simulate = false;
  // Frames: a camera index, a file the rig rewrites (`rig --frames`), or a video / image
  // sequence (replayed through the loop as fast as it decodes, its timestamps the loop's clock).
  // None of them with `simulate`: the simulated rig is rendered.
  std::optional<CameraId> camera;
  // The --camera-* options' texts by capture key (app/capture_options.h), over the config's
  // `capture:` section.
  std::map<std::string, std::string> capture_args;
  std::optional<std::string> rig_frames;
  std::optional<std::string> input;
  // What to do (one of): target angle, profile file, open-loop pressure, open-loop duty.
  std::optional<double> target_deg;
  std::optional<std::string> profile_file;
  std::optional<double> pressure_kpa;
  std::optional<double> pwm;
  // Or targets from another program (ZeroMQ SUB, app/target_feed.h): the run waits at most
  // `target_wait_s` for the first before it opens the board.
  std::optional<std::string> target_from;
  double target_wait_s = 10.0;
  // --publish: every frame's record (the CSV's columns) to subscribers as it happens.
  std::optional<PublishOptions> publish;
  // --hook: a Python file run on every frame, its values in the CSV and the stream.
  HookArgs hook;
  std::string csv_file;
  std::optional<double> duration_s;     // Default: the profile's length + 2 s, or 10 s.
  double fps = 30.0;                    // Frame rate of simulate / rig_frames.
  int sim_supersample = 2;              // Renderer supersampling in simulate (speed vs fidelity).
  // Two cameras instead of one (none of camera, rig_frames, input then).
  std::optional<ControlStereoOptions> stereo;
  bool quiet = false;
  // Identification instead of a target (`softsight identify`, `control --auto-tune`): the
  // experiment of control/identify.h runs open loop until it is done, then the model is fitted
  // and gains computed (ControlSummary::identified). No target option then.
  bool identify = false;
  IdentifyOptions identify_options;
  // Replaces the config's control.controller (the gains `--auto-tune` found).
  std::optional<ControllerOptions> controller;
  // Replaces the config's control.inner_loop (the board's gains `--auto-tune` chose).
  std::optional<InnerLoopGains> inner_loop;
  // Replaces the config's control.model (what `--auto-tune` identified): its reach is checked.
  std::optional<ActuatorModel> model;
  // A target beyond the model's reach runs, limited to the reach, instead of being refused.
  bool allow_saturation = false;
  std::string metrics_csv_file;         // The step-response figures (StepMetricsCsv), if given.
  // Outputs the same command writes in another step (identify's config and model CSV; the loop's
  // CSV and metrics after --auto-tune's identification): checked with this run's own before the
  // board is opened, so no step can write over another's file or an input.
  std::vector<PathRole> other_outputs;
};

// What an identification run found.
struct IdentifyOutcome {
  ActuatorModel model;
  ControllerOptions tuned;                 // The config's controller with the gains from the model.
  InnerLoopGains inner_loop;               // For the board's pressure loop (not given: its own).
  std::vector<IdentifySample> samples;     // Every frame of the experiment.
};

// A control run's summary: the run's own (RunSummary: frames, frames with an angle, found rates,
// timings, why it stopped) and what only the controller and the link know.
struct ControlSummary {
  // The run's summary, as every command's run gives it (frames, `measured`: frames with an
  // angle (two cameras: the 3D angle), found rates, the latency per frame from its capture (the
  // camera's frame handed over; the simulated rig's frame rendered) to the tracker's result and
  // to every output written, the CSV row's from the CSV sink). A run a signal or an error
  // stopped in a wait for the board: as far as it got.
  RunSummary run;
  double duration_s = 0.0;              // Covered by the frames' timestamps.
  std::optional<double> rms_error_deg;  // measured - target over frames with both, angle mode.
  std::optional<double> final_error_deg;
  double max_pressure_kpa = 0.0;        // Highest pressure the board reported.
  uint64_t link_rejected = 0;           // Lines from the board the host rejected.
  uint32_t board_rejected = 0;          // Lines from the host the board rejected.
  uint64_t resends = 0;
  // Why the run stopped is the run's: run.stop_reason and run.stop_text() ("end of input",
  // "duration reached", "stopped by SIGTERM" (kStopRequested, StopSignalReason's words in
  // run.stop_detail), kError with run.error). The signal's number is not kept here: the exit
  // code takes it from the StopRequest (ExitCodeAfterStop), and a caller asks only whether a
  // signal stopped an identification (IdentificationStoppedBySignal).
  // From the capture to the serial command that frame's step sent, ms: median and 99th
  // percentile (the controller's own figure).
  double latency_command_ms_median = 0.0, latency_command_ms_p99 = 0.0;
  // Angle mode: rise and settling time, overshoot and steady-state error of the last step to a
  // constant target, RMS error over the run (control/step_metrics.h).
  StepMetrics metrics;
  // Every step of the run (a staircase profile: one per jump of the target), each with its own
  // figures and RMS error; the metrics CSV has one row per step.
  std::vector<StepMetrics> steps;
  // A target that moves (ramps, sines): RMS error, lag, and the error with the lag taken out.
  std::optional<TrackingMetrics> tracking;
  std::optional<IdentifyOutcome> identified;
  // What the run did other than asked, one line each (FormatControlSummary prints them): the
  // valves held closed at max_kpa in duty mode, board answers that were not believed.
  std::vector<std::string> notes;
};

// Runs the loop. Throws InputError for bad input or a failed link (e.g. the port disappears);
// every CSV row written before stays intact. `summary_out` receives the summary even then.
ControlSummary RunControl(const ControlOptions& options, ControlSummary* summary_out = nullptr);
// Whether a signal (Ctrl-C, SIGTERM) stopped an identification run (ControlOptions::identify)
// that RunControl returned from: it then has no `identified` and run.stop_reason is
// kStopRequested (a finished experiment also ends with a stop request, the controller's, but
// with its model). It vented and the caller writes nothing.
bool IdentificationStoppedBySignal(const ControlSummary& summary);
std::string FormatControlSummary(const ControlSummary& summary);
// Three lines: the static map, the dynamics, the gains.
std::string FormatIdentifyOutcome(const IdentifyOutcome& found);
// "run.csv" -> "run_identify.csv": where `control --auto-tune` writes the identification run.
std::string IdentifyCsvBeside(const std::string& csv_file);

}  // namespace softsight
