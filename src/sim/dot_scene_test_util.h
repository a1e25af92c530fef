// An independent renderer for tests (test code only): free markers of any shape moving along
// given paths over a textured background, drawn with OpenCV's own shapes at 4x and area-averaged
// down, with optional motion blur (sub-frame exposures) and sensor noise. It shares no code with
// sim/scene.cc, so the trackers are tried on footage they were not developed against: carts on a
// track, dots on a hand-held plate, a sticker on a wheel, a disc behind a paddle.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace softsight::testing {

// Where a shape is at time t (in frames; fractional for motion blur) and how it is turned.
struct DotPose {
  cv::Point2d centre_px;
  double angle_deg = 0.0;
  bool visible = true;
  double scale = 1.0;  // Of the shape's radii (a plate coming closer).
};

struct DotShape {
  cv::Size2d radii_px{5, 5};        // Semi-axes (an ellipse; equal: a disc).
  cv::Vec3b bgr{0, 220, 230};
  // A highlight: a smaller bright ellipse inside the shape, offset from its centre (a specular
  // reflection on a glossy puck).
  std::optional<cv::Vec3b> highlight_bgr;
  double highlight_fraction = 0.35;   // Of the radii.
  cv::Point2d highlight_offset{0.3, -0.3};  // In radii.
  std::function<DotPose(double t)> path;
};

// A rectangle over everything (a paddle, a hand), from frame `first` to `last`, moving.
struct DotCover {
  std::function<cv::Rect2d(double t)> rect_px;
  int first = 0, last = 1 << 30;
  cv::Vec3b bgr{60, 60, 60};
};

struct DotSceneOptions {
  cv::Size size{640, 480};
  uint64_t seed = 1;
  double noise_sigma = 2.0;
  int blur_samples = 1;       // Sub-frame exposures per frame (1: none).
  double exposure = 0.5;      // Fraction of the frame interval the shutter is open.
  // Background: mean gray with low-frequency blotches and fine grain; `clutter` adds gray
  // rectangles and discs (not of any shape's colour unless `clutter_bgr` says so).
  double background_level = 110;
  double tint_sigma = 6.0;  // Per-channel tint of the blotches (0: a gray bench).
  int clutter = 0;
  std::optional<cv::Vec3b> clutter_bgr;
};

class DotScene {
 public:
  DotScene(DotSceneOptions options, std::vector<DotShape> shapes, std::vector<DotCover> covers = {})
      : options_(options), shapes_(std::move(shapes)), covers_(std::move(covers)) {
    MakeBackground();
  }

  const std::vector<DotShape>& shapes() const { return shapes_; }

  // The exact centre of shape `s` at frame `frame` (mid-exposure), absent when not visible.
  std::optional<cv::Point2d> truth(size_t s, int frame) const {
    const DotPose pose = shapes_[s].path(frame);
    if (!pose.visible) return std::nullopt;
    return pose.centre_px;
  }

