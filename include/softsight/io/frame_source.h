// Where frames come from: a video file (anything FFmpeg reads), an image sequence (a folder or a
// printf pattern), a camera (V4L2 index, or GenICam through Aravis), or the synthetic renderer.
// Timestamps come from the source.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "softsight/core/types.h"
#include "softsight/io/camera_settings.h"

namespace softsight {

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Reads the next frame into `frame`, reusing its buffer when the size allows. Returns false at
  // the end of the stream. Throws InputError naming the source and frame index when a frame
  // fails to decode mid-stream.
  virtual bool read(Frame& frame) = 0;

  // Human-readable name for messages: "video demo.avi", "camera 0", "images shots/%04d.png".
  virtual std::string description() const = 0;

  // Number of frames when known in advance (files, synthetic scenes); absent for cameras.
  virtual std::optional<int64_t> frame_count() const = 0;

  // Nominal frame rate in frames per second when known.
  virtual std::optional<double> fps() const = 0;

  // True for live sources (cameras): no progress bar, frames may be dropped.
  virtual bool is_live() const { return false; }

  // Frames the source skipped so far because its reader was slower than it (newest frame wins,
  // see NewestFrameSource). Files, image sequences and rendered scenes never drop: always 0.
  virtual int64_t dropped_frames() const { return 0; }
  // Something the run's summary should say about the input, e.g. gaps in an image sequence's
  // numbering ("the numbering has gaps: 3 file numbers missing (first: 5..7) ...").
  virtual std::optional<std::string> note() const { return std::nullopt; }

  // The files this source reads (a video; every file of an image sequence); none for cameras
  // and synthetic scenes. Outputs are checked against them before anything is written.
  virtual std::vector<std::string> files() const { return {}; }

  // Makes the frame `position` frames after the first one (0-based, in the order read() returns
  // them) the next one read() returns, without decoding the frames before it, when the source
  // can do that exactly: a video through its container's index (FFmpeg's own seek, which decodes
  // from the key frame before the target up to it), an image sequence, a rendered scene. Returns
  // false, changing nothing, when it cannot (a camera; a video that has shown damaged frames, as
  // its positions and frame numbers then differ; a position past the known end). A position
  // beyond a too-long header count makes the next read() return false.
  virtual bool seek_to(int64_t position) {
    (void)position;
    return false;
  }
};

}  // namespace softsight

namespace softsight {

struct SceneOptions;
struct PlateSceneOptions;
struct NoiseOptions;

// How to open a source. Exactly one of `input` or `camera` is used.
// `input` naming a built-in synthetic scene: "synth:bending", "synth:wedge1", "synth:wedge4",
// "synth:bench", "synth:plate" (see softsight/sim/builtin_scenes.h).
inline constexpr const char* kSyntheticPrefix = "synth:";

struct FrameSourceSpec {
  // A video file (anything FFmpeg reads), a folder of images (sorted by name), a numbered
  // pattern such as "frames/%04d.png" (one %d or %0Nd; rows carry each file's number), or a
  // synthetic scene ("synth:bending").
  std::string input{};
  std::optional<CameraId> camera{};    // A camera (live): V4L2 index or Aravis device.
  // Frame rate for image sequences, whose files carry no timestamps (frames per second).
  double sequence_fps = 30.0;
  // The camera's capture settings (config `capture:` and --camera-* options), applied when it
  // opens; what it accepted goes to `capture_report` when given. Ignored for files.
  CameraSettings capture = {};
  CameraSettingsReport* capture_report = nullptr;
};

// Opens the source; throws InputError naming the file or camera when it cannot be read.
std::unique_ptr<FrameSource> OpenFrameSource(const FrameSourceSpec& spec);

// A synthetic scene as a source (frames rendered on demand, exact timestamps from the scene).
std::unique_ptr<FrameSource> OpenSyntheticSource(const SceneOptions& scene,
                                                 const NoiseOptions& noise);
std::unique_ptr<FrameSource> OpenSyntheticSource(const PlateSceneOptions& scene,
                                                 const NoiseOptions& noise);

// True when every pixel of a BGR frame has B == G == R (a grayscale video decoded as BGR).
bool IsGrayscale(const cv::Mat& frame_bgr);

}  // namespace softsight
