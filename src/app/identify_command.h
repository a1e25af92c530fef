// `softsight identify`: a safe automatic experiment on the actuator (control/identify.h), the
// model fitted to it, gains from the model, all saved into a new config (never the input one).
#pragma once

#include "stream/publish_sink.h"

#include <optional>
#include <string>

#include "app/control_command.h"

namespace softsight {

struct IdentifyCommandOptions {
  std::string config_file;    // Markers + `control:` section, read only.
  std::string output_file;    // The config to write: the input's, plus model: and the gains.
  // --publish: every frame of the experiment to subscribers as it happens.
  std::optional<PublishOptions> publish;
  bool simulate = false;      // The in-process simulated rig, rendered and tracked.
  std::optional<std::string> port;
  std::optional<CameraId> camera;
  std::optional<std::string> rig_frames;
  // Two cameras: the experiment measures the 3D angle (control's --stereo; no camera, rig_frames).
  std::optional<ControlStereoOptions> stereo;
  std::string csv_file;       // Every frame of the experiment (optional).
  std::string model_csv_file; // Measured against the fitted model, per frame (optional).
  double fps = 30.0;          // Of --simulate and --rig-frames.
  int sim_supersample = 2;
  std::optional<double> closed_loop_s;  // SIMC tau_c.
  std::optional<double> max_s;          // Bound on the experiment's length (default 600 s).
  bool quiet = false;
};

// Runs the experiment, fits, tunes and writes output_file (only when everything succeeded).
// Throws InputError (IdentifyAbort for an experiment stopped for safety) after venting; the
// output is then not written. Refuses an output that is the input. Ctrl-C or SIGTERM during the
// experiment is no error: it vents, writes nothing and returns nullopt, with the run's summary
// (run.stop_text(), duration) in `stopped_out`.
std::optional<IdentifyOutcome> RunIdentify(const IdentifyCommandOptions& options,
                                           ControlSummary* stopped_out = nullptr);

// The model CSV: time_s, identify_phase, setpoint_kpa, board_pressure_kpa, model_pressure_kpa,
// angle_deg, model_angle_deg (softsight plot draws measured against model).
std::string ModelCsv(const IdentifyOutcome& found);

}  // namespace softsight
