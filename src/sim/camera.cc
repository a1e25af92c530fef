#include "sim/camera.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace softsight::sim {

uint64_t Mix(uint64_t seed, uint64_t index) {
  uint64_t z = seed + 0x9E3779B97F4A7C15ull * (index + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double GainAt(const NoiseOptions& noise, int index, int frame_count) {
  const double t = frame_count > 1 ? std::clamp(index / double(frame_count - 1), 0.0, 1.0) : 0.0;
  return noise.gain_start + (noise.gain_end - noise.gain_start) * t;
}

void ApplyCamera(const NoiseOptions& noise, double gain, int index, cv::Mat& image,
                 cv::Mat& noise_buffer) {
  if (noise.blur_sigma_px > 0) cv::GaussianBlur(image, image, cv::Size(0, 0), noise.blur_sigma_px);
  if (gain != 1.0) image.convertTo(image, -1, gain);
  if (noise.sigma > 0) {
    cv::RNG rng(Mix(noise.seed, static_cast<uint64_t>(index)));
    noise_buffer.create(image.size(), CV_MAKETYPE(CV_16S, image.channels()));
    rng.fill(noise_buffer, cv::RNG::NORMAL, 0.0, noise.sigma);
    cv::add(image, noise_buffer, image, cv::noArray(), CV_8U);
  }
}

}  // namespace softsight::sim