  // Frame `frame`, CV_8UC3. Only the pixels near shapes and covers are drawn at 4x and averaged
  // down (the rest is the background, averaged once): the 4x average of a pixel is its own 4x4
  // block's, so the picture is the whole-frame render's, bit for bit, at a small part of its cost.
  cv::Mat render(int frame) const {
    cv::Mat accumulated(options_.size, CV_32FC3, cv::Scalar::all(0));
    const int samples = std::max(1, options_.blur_samples);
    cv::Mat small, canvas, block;
    std::vector<Drawing> drawings;
    std::vector<cv::Rect> dirty;
    for (int k = 0; k < samples; ++k) {
      const double t = samples == 1 ? frame
                                    : frame + options_.exposure * ((k + 0.5) / samples - 0.5);
      Drawings(frame, t, &drawings);
      DirtyRects(drawings, &dirty);
      background_small_.copyTo(small);
      for (const cv::Rect& r : dirty) {
        const cv::Rect big(r.x * kSs, r.y * kSs, r.width * kSs, r.height * kSs);
        background_big_(big).copyTo(canvas);
        for (const Drawing& d : drawings) d.draw(canvas, big.tl());
        cv::resize(canvas, block, r.size(), 0, 0, cv::INTER_AREA);
        block.copyTo(small(r));
      }
      cv::accumulate(small, accumulated);
    }
    accumulated *= 1.0 / samples;
    cv::Mat noise(options_.size, CV_32FC3);
    cv::RNG rng(options_.seed * 7919 + static_cast<uint64_t>(frame) + 1);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options_.noise_sigma);
    accumulated += noise;
    cv::Mat out;
    accumulated.convertTo(out, CV_8UC3);
    return out;
  }

  // A rectangle around shape `s` at frame 0, as a person would drag it (`margin` px around).
  cv::Rect roi(size_t s, int frame = 0, int margin = 6) const {
    const cv::Point2d c = *truth(s, frame);
    const double r = std::max(shapes_[s].radii_px.width, shapes_[s].radii_px.height) + margin;
    return cv::Rect(cvFloor(c.x - r), cvFloor(c.y - r), cvCeil(2 * r) + 1, cvCeil(2 * r) + 1);
  }

 private:
  static constexpr int kSs = 4;     // Supersampling: shapes are drawn at 4x.
  static constexpr int kShift = 4;  // Fractional bits of cv::ellipse's coordinates.

  // One shape or cover of a frame's sub-exposure, drawn into a 4x canvas whose pixel (0, 0) is
  // the 4x frame's `origin` (an integer shift of integer coordinates: the same pixels as drawn
  // into the whole 4x frame). `reach`: the output pixels it can touch.
  struct Drawing {
    bool ellipse = true;
    cv::Point centre;  // Ellipse: 4x coordinates with kShift fractional bits.
    cv::Size axes;
    double angle_deg = 0;
    cv::Point tl, br;  // Cover: 4x pixels, inclusive.
    cv::Scalar bgr;
    cv::Rect reach;
    void draw(cv::Mat& canvas, const cv::Point& origin) const {
      if (ellipse) {
        const cv::Point c = centre - origin * (1 << kShift);
        cv::ellipse(canvas, c, axes, angle_deg, 0, 360, bgr, cv::FILLED, cv::LINE_8, kShift);
      } else {
        cv::rectangle(canvas, tl - origin, br - origin, bgr, cv::FILLED);
      }
    }
  };

  static Drawing EllipseDrawing(const cv::Point2d& centre, const cv::Size2d& radii,
                                double angle_deg, const cv::Vec3b& bgr) {
    const double scale = kSs * (1 << kShift);
    // Output pixel-centre convention: output x covers big columns [4x, 4x + 4), so its centre
    // at x maps to big coordinate 4 (x + 0.5) in the big image's own pixel-centre convention
    // minus 0.5.
    Drawing d;
    d.centre = cv::Point(cvRound((centre.x + 0.5) * scale - 0.5 * (1 << kShift)),
                         cvRound((centre.y + 0.5) * scale - 0.5 * (1 << kShift)));
    d.axes = cv::Size(cvRound(radii.width * scale), cvRound(radii.height * scale));
    d.angle_deg = angle_deg;
    d.bgr = cv::Scalar(bgr);
    const double r = std::max(radii.width, radii.height) + 2;
    d.reach = cv::Rect(cvFloor(centre.x - r), cvFloor(centre.y - r), cvCeil(2 * r) + 1,
                       cvCeil(2 * r) + 1);
    return d;
  }

  static void DrawEllipse(cv::Mat& big, const cv::Point2d& centre, const cv::Size2d& radii,
                          double angle_deg, const cv::Vec3b& bgr) {
    EllipseDrawing(centre, radii, angle_deg, bgr).draw(big, {0, 0});
  }

  // The shapes and covers at time t of frame `frame`, in drawing order.
  void Drawings(int frame, double t, std::vector<Drawing>* out) const {
    out->clear();
    for (const DotShape& shape : shapes_) {
      const DotPose pose = shape.path(t);
      if (!pose.visible) continue;
      const cv::Size2d radii = shape.radii_px * pose.scale;
      out->push_back(EllipseDrawing(pose.centre_px, radii, pose.angle_deg, shape.bgr));
      if (shape.highlight_bgr) {
        const double a = pose.angle_deg * CV_PI / 180.0;
        const cv::Point2d off(shape.highlight_offset.x * radii.width,
                              shape.highlight_offset.y * radii.height);
        const cv::Point2d turned(off.x * std::cos(a) - off.y * std::sin(a),
                                 off.x * std::sin(a) + off.y * std::cos(a));
        const cv::Point2d c = pose.centre_px + turned;
        out->push_back(EllipseDrawing(c, radii * shape.highlight_fraction, pose.angle_deg,
                                      *shape.highlight_bgr));
      }
    }
    for (const DotCover& cover : covers_) {
      if (frame < cover.first || frame > cover.last) continue;
      const cv::Rect2d r = cover.rect_px(t);
      Drawing d;
      d.ellipse = false;
      d.tl = cv::Point(cvRound((r.x + 0.5) * kSs), cvRound((r.y + 0.5) * kSs));
      d.br = cv::Point(cvRound((r.x + r.width + 0.5) * kSs) - 1,
                       cvRound((r.y + r.height + 0.5) * kSs) - 1);
      d.bgr = cv::Scalar(cover.bgr);
      const auto out_px = [](int big) { return cvFloor(big / static_cast<double>(kSs)); };
      d.reach = cv::Rect(cv::Point(out_px(d.tl.x) - 1, out_px(d.tl.y) - 1),
                         cv::Point(out_px(d.br.x) + 2, out_px(d.br.y) + 2));
      out->push_back(d);
    }
  }

  // The output rectangles to draw: every drawing's reach, overlapping ones merged (so each
  // drawing lies whole inside the one rectangle that holds it), clipped to the frame.
  void DirtyRects(const std::vector<Drawing>& drawings, std::vector<cv::Rect>* out) const {
    out->clear();
    for (const Drawing& d : drawings) out->push_back(d.reach);
    for (bool merged = true; merged;) {
      merged = false;
      for (size_t i = 0; i < out->size() && !merged; ++i) {
        for (size_t j = i + 1; j < out->size(); ++j) {
          if (((*out)[i] & (*out)[j]).area() > 0) {
            (*out)[i] |= (*out)[j];
            out->erase(out->begin() + static_cast<std::ptrdiff_t>(j));
            merged = true;
            break;
          }
        }
      }
    }
    const cv::Rect frame_rect(cv::Point(0, 0), options_.size);
    for (cv::Rect& r : *out) r &= frame_rect;
    const auto empty = [](const cv::Rect& r) { return r.empty(); };
    out->erase(std::remove_if(out->begin(), out->end(), empty), out->end());
  }

  void MakeBackground() {
    cv::RNG rng(options_.seed);
    // Blotches of brightness (18 levels) with a little tint (6 levels per channel), as a bench
    // under one light.
    const cv::Size coarse(options_.size.width / 16 + 2, options_.size.height / 16 + 2);
    cv::Mat level(coarse, CV_32F), tint(coarse, CV_32FC3), blotches;
    rng.fill(level, cv::RNG::NORMAL, 0.0, 18.0);
    rng.fill(tint, cv::RNG::NORMAL, 0.0, std::max(options_.tint_sigma, 1e-9));
    cv::cvtColor(level, blotches, cv::COLOR_GRAY2BGR);
    blotches += tint;
    cv::Mat low;
    cv::resize(blotches, low, options_.size, 0, 0, cv::INTER_CUBIC);
    cv::Mat grain(options_.size, CV_32FC3);
    rng.fill(grain, cv::RNG::NORMAL, 0.0, 6.0);
    cv::GaussianBlur(grain, grain, cv::Size(0, 0), 0.8);
    cv::Mat bg = low + grain + cv::Scalar::all(options_.background_level);
    cv::Mat bg8;
    bg.convertTo(bg8, CV_8UC3);
    cv::resize(bg8, background_big_,
               cv::Size(options_.size.width * kSs, options_.size.height * kSs), 0, 0,
               cv::INTER_LINEAR);
    for (int k = 0; k < options_.clutter; ++k) {
      const cv::Point2d c(rng.uniform(0.0, options_.size.width * 1.0),
                          rng.uniform(0.0, options_.size.height * 1.0));
      const int level = rng.uniform(40, 220);
      const cv::Vec3b bgr = options_.clutter_bgr ? *options_.clutter_bgr
                                                 : cv::Vec3b(level, level, level);
      if (k % 2 == 0) {
        const cv::Size2d radii(rng.uniform(3.0, 30.0), rng.uniform(3.0, 30.0));
        DrawEllipse(background_big_, c, radii, rng.uniform(0.0, 180.0), bgr);
      } else {
        const cv::Rect r(cvRound(c.x * kSs), cvRound(c.y * kSs), rng.uniform(8, 200),
                         rng.uniform(8, 200));
        cv::rectangle(background_big_, r, cv::Scalar(bgr), cv::FILLED);
      }
    }
    cv::resize(background_big_, background_small_, options_.size, 0, 0, cv::INTER_AREA);
  }

  DotSceneOptions options_;
  std::vector<DotShape> shapes_;
  std::vector<DotCover> covers_;
  cv::Mat background_big_;
  cv::Mat background_small_;  // background_big_ averaged down, as every frame starts.
};

}  // namespace softsight::testing
