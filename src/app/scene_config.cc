#include "app/scene_config.h"

#include <filesystem>
#include <variant>

#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "softsight/sim/builtin_scenes.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {

ColourParams ThresholdsFor(const cv::Vec3b& bgr) {
  cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar(bgr[0], bgr[1], bgr[2])), hsv;
  cv::cvtColor(pixel, hsv, cv::COLOR_BGR2HSV);
  const int hue = hsv.at<cv::Vec3b>(0, 0)[0];
  ColourParams params;
  params.h = HsvRange::HueAround(hue, 12);
  params.s = {80, 255};
  params.v = {40, 255};
  params.filter = ColourParams::Filter::kNone;
  return params;
}

TrackingConfig ConfigForScene(const SceneOptions& scene) {
  TrackingConfig config;
  for (const SceneMarker& marker : scene.markers) {
    MarkerSpec spec;
    spec.name = marker.name;
    ColourParams colour = ThresholdsFor(marker.bgr);
    // The scenes render with sensor noise: a light smoothing, as a person would add.
    colour.filter = ColourParams::Filter::kGaussian;
    colour.filter_ksize = 3;
    spec.params = colour;
    config.markers.push_back(spec);
  }
  config.measure = SceneMeasureOptions(scene);
  // As if the camera saw the actuator's plane at 0.25 mm per pixel.
  config.measure.metric.scale_mm_per_px = 0.25;
  return config;
}

std::string ConfigForBuiltinInput(const std::string& input, const std::string& folder) {
  const std::string prefix = "synth:";
  if (input.rfind(prefix, 0) != 0) {
    throw InputError("--config is required for " + (input.empty() ? std::string("a camera") : input) +
                     ": give the marker configuration (YAML, see examples/ or `softsight init`); "
                     "only a synth: scene brings its own");
  }
  const std::string name = input.substr(prefix.size());
  const BuiltinSceneOptions scene = ParseBuiltinScene(name);  // InputError for an unknown name.
  if (!std::holds_alternative<SceneOptions>(scene)) {
    throw InputError("--config is required for " + input +
                     " (only the actuator scenes bring their own; see examples/)");
  }
  const std::string path = (std::filesystem::path(folder) / ("synth-" + name + ".yaml")).string();
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    SaveTrackingConfig(ConfigForScene(std::get<SceneOptions>(scene)), path);
  }
  return path;
}

}  // namespace softsight
