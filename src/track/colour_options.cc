// ColourParams, registered once: key, unit, range and doc of every field (defaults: the struct).
#include "track/track_options.h"

namespace softsight {
namespace {

using Filter = ColourParams::Filter;
using Shape = ColourParams::Shape;

// An HSV channel's [lo, hi] as a two-element list.
Option<ColourParams> HsvOption(const char* key, HsvRange ColourParams::*range, int max,
                               const char* doc) {
  return CustomOption<ColourParams>(
             key, OptionKind::kInts,
             [range](const ColourParams& p) -> std::optional<OptionValue> {
               return OptionValue(std::vector<int64_t>{(p.*range).lo, (p.*range).hi});
             },
             [range](ColourParams& p, const std::optional<OptionValue>& v) {
               if (!v) return;
               const auto& list = std::get<std::vector<int64_t>>(*v);
               p.*range = HsvRange{static_cast<int>(list[0]), static_cast<int>(list[1])};
             })
      .Count(2)
      .Range(0, max)
      .Doc(doc)
      // With auto_colour or gray the ranges are not used, so a saved config does not carry them.
      .AppliesIf([](const ColourParams& p) { return !p.auto_bgr && !p.gray; });
}

// auto_colour: a nominal [b, g, r] instead of the HSV ranges.
Option<ColourParams> AutoColourOption() {
  using P = ColourParams;
  return CustomOption<P>(
      "auto_colour", OptionKind::kInts,
      [](const P& p) -> std::optional<OptionValue> {
        if (!p.auto_bgr) return std::nullopt;
        const cv::Vec3b c = *p.auto_bgr;
        return OptionValue(std::vector<int64_t>{c[0], c[1], c[2]});
      },
      [](P& p, const std::optional<OptionValue>& v) {
        if (!v) {
          p.auto_bgr.reset();
          return;
        }
        const auto& list = std::get<std::vector<int64_t>>(*v);
        p.auto_bgr = cv::Vec3b(static_cast<uchar>(list[0]), static_cast<uchar>(list[1]),
                               static_cast<uchar>(list[2]));
      },
      /*optional=*/true)
      .Count(3)
      .Range(0, 255)
      .Doc("nominal [b, g, r] instead of hsv: threshold around it, candidates verified against it");
}

// gray: a gray-level range instead of the HSV ranges.
Option<ColourParams> GrayLevelOption() {
  using P = ColourParams;
  return CustomOption<P>(
      "gray", OptionKind::kInts,
      [](const P& p) -> std::optional<OptionValue> {
        if (!p.gray) return std::nullopt;
        return OptionValue(std::vector<int64_t>{p.gray->lo, p.gray->hi});
      },
      [](P& p, const std::optional<OptionValue>& v) {
        if (!v) {
          p.gray.reset();
          return;
        }
        const auto& list = std::get<std::vector<int64_t>>(*v);
        p.gray = HsvRange{static_cast<int>(list[0]), static_cast<int>(list[1])};
      },
      /*optional=*/true)
      .Count(2)
      .Range(0, 255)
      .Doc("gray-level [lo, hi] instead of hsv: white or black dots, on gray or colour video");
}

// roi: where the first acquisition looks.
Option<ColourParams> RoiOption() {
  using P = ColourParams;
  return CustomOption<P>(
      "roi", OptionKind::kInts,
      [](const P& p) -> std::optional<OptionValue> {
        if (!p.roi) return std::nullopt;
        return OptionValue(
            std::vector<int64_t>{p.roi->x, p.roi->y, p.roi->width, p.roi->height});
      },
      [](P& p, const std::optional<OptionValue>& v) {
        if (!v) {
          p.roi.reset();
          return;
        }
        const auto& r = std::get<std::vector<int64_t>>(*v);
        p.roi = cv::Rect(static_cast<int>(r[0]), static_cast<int>(r[1]),
                         static_cast<int>(r[2]), static_cast<int>(r[3]));
      },
      /*optional=*/true)
      .Count(4)
      .Range(0, 65535)
      .Unit("px")
      .Doc("[x, y, w, h] where the first acquisition looks (a dragged rectangle)");
}

OptionTable<ColourParams> MakeColourTable() {
  using P = ColourParams;
  return {
      HsvOption("hsv.h", &P::h, 179, "hue [lo, hi], OpenCV's 0..179; lo > hi wraps round red"),
      HsvOption("hsv.s", &P::s, 255, "saturation [lo, hi]"),
      HsvOption("hsv.v", &P::v, 255, "value (brightness) [lo, hi]"),
      AutoColourOption(),
      GrayLevelOption(),
      EnumOption<P>("filter.type", &P::filter,
                    std::vector<std::pair<std::string, Filter>>{{"none", Filter::kNone},
                                                                {"gaussian", Filter::kGaussian},
                                                                {"median", Filter::kMedian}})
          .Doc("pre-filter: gaussian is cheap, median keeps edges sharper"),
      IntOption<P>("filter.ksize", &P::filter_ksize)
          .Odd()
          .Range(3, 31)
          .Unit("px")
          .Doc("filter kernel side; larger smooths more and blurs small markers"),
      IntOption<P>("morphology.size", &P::morph_size)
          .Odd()
          .Range(1, 31)
          .Unit("px")
          .Doc("opening then closing with this element side; 1 disables both"),
      EnumOption<P>("morphology.shape", &P::morph_shape,
                    std::vector<std::pair<std::string, Shape>>{{"rect", Shape::kRect},
                                                               {"ellipse", Shape::kEllipse},
                                                               {"cross", Shape::kCross}})
          .Doc("structuring element"),
      DoubleOption<P>("blob.min_area", &P::min_area_px)
          .Range(1, 1e9)
          .Unit("px^2")
          .Doc("smaller blobs are specks"),
      DoubleOption<P>("blob.max_area", &P::max_area_px)
          .Range(1, 1e9)
          .Or(0, "no limit")
          .Unit("px^2")
          .Doc("larger blobs are not the marker (at least blob.min_area)"),
      DoubleOption<P>("blob.min_circularity", &P::min_circularity)
          .Range(0, 1)
          .Doc("moment compactness: 1 disc, 0.8 a 2:1 ellipse, < 0.1 a cable"),
      DoubleOption<P>("blob.min_area_fraction", &P::min_area_fraction)
          .Range(0, 1)
          .Doc("a blob below this share of the marker's reference area is not found (covered)"),
      DoubleOption<P>("blob.max_area_factor", &P::max_area_factor)
          .Range(1, 1e6)
          .Or(0, "no limit")
          .Doc("a blob above this multiple of the reference area is not the marker"),
      EnumOption<P>("centroid", &P::centroid,
                    std::vector<std::pair<std::string, ColourParams::Centroid>>{
                        {"soft", ColourParams::Centroid::kSoft},
                        {"binary", ColourParams::Centroid::kBinary}})
          .Doc("soft: edge pixels weighted by membership (sub-pixel); binary: the paper's mask"),
      BoolOption<P>("rim_fit", &P::rim_fit)
          .Doc("a round marker seen smaller than learned is placed by the circle of its size "
               "through its visible rim (false: markers moving in depth, two cameras)"),
      DoubleOption<P>("ambiguity_margin", &P::ambiguity_margin)
          .Range(0, 10)
          .Doc("a runner-up within this misfit of the best makes the marker ambiguous (not found)"),
      DoubleOption<P>("adapt_rate", &P::adapt_rate)
          .Range(0, 1)
          .Doc("share per frame by which the learned area, shape and colour follow the marker"),
      RoiOption(),
      IntOption<P>("roi_frame", &P::roi_frame)
          .Range(0, 1e9)
          .Doc("frame the roi was picked on: the marker is not started before it (no roi: "
               "tracking starts there)"),
      IntOption<P>("window", &P::window_px)
          .Range(8, 4096)
          .Or(0, "search the whole frame")
          .Unit("px")
          .Doc("side of the square searched around the prediction while tracking"),
      IntOption<P>("widen_steps", &P::widen_steps)
          .Range(0, 8)
          .Doc("times the window doubles (same frame) before the whole frame is searched"),
      IntOption<P>("acquire_downsample", &P::acquire_downsample)
          .OneOf({1, 2, 4, 8})
          .Or(0, "automatic")
          .Doc("whole-frame acquisition samples one pixel per factor x factor cell first"),
  };
}

}  // namespace

const OptionTable<ColourParams>& ColourParamsOptions() {
  static const OptionTable<ColourParams> table = MakeColourTable();
  return table;
}

}  // namespace softsight
