// `softsight control --stereo`: the loop closed on the angle measured in 3D. The pairs of frames
// (two live cameras paired by capture time, or the simulated rig rendered into both views of the
// simulated pair), each through a StereoSession on the one run loop (RunPipeline on pairs), and
// one measurement per pair for the controller: the same ControlSink as one camera's, which is
// handed an angle and never learns where it came from. Private to the command; RunControl wires
// it.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/control_command.h"
#include "app/control_parts.h"
#include "app/flag_table.h"
#include "softsight/config/config.h"
#include "softsight/control/rig.h"
#include "softsight/io/csv_writer.h"
#include "softsight/io/stereo_input.h"
#include "softsight/pipeline/hook.h"
#include "softsight/pipeline/stereo_session.h"
#include "softsight/pipeline/summary.h"
#include "softsight/sim/stereo_scene.h"

namespace softsight::control_parts {

// Which angle of a pair the loop is given (ControlStereoOptions::angle).
enum class StereoAngle { k3d, kLeft, kRight };
// "3d", "left" or "right"; throws InputError naming --stereo-angle and the choices.
StereoAngle ParseStereoAngle(const std::string& text);

// The loop's measurement from a pair's result. k3d: the 3D angle at the middle marker, absent
// unless the markers it needs were found in both views and passed the epipolar check (a marker
// lost or refused in either view is a lost marker to the controller: hold, then vent). kLeft,
// kRight: that camera's own angle on its image, whatever the other view saw.
std::optional<double> StereoMeasuredAngle(const StereoFrameResult& result, StereoAngle angle);

// The simulated rig seen by two cameras: each pair renders the rig's current bend into both views
// (sim/stereo_scene.h), then the rig advances one frame period, in lock-step with the loop
// (simulated time). Ends after `duration_s`.
class SimulatedStereoRigInput : public StereoInput {
 public:
  SimulatedStereoRigInput(SimulatedRig& rig, const StereoScene& scene, double fps,
                          double duration_s);
  bool read(FramePair& pair) override;
  std::string description() const override { return "simulated rig seen by two cameras"; }
  std::vector<std::string> files() const override { return {}; }
  // The rig's state and the scene's 3D truth when the last pair was rendered.
  const std::optional<RigSnapshot>& truth() const { return truth_; }
  const std::optional<StereoSceneTruth>& scene_truth() const { return scene_truth_; }

 private:
  SimulatedRig& rig_;
  const StereoScene& scene_;
  double fps_;
  int64_t frames_;
  int64_t index_ = 0;
  std::optional<RigSnapshot> truth_;
  std::optional<StereoSceneTruth> scene_truth_;
};

// The two views: the session (the calibration, a file or the simulated pair's own, and each
// view's markers), made and checked before the port is opened, then the pairs.
struct StereoControlFrames {
  std::unique_ptr<StereoSession> session;
  StereoAngle angle = StereoAngle::k3d;
  std::unique_ptr<StereoScene> scene;  // The simulated pair's renderer.
  std::unique_ptr<StereoInput> input;
  SimulatedStereoRigInput* rendered = nullptr;  // `input`, when simulated.
  std::optional<double> fps;  // The pairs' rate when known (the simulated pair's).
};

// The session. Throws InputError (one line naming the option or file): a missing or unusable
// calibration, "builtin" without --simulate, a calibration whose image size is not the simulated
// cameras', cameras with --simulate or one camera only, a right config with other markers.
// `inputs` gets the files read (none may be an output).
StereoControlFrames OpenStereoSession(const ControlOptions& options,
                                      const TrackingConfig& left_config,
                                      std::vector<PathRole>* inputs);
// Then the pairs: the simulated rig rendered into both views (`rig`), or the two cameras.
void OpenStereoPairs(const ControlOptions& options, const TrackingConfig& left_config,
                     SimulatedRig* rig, double duration_s, StereoControlFrames* frames);

// The stereo CSV's columns (pipeline/stereo_session.h StereoColumns: per marker 3D position,
// status; angle_deg in 3D, out_of_plane_deg, ..., angle_left_deg, angle_right_deg), with
// `extra` and then latency_command_ms before proc_ms.
BasicCsvColumnTable<StereoFrameResult> StereoControlColumns(
    const StereoSession& session, std::vector<BasicCsvColumn<StereoFrameResult>> extra,
    BasicCsvColumn<StereoFrameResult> latency);

// The controller as a sink of the pair run (pipeline/run.h RunPipeline on pairs): each pair's
// angle (StereoMeasuredAngle) is one step of `control`, on the left frame's time, as one
// camera's frame is. Before the CSV and the stream: their columns read this pair's step.
class StereoControlSink : public PairSink {
 public:
  StereoControlSink(ControlSink& control, StereoAngle angle) : control_(control), angle_(angle) {}
  void consume(const FramePair& pair, const StereoFrameResult& result) override {
    control_.step(pair.left, StereoMeasuredAngle(result, angle_));
  }
  void end(const RunSummary& summary) override { control_.end(summary); }

 private:
  ControlSink& control_;
  StereoAngle angle_;
};

// --hook with two cameras: the hook runs as on one camera's frames, on each pair's first
// (left) frame and that camera's own tracking of it (its markers in image pixels, its own
// angle); its values go into the pair's row. A hook that wants 3D values reads the row's
// columns afterwards (the CSV, the stream): the hook's Python side knows one view's result.
class StereoHookSink : public PairSink {
 public:
  explicit StereoHookSink(HookSink& hook) : hook_(hook) {}
  // The hook's columns over the pair's rows: each the value the hook gave for the row's left
  // frame, or an empty field.
  std::vector<BasicCsvColumn<StereoFrameResult>> columns() const {
    std::vector<BasicCsvColumn<StereoFrameResult>> columns;
    for (CsvColumn& column : hook_.columns()) {
      columns.push_back({column.name, [append = std::move(column.append)](
                                          const StereoFrameResult& row, std::string& text) {
                           append(*row.left_view, text);
                         }});
    }
    return columns;
  }
  void begin(const RunInfo& info) override { hook_.begin(info); }
  void consume(const FramePair& pair, const StereoFrameResult& result) override {
    hook_.consume(pair.left, *result.left_view);
  }
  void end(const RunSummary& summary) override { hook_.end(summary); }
  void report(RunSummary& summary) const override { hook_.report(summary); }

 private:
  HookSink& hook_;
};

// The command line's two-camera options (control and identify): --stereo, --left-camera,
// --right-camera, --right-config, --stereo-angle, --max-epipolar-px, --sim-tilt-deg, into the
// command's ControlStereoOptions. StereoOptionsGiven then says whether they ask for two cameras
// (--stereo), and refuses the others without it.
const FlagTable<ControlStereoOptions>& ControlStereoFlags();
std::optional<ControlStereoOptions> StereoOptionsGiven(const CLI::App& sub,
                                                       const ControlStereoOptions& args);

}  // namespace softsight::control_parts
