// Compiled with the public-headers check (cmake/softsight.cmake), with the project's -Wall -Wextra
// (and -Werror in CI): a library user's designated initializers name only the fields they set,
// and -Wextra's missing-field-initializers warned for every field without a default member
// initializer (`FrameSourceSpec{.input = "run.avi"}` warned for `camera`). Every data member of
// a public struct has one ({} where the type's own default is meant); a new member without one
// fails here when its struct is below. Nothing runs: compiling is the check.
#include <string>

#include "softsight/calib/camera_calibration.h"
#include "softsight/config/config.h"
#include "softsight/core/types.h"
#include "softsight/geometry/measurement.h"
#include "softsight/io/camera_settings.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/frame_writer.h"
#include "softsight/io/plot.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/stereo_session.h"
#include "softsight/sim/scene.h"
#include "softsight/track/marker_finder.h"

namespace softsight {

// Each as a user would write it: one or two fields, the rest their defaults.
[[maybe_unused]] void DesignatedInitializersOfThePublicStructs() {
  [[maybe_unused]] const FrameSourceSpec video{.input = "run.avi"};
  [[maybe_unused]] const FrameSourceSpec camera{.camera = 0, .sequence_fps = 60.0};
  [[maybe_unused]] const RunOptions run{.max_frames = 100};
  [[maybe_unused]] const SceneMarker marker{.name = "red", .body_fraction = 0.5};
  [[maybe_unused]] const SceneOptions scene{.frame_count = 30};
  [[maybe_unused]] const NoiseOptions noise{.sigma = 5.0};
  [[maybe_unused]] const MeasureOptions measure{.base = "red", .middle = "blue", .tip = "green"};
  [[maybe_unused]] const MetricModel metric{.scale_mm_per_px = 0.2};
  [[maybe_unused]] const FrameWriterOptions writer{.path = "out.avi"};
  [[maybe_unused]] const PlotOptions plot{.title = "run"};
  [[maybe_unused]] const CameraSettings settings{.fps = 30.0};
  [[maybe_unused]] const ChessboardSpec board{.square_mm = 20.0};
  [[maybe_unused]] const CalibrationOptions calibration{.estimate_k3 = true};
  [[maybe_unused]] const MarkerFinderOptions finder{.expected_count = 3};
  [[maybe_unused]] const Observation observation{.score = 0.9};
  [[maybe_unused]] const MarkerObservation named{.name = "red"};
  [[maybe_unused]] const Measurement measurement{.angle_deg = 120.0};
  [[maybe_unused]] const FrameResult result{.frame_index = 0};
  [[maybe_unused]] const StereoOptions stereo{.board_normal = cv::Vec3d(0, 0, 1)};
  [[maybe_unused]] const TrackingConfig config{.measure = measure};
}

}  // namespace softsight
