// Test support (tests only): the stereo calibration of a rendered rig, exactly as the renderer
// made it (no calibration error), so triangulation is tested on its own.
#pragma once

#include "softsight/calib/stereo_calibration.h"
#include "softsight/sim/stereo_scene.h"

namespace softsight::testing {

inline StereoCalibration CalibrationOfRig(const StereoRig& rig) {
  StereoCalibration stereo;
  stereo.left = {rig.left.image_size, rig.left.camera_matrix, rig.left.distortion};
  stereo.right = {rig.right.image_size, rig.right.camera_matrix, rig.right.distortion};
  stereo.R = rig.R;
  stereo.T = rig.T;
  CompleteStereoCalibration(stereo);
  return stereo;
}

}  // namespace softsight::testing
