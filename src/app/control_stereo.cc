#include "app/control_stereo.h"

#include <chrono>
#include <cmath>
#include <iostream>

#include "app/capture_options.h"
#include "app/cli_checks.h"
#include "app/shared_flags.h"
#include "app/track_stereo_command.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/run_source.h"
#include "softsight/track/colour_tracker.h"

namespace softsight::control_parts {
namespace {

constexpr const char* kBuiltinStereo = "builtin";

// The simulated pair's calibration, exactly as it renders (no calibration error).
StereoCalibration CalibrationOf(const StereoRig& rig) {
  StereoCalibration stereo;
  stereo.left = {rig.left.image_size, rig.left.camera_matrix, rig.left.distortion};
  stereo.right = {rig.right.image_size, rig.right.camera_matrix, rig.right.distortion};
  stereo.R = rig.R;
  stereo.T = rig.T;
  CompleteStereoCalibration(stereo);
  return stereo;
}

std::string SizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

std::unique_ptr<FrameSource> OpenCamera(const CameraId& camera, const ControlOptions& options,
                                        const TrackingConfig& config) {
  FrameSourceSpec spec;
  spec.camera = camera;
  spec.capture =
      MergeCaptureOptions(options.capture_args, config.capture.value_or(CameraSettings{}));
  CameraSettingsReport accepted;
  spec.capture_report = &accepted;
  std::unique_ptr<FrameSource> source = SourceForRun(OpenFrameSource(spec), FilePacing::kReadAhead);
  PrintCaptureReport(accepted);
  return source;
}

}  // namespace

StereoAngle ParseStereoAngle(const std::string& text) {
  if (text == "3d") return StereoAngle::k3d;
  if (text == "left") return StereoAngle::kLeft;
  if (text == "right") return StereoAngle::kRight;
  throw InputError("--stereo-angle " + EscapeForMessage(text) + ": expected 3d, left or right");
}

std::optional<double> StereoMeasuredAngle(const StereoFrameResult& result, StereoAngle angle) {
  switch (angle) {
    case StereoAngle::k3d: return result.shape.angle_deg;
    case StereoAngle::kLeft: return result.left_angle_deg;
    case StereoAngle::kRight: return result.right_angle_deg;
  }
  return std::nullopt;
}

SimulatedStereoRigInput::SimulatedStereoRigInput(SimulatedRig& rig, const StereoScene& scene,
                                                 double fps, double duration_s)
    : rig_(rig), scene_(scene), fps_(fps),
      frames_(static_cast<int64_t>(std::floor(duration_s * fps + 1e-9)) + 1) {}

bool SimulatedStereoRigInput::read(FramePair& pair) {
  if (index_ >= frames_) return false;
  if (index_ > 0) rig_.advance(1.0 / fps_);
  truth_ = rig_.snapshot();
  const double t = static_cast<double>(index_) / fps_;
  scene_truth_ = scene_.render_at_bend(truth_->bend_deg, static_cast<int>(index_),
                                       pair.left.image, pair.right.image);
  for (Frame* frame : {&pair.left, &pair.right}) {
    frame->index = index_;
    frame->time_s = t;
    frame->captured = std::chrono::steady_clock::now();
  }
  pair.pair_dt_ms.reset();
  ++index_;
  return true;
}

StereoControlFrames OpenStereoSession(const ControlOptions& options,
                                      const TrackingConfig& left_config,
                                      std::vector<PathRole>* inputs) {
  const ControlStereoOptions& o = *options.stereo;
  StereoControlFrames frames;
  frames.angle = ParseStereoAngle(o.angle);
  const bool cameras = o.left_camera || o.right_camera;
  if (options.simulate && cameras) {
    throw InputError("--simulate --stereo: the simulated rig is rendered into both views; "
                     "give no --left-camera / --right-camera");
  }
  if (!options.simulate && !(o.left_camera && o.right_camera)) {
    throw InputError("--stereo: give both --left-camera and --right-camera (or "
                     "--simulate)");
  }
  if (!(o.sim_tilt_deg >= 0.0 && o.sim_tilt_deg <= 80.0)) {
    throw InputError("--sim-tilt-deg " + ShortNumber(o.sim_tilt_deg) + ": must be in [0, 80]");
  }

  StereoCalibration calibration;
  const StereoRig simulated_pair = MakeStereoRig();
  if (o.stereo_file == kBuiltinStereo) {
    if (!options.simulate) {
      throw InputError("--stereo builtin: the simulated pair's calibration is for --simulate; "
                       "give the file of `softsight calibrate --left ... --right ...`");
    }
    calibration = CalibrationOf(simulated_pair);
  } else {
    try {
      calibration = LoadStereoCalibration(o.stereo_file);
    } catch (const InputError& e) {
      throw InputError(std::string("--stereo ") + e.what());
    }
    inputs->push_back({"--stereo", o.stereo_file});
    if (options.simulate && calibration.left.image_size != simulated_pair.left.image_size) {
      throw InputError("--stereo " + o.stereo_file + ": calibrated for " +
                       SizeText(calibration.left.image_size) +
                       " images, but the simulated cameras give " +
                       SizeText(simulated_pair.left.image_size) +
                       " (--stereo builtin: the simulated pair's own calibration)");
    }
  }
  TrackingConfig right_config = left_config;
  if (o.right_config_file) {
    right_config = LoadStereoViewConfig(*o.right_config_file);
    for (PathRole& role : ConfigInputs(right_config)) inputs->push_back(std::move(role));
    inputs->push_back({"--right-config", *o.right_config_file});
  }
  StereoOptions stereo_options;
  stereo_options.triangulation.max_epipolar_px = o.max_epipolar_px;
  std::string error;
  if (!stereo_options.Check(&error)) throw InputError("--max-epipolar-px: " + error);
  frames.session =
      std::make_unique<StereoSession>(left_config, right_config, calibration, stereo_options);
  return frames;
}

void OpenStereoPairs(const ControlOptions& options, const TrackingConfig& left_config,
                     SimulatedRig* rig, double duration_s, StereoControlFrames* frames_out) {
  const ControlStereoOptions& o = *options.stereo;
  StereoControlFrames& frames = *frames_out;
  if (options.simulate) {
    const StereoRig simulated_pair = MakeStereoRig();
    StereoSceneOptions scene;
    scene.plane_tilt_start_deg = scene.plane_tilt_end_deg = o.sim_tilt_deg;
    scene.supersample = options.sim_supersample;
    scene.hidden = o.sim_hidden;
    frames.scene = std::make_unique<StereoScene>(simulated_pair, scene);
    auto input =
        std::make_unique<SimulatedStereoRigInput>(*rig, *frames.scene, options.fps, duration_s);
    frames.rendered = input.get();
    frames.input = std::move(input);
    frames.fps = options.fps;
  } else {
    TimePairingOptions pairing;
    pairing.clock = TimePairingOptions::Clock::kCaptureTime;
    frames.input = PairByTime(OpenCamera(*o.left_camera, options, left_config),
                              OpenCamera(*o.right_camera, options, left_config), pairing);
  }
}

BasicCsvColumnTable<StereoFrameResult> StereoControlColumns(
    const StereoSession& session, std::vector<BasicCsvColumn<StereoFrameResult>> extra,
    BasicCsvColumn<StereoFrameResult> latency) {
  BasicCsvColumnTable<StereoFrameResult> columns =
      StereoColumns(session.marker_names(), session.segment_names());
  for (BasicCsvColumn<StereoFrameResult>& column : extra) {
    columns.insert_before("proc_ms", std::move(column));
  }
  columns.insert_before("proc_ms", std::move(latency));
  return columns;
}

const FlagTable<ControlStereoOptions>& ControlStereoFlags() {
  using A = ControlStereoOptions;
  static const FlagTable<ControlStereoOptions> table = {
      ValueFlag<A>(kStereoFlag, &A::stereo_file)
          .Help("Two cameras: close the loop on the 3D angle. The pair's calibration "
                "from `softsight calibrate --left ... --right ...`, or `builtin` with "
                "--simulate (the simulated pair of docs/stereo.md, the actuator bending "
                "out of the image plane)"),
      CameraFlag<A>("--left-camera", &A::left_camera,
                    "With --stereo: the first camera, paired with the second by capture time"),
      CameraFlag<A>("--right-camera", &A::right_camera, "With --stereo: the second camera"),
      RightConfigFlag<A>(&A::right_config_file,
                         "With --stereo: the right view's marker config, when its colours or rois "
                         "differ (same names)"),
      ValueFlag<A>("--stereo-angle", &A::angle)
          .Help("With --stereo: the angle the loop closes on: 3d (verified in both views), or "
                "left / right (that camera's own 2D angle, to compare)")
          .ShowDefault(),
      MaxEpipolarFlag<A>(&A::max_epipolar_px,
                         "With --stereo: a pair farther than this from its epipolar line is not "
                         "believed (a lost marker to the loop)"),
      ValueFlag<A>("--sim-tilt-deg", &A::sim_tilt_deg)
          .Help("With --simulate --stereo: the simulated actuator's bending plane, turned this "
                "far out of the first camera's image plane (deg)")
          .ShowDefault()
          .Check(NumberIn(0, 80)),
  };
  return table;
}

std::optional<ControlStereoOptions> StereoOptionsGiven(const CLI::App& sub,
                                                       const ControlStereoOptions& args) {
  if (sub.count("--stereo") > 0) return args;
  for (const char* option : {"--left-camera", "--right-camera", "--right-config", "--stereo-angle",
                             "--max-epipolar-px", "--sim-tilt-deg"}) {
    if (sub.count(option) > 0) {
      throw InputError(std::string(option) + " is for two cameras: give --stereo FILE (or "
                       "--stereo builtin with --simulate)");
    }
  }
  return std::nullopt;
}

}  // namespace softsight::control_parts
