// ColourTracker: the colour-intensity tracker of paper section 2.1 behind the Tracker interface.
// Private to the track module (built through CreateTracker); tests include it for the internals.
//
// Per frame:
//  1. While tracking, analyse a window around the constant-velocity prediction; if no acceptable
//     blob is there, or a blob touches the window's border nearer than the best one (the marker
//     may extend outside), double the window widen_steps times.
//  2. Otherwise acquire on the whole frame (or the ROI before the first success): threshold a
//     shrunk copy to find candidate cells, analyse each candidate at full resolution.
// "Analyse a region" is always the same full-resolution pipeline on the region plus a margin
// wide enough that filter and morphology see exactly what a whole-frame pass would see, so a
// blob that lies inside the region (not touching its border) is bit-identical to the blob a
// whole-frame analysis finds.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/tracker.h"

namespace softsight {

// One connected component of the marker mask, in frame coordinates.
struct ColourBlob {
  cv::Point2d centroid_px;  // m10/m00, m01/m00 (only for complete blobs).
  double area_px = 0;       // m00: pixel count.
  double circularity = 0;   // See ColourParams::min_circularity (only for complete blobs).
  cv::Rect bbox_px;
  bool clipped = false;     // Touches a region edge that is not a frame edge: incomplete.
};

// A hue/saturation/value box as one inRange call: a wrapping hue range is shifted by a lookup
// table so that it becomes one ordinary range.
struct HsvBox {
  bool shift = false;       // Apply `lut` (hue - lo mod 180) before inRange.
  cv::Mat lut;              // 1x256 CV_8UC3.
  cv::Scalar lower, upper;

  static HsvBox Make(HsvRange h, HsvRange s, HsvRange v);
};

class ColourTracker : public Tracker {
 public:
  // `params` must pass Check() (CreateTracker checks).
  explicit ColourTracker(const ColourParams& params);

  void init(const cv::Mat& frame_bgr, const cv::Rect& hint) override;
  Observation update(const cv::Mat& frame_bgr) override;
  void reset() override;

  // ---- Internals exposed for tests and benchmarks ------------------------------------------------
  // Every complete blob of the frame, whole-frame search at full resolution or coarse-to-fine
  // (downsample >= 2); sorted by (y, x) of the centroid.
  void find_blobs(const cv::Mat& frame_bgr, int downsample, std::vector<ColourBlob>* blobs);
  // The factor the next whole-frame acquisition would use.
  int acquire_downsample() const;
  std::optional<double> reference_area_px() const { return reference_area_px_; }
  std::optional<int> auto_threshold() const { return auto_threshold_; }
  // Bounded side of the last region searched (for tests of the windowing).
  const cv::Rect& last_search_px() const { return last_search_px_; }

 private:
  // Full-resolution pipeline on `region` (clipped to the frame); appends every blob with its
  // complete/clipped flag. Blobs below min_area_px are skipped unless clipped.
  void analyse(const cv::Mat& frame, cv::Rect region, std::vector<ColourBlob>* blobs);
  void analyse_region(const cv::Mat& frame, const cv::Rect& region,
                      std::vector<ColourBlob>* blobs);
  // Marker mask of `src` (already filtered) into `mask`.
  void classify(const cv::Mat& src, const HsvBox& box, int distance_threshold, cv::Mat& mask);
  // Every complete blob of `region`: analyse, growing the region around clipped blobs.
  void complete_blobs(const cv::Mat& frame, cv::Rect region, std::vector<ColourBlob>* blobs);
  // Coarse candidates -> full-resolution windows -> complete blobs.
  void coarse_to_fine(const cv::Mat& frame, cv::Rect region, int factor,
                      std::vector<ColourBlob>* blobs);
  void learn_auto_threshold(const cv::Mat& frame, const cv::Rect& region);

  bool acceptable(const ColourBlob& blob) const;
  std::optional<ColourBlob> track_in_windows(const cv::Mat& frame);
  std::optional<ColourBlob> acquire(const cv::Mat& frame);
  Observation report(const std::optional<ColourBlob>& blob);

  ColourParams params_;
  cv::Mat kernel_;          // Morphology structuring element.
  int margin_px_ = 0;       // Filter radius + 4 morphology radii (+1).
  HsvBox fine_box_, coarse_box_;

  // The marker, learned at acquisition.
  std::optional<double> reference_area_px_;
  double reference_circularity_ = 1.0;
  std::optional<int> auto_threshold_;         // Otsu's distance threshold (auto_bgr mode).
  std::optional<cv::Rect> acquire_roi_;       // Restricts acquisitions until the first success.

  // Motion.
  std::optional<cv::Point2d> last_px_;        // Last found position (kept to prefer on re-acquisition).
  cv::Point2d velocity_px_{0, 0};             // Per frame; 0 after a (re-)acquisition.
  bool tracking_ = false;                     // Found in the previous frame.
  cv::Size frame_size_;
  cv::Rect last_search_px_;

  // Buffers reused frame to frame: raw storage behind Mat headers of the size each frame needs.
  cv::Mat filtered_store_, hsv_store_, mask_store_, morph_store_, labels_store_, blob_store_;
  cv::Mat coarse_store_, coarse_mask_store_, coarse_labels_store_, tiles_store_;
  cv::Mat stats_, centroids_, coarse_stats_, coarse_centroids_;
  std::vector<ColourBlob> blobs_, pending_;
  std::vector<cv::Rect> windows_, boxes_;
  std::vector<cv::Point> points_;
};

}  // namespace softsight
