// `softsight track-stereo`: two videos of one actuator from a calibrated pair of cameras ->
// each view tracked by its own TrackingSession -> markers matched by name, epipolar-checked and
// triangulated -> 3D positions and measurements, one CSV row per pair of frames.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace softsight {

struct TrackStereoOptions {
  std::string config_file;                       // Markers (and the triple or chain).
  std::optional<std::string> right_config_file;  // The right view's, when its rois differ.
  std::string left_input, right_input;           // Videos, image folders or patterns.
  std::string stereo_file;                       // From `calibrate --left --right`.
  std::string csv_file;
  // The right view's frame paired with left frame i is i + frame_offset (the right camera
  // started recording frame_offset frames earlier; negative: later).
  int64_t frame_offset = 0;
  double max_epipolar_px = 2.0;           // See TriangulationOptions.
  std::string reference_plane = "image";  // "image" or "first" (StereoOptions).
  std::optional<int64_t> max_frames;
  double sequence_fps = 30.0;  // Image sequences' frame rate.
};

struct TrackStereoSummary {
  int64_t pairs = 0;  // Pairs of frames tracked (CSV rows).
  // Per marker: pairs found in 3D, and pairs refused by the epipolar check.
  std::vector<std::pair<std::string, int64_t>> found, epipolar;
  std::optional<double> median_sigma_mm;     // Over the found points.
  std::optional<double> median_epipolar_px;  // Over the pairs both views found.
};

// Runs the whole job and prints its report. Throws InputError for bad input (config, stereo
// file, videos, offset, outputs that are inputs) or a frame of the wrong size.
TrackStereoSummary RunTrackStereo(const TrackStereoOptions& options, std::ostream& report);

}  // namespace softsight
