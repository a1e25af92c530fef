// The measurement settings, registered once: key, unit, range and doc of every field (defaults:
// the structs).
#include "geometry/measure_options.h"

namespace softsight {
namespace {

OptionTable<MetricModel> MakeMetric() {
  using P = MetricModel;
  return {
      DoubleOption<P>("scale_mm_per_px", &P::scale_mm_per_px)
          .Above(0)
          .AtMost(1e6)
          .Unit("mm/px")
          .Doc("one scale: the camera axis orthogonal to the actuator's plane (adds _mm columns)")
          // A scale measured between two points is written as those points.
          .AppliesIf([](const P& m) { return !m.scale_points; }),
      CustomOption<P>(
          "plane_mm_from_image", OptionKind::kDoubles,
          [](const P& m) -> std::optional<OptionValue> {
            if (!m.plane_mm_from_image) return std::nullopt;
            return OptionValue(std::vector<double>(m.plane_mm_from_image->val,
                                                   m.plane_mm_from_image->val + 9));
          },
          [](P& m, const std::optional<OptionValue>& v) {
            if (!v) {
              m.plane_mm_from_image.reset();
              return;
            }
            const auto& h = std::get<std::vector<double>>(*v);
            cv::Matx33d matrix;
            for (int i = 0; i < 9; ++i) matrix.val[i] = h[i];
            m.plane_mm_from_image = matrix;
          },
          /*optional=*/true)
          .Count(9)
          .Range(-1e12, 1e12)
          .Doc("homography image px -> plane mm, row-major (what `plane:` loads; a saved config)"),
  };
}

OptionTable<MeasureOptions> MakeMeasure() {
  using P = MeasureOptions;
  OptionTable<P> table = {
      CustomOption<P>(
          "triple", OptionKind::kStrings,
          [](const P& o) -> std::optional<OptionValue> {
            if (o.base.empty() && o.middle.empty() && o.tip.empty()) return std::nullopt;
            return OptionValue(std::vector<std::string>{o.base, o.middle, o.tip});
          },
          [](P& o, const std::optional<OptionValue>& v) {
            const auto names = v ? std::get<std::vector<std::string>>(*v)
                                 : std::vector<std::string>(3);
            o.base = names[0];
            o.middle = names[1];
            o.tip = names[2];
          },
          /*optional=*/true)
          .Count(3)
          .Doc("[base, middle, tip]: the markers of the paper's measurements"),
      CustomOption<P>(
          "chain", OptionKind::kStrings,
          [](const P& o) -> std::optional<OptionValue> {
            if (o.chain.empty()) return std::nullopt;
            return OptionValue(o.chain);
          },
          [](P& o, const std::optional<OptionValue>& v) {
            o.chain = v ? std::get<std::vector<std::string>>(*v) : std::vector<std::string>();
          },
          /*optional=*/true)
          .Doc("every marker base to tip (at least 3): circle fit through all of them"),
      CustomOption<P>(
          "tip_reference", OptionKind::kDoubles,
          [](const P& o) -> std::optional<OptionValue> {
            if (!o.tip_reference_px) return std::nullopt;
            return OptionValue(std::vector<double>{o.tip_reference_px->x, o.tip_reference_px->y});
          },
          [](P& o, const std::optional<OptionValue>& v) {
            if (!v) {
              o.tip_reference_px.reset();
              return;
            }
            const auto& p = std::get<std::vector<double>>(*v);
            o.tip_reference_px = cv::Point2d(p[0], p[1]);
          },
          /*optional=*/true)
          .Count(2)
          .Range(-1e6, 1e6)
          .Unit("px")
          .Doc("[x, y] the bending distance is measured from (default: the tip's first position)"),
  };
  AppendOptions(&table, "", &P::metric, MetricModelOptions());
  return table;
}

}  // namespace

const OptionTable<MetricModel>& MetricModelOptions() {
  static const OptionTable<MetricModel> table = MakeMetric();
  return table;
}

const OptionTable<MeasureOptions>& MeasureOptionsTable() {
  static const OptionTable<MeasureOptions> table = MakeMeasure();
  return table;
}

}  // namespace softsight
