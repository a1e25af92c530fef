#include "softsight/core/format.h"
#include "softsight/io/plot.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <tuple>

#include "softsight/core/error.h"

namespace softsight {
namespace {

// ---- Layout constants (figure pixels)
// ------------------------------------------------------------
constexpr int kLeftMargin = 78;  // Room for y tick labels.
constexpr int kRightMargin = 24;
constexpr int kTitleHeight = 38;
constexpr int kPanelLabelHeight = 26;  // Strip above each plot area holding its y label + legend.
constexpr int kTickLabelHeight = 24;   // Strip below each plot area holding the x tick labels.
constexpr int kBottomMargin = 30;      // The x axis title under the last panel.
constexpr int kYTicks = 5;
constexpr int kXTicks = 10;

const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrid(225, 225, 225);
const cv::Scalar kWhite(255, 255, 255);
// Series colours (BGR), chosen to stay distinct in print and for common colour blindness.
const cv::Scalar kMeasured(178, 114, 0);  // blue
const cv::Scalar kTarget(0, 94, 213);     // vermilion
const cv::Scalar kBending(115, 158, 0);   // bluish green
const cv::Scalar kArc(167, 121, 204);     // reddish purple
const cv::Scalar kPalette[] = {{0, 159, 230}, {233, 180, 86}, {66, 228, 240}, {0, 0, 0}};

bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

// The unit a column name carries in its suffix, as a person writes it.
std::string UnitOf(const std::string& column) {
  const size_t underscore = column.rfind('_');
  if (underscore == std::string::npos) return "";
  const std::string suffix = column.substr(underscore + 1);
  static const std::pair<const char*, const char*> kUnits[] = {
      {"deg", "deg"}, {"px", "px"},   {"mm", "mm"}, {"s", "s"},
      {"ms", "ms"},   {"kpa", "kPa"}, {"pa", "Pa"}, {"mbar", "mbar"},
      {"bar", "bar"}, {"psi", "psi"}, {"pct", "%"}, {"percent", "%"}};
  for (const auto& [name, shown] : kUnits) {
    if (suffix == name) return shown;
  }
  return "";
}

std::string WithUnit(const std::string& label, const std::string& unit) {
  return unit.empty() ? label : label + " [" + unit + "]";
}

// 1, 2 or 5 times a power of ten, the smallest not below span / max_ticks.
double NiceStep(double span, int max_ticks) {
  const double raw = span / std::max(1, max_ticks);
  if (!(raw > 0) || !std::isfinite(raw)) return 1.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * magnitude >= raw * (1 - 1e-9)) return m * magnitude;
  }
  return 10 * magnitude;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  bool empty() const { return lo > hi; }
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
};

// Rows where both time and value are present, split into unbroken runs.
std::vector<std::vector<cv::Point2d>> Runs(const PlotData& data, const PlotLayout& layout,
                                           const PlotPanel& panel, const PlotSeries& series) {
  std::vector<std::vector<cv::Point2d>> runs;
  std::vector<cv::Point2d> run;
  const CsvTable& table = data.table(series.table);
  const auto& t = table.values[layout.time_columns[series.table]];
  for (size_t row = 0; row < table.row_count(); ++row) {
    const std::optional<double> v = PlotSeriesValue(table, series, row);
    if (t[row] && v) {
      run.push_back(panel.to_pixel(*t[row], *v));
    } else if (!run.empty()) {
      runs.push_back(std::move(run));
      run.clear();
    }
  }
  if (!run.empty()) runs.push_back(std::move(run));
  return runs;
}

PlotSeries Series(std::string label, size_t column, const cv::Scalar& bgr, size_t table) {
  PlotSeries series;
  series.label = std::move(label);
  series.column = column;
  series.bgr = bgr;
  series.table = table;
  return series;
}

PlotPanel MakePanel(std::string y_label) {
  PlotPanel panel;
  panel.y_label = std::move(y_label);
  return panel;
}

const char* const kPanelKinds[] = {"angle", "plane", "bending", "arc", "radius", "xy", "control"};
const char* const kDefaultPanels[] = {"angle", "plane", "bending", "arc", "control"};
// The live overlay's "straight" (gui/overlay.h, ReadsStraight): a radius of this many arc lengths
// or more is mostly centroid noise and grows without bound as the actuator straightens, so the
// radius panel leaves it out (a gap) rather than let it set the axis.
constexpr double kStraightRadiusPerArcLength = 25.0;
// One colour per run when several are overlaid; the truth is black.
const cv::Scalar kRunColours[] = {kMeasured, kTarget, kBending, kArc, {0, 159, 230}, {233, 180, 86}};

// How the series of table `t` are labelled and coloured: a single run keeps the names of the
// quantities ("measured", "target"); overlaid runs are told apart by their file names.
struct Legend {
  const PlotData& data;
  std::vector<std::string> names;  // Per table.
  bool single() const { return data.table_count() == 1; }
  bool is_truth(size_t t) const { return t >= data.runs.size(); }
  std::string label(size_t t, const std::string& quantity) const {
    if (single()) return quantity;
    if (is_truth(t)) return quantity.empty() ? "truth" : "truth " + quantity;
    return quantity.empty() ? names[t] : names[t] + " " + quantity;
  }
  cv::Scalar colour(size_t t, const cv::Scalar& single_colour) const {
    if (single()) return single_colour;
    if (is_truth(t)) return kBlack;
    return kRunColours[t % std::size(kRunColours)];
  }
};

std::string Stem(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const size_t dot = name.find_last_of('.');
  if (dot != std::string::npos && dot > 0) name.erase(dot);
  return name;
}

// A panel of one quantity: the column `stem`_mm when the first run has it (a metric model was
// configured), else `stem`_px, from every table that has it.
void AddLengthPanel(const PlotData& data, const Legend& legend, const std::string& stem,
                    const std::string& label, const cv::Scalar& colour,
                    std::vector<PlotPanel>* panels) {
  const bool mm = data.runs.front().find(stem + "_mm").has_value();
  const std::string column = stem + (mm ? "_mm" : "_px");
  PlotPanel panel = MakePanel(WithUnit(label, mm ? "mm" : "px"));
  panel.unit = mm ? "mm" : "px";
  for (size_t t = 0; t < data.table_count(); ++t) {
    const auto c = data.table(t).find(column);
    if (!c) continue;
    PlotSeries series = Series(legend.label(t, legend.single() ? label : ""), *c,
                               legend.colour(t, colour), t);
    if (stem == "radius") {
      series.cap_column = data.table(t).find(std::string("arc_length") + (mm ? "_mm" : "_px"));
      series.cap_factor = kStraightRadiusPerArcLength;
    }
    panel.series.push_back(series);
  }
  if (!panel.series.empty()) panels->push_back(panel);
}

// The angle: measured (a track-stereo CSV's 3D angle beside each camera's), target and model.
void AddAnglePanel(const PlotData& data, const Legend& legend, std::vector<PlotPanel>* panels) {
  PlotPanel panel = MakePanel("angle [deg]");
  panel.unit = "deg";
  for (size_t t = 0; t < data.table_count(); ++t) {
    const CsvTable& table = data.table(t);
    const auto angle = table.find("angle_deg");
    const auto target = table.find("target_deg");
    const auto model = table.find("model_angle_deg");  // `softsight identify --model-csv`.
    if (target) panel.series.push_back(Series(legend.label(t, "target"), *target, kTarget, t));
    if (model) panel.series.push_back(Series(legend.label(t, "model"), *model, kTarget, t));
    // A track-stereo CSV: the 3D angle beside what each camera alone measures.
    const auto left = table.find("angle_left_deg"), right = table.find("angle_right_deg");
    if (angle) {
      const std::string quantity =
          legend.single() ? (target || model ? "measured" : left ? "3D" : "angle") : "";
      panel.series.push_back(Series(legend.label(t, quantity), *angle, legend.colour(t, kMeasured), t));
    }
    if (left && legend.single()) {
      panel.series.push_back(Series("left camera", *left, kPalette[0], t));
      if (right) panel.series.push_back(Series("right camera", *right, kPalette[1], t));
    }
  }
  if (!panel.series.empty()) panels->push_back(panel);
}

// track-stereo: the bending plane's angle out of the reference plane.
void AddPlanePanel(const PlotData& data, const Legend& legend, std::vector<PlotPanel>* panels) {
  PlotPanel panel = MakePanel("out-of-plane angle [deg]");
  panel.unit = "deg";
  for (size_t t = 0; t < data.table_count(); ++t) {
    const auto column = data.table(t).find("out_of_plane_deg");
    if (column) {
      panel.series.push_back(Series(legend.label(t, legend.single() ? "out of plane" : ""),
                                    *column, legend.colour(t, kArc), t));
    }
  }
  if (!panel.series.empty()) panels->push_back(panel);
}

// One panel per coordinate of every marker of the first run whose columns <m><axis> all exist
// (`axes[0]` names them), in its column order.
void AddCoordinatePanels(const PlotData& data, const Legend& legend,
                         std::initializer_list<const char*> axes, const char* unit,
                         std::vector<PlotPanel>* panels) {
  const CsvTable& first = data.runs.front();
  const std::string first_axis = *axes.begin();
  for (const std::string& column : first.columns) {
    if (column.size() < 3 || column.compare(column.size() - 2, 2, first_axis) != 0) continue;
    const std::string name = column.substr(0, column.size() - 2);
    if (!std::all_of(axes.begin() + 1, axes.end(),
                     [&](const char* axis) { return first.find(name + axis).has_value(); })) {
      continue;
    }
    for (const char* axis : axes) {
      PlotPanel panel = MakePanel(name + " " + (axis + 1) + " [" + unit + "]");
      panel.unit = unit;
      for (size_t t = 0; t < data.table_count(); ++t) {
        const auto c = data.table(t).find(name + axis);
        if (c) panel.series.push_back(Series(legend.label(t, legend.single() ? name + " " + (axis + 1) : ""),
                                       *c, legend.colour(t, kMeasured), t));
      }
      panels->push_back(panel);
    }
  }
}

// Controller columns: every pressure (a name with "pressure" or a pressure unit, such as
// `softsight control`'s setpoint_kpa and board_pressure_kpa) in one panel, every duty*
// column in another.
void AddControllerPanels(const PlotData& data, const Legend& legend,
                         std::vector<PlotPanel>* panels) {
  const auto is_pressure = [](const std::string& column) {
    const std::string unit = UnitOf(column);
    return column.find("pressure") != std::string::npos || unit == "kPa" || unit == "Pa" ||
           unit == "mbar" || unit == "bar" || unit == "psi";
  };
  const auto is_duty = [](const std::string& column) { return StartsWith(column, "duty"); };
  const std::pair<const char*, bool (*)(const std::string&)> kControllerPanels[] = {
      {"pressure", +is_pressure}, {"duty", +is_duty}};
  for (const auto& [label, belongs] : kControllerPanels) {
    PlotPanel panel;
    std::string unit;
    for (size_t t = 0; t < data.runs.size(); ++t) {
      const CsvTable& table = data.runs[t];
      for (size_t c = 0; c < table.columns.size(); ++c) {
        if (!belongs(table.columns[c])) continue;
        if (panel.series.empty()) unit = UnitOf(table.columns[c]);
        const cv::Scalar colour = kPalette[panel.series.size() % std::size(kPalette)];
        panel.series.push_back(Series(legend.label(t, table.columns[c]), c, colour, t));
      }
    }
    if (!panel.series.empty()) {
      panel.y_label = WithUnit(label, unit);
      panel.unit = unit;
      panels->push_back(panel);
    }
  }
}

// The panels of `kind`, appended to `panels`.
void AddPanels(const std::string& kind, const PlotData& data, const Legend& legend,
               std::vector<PlotPanel>* panels) {
  if (kind == "angle") {
    AddAnglePanel(data, legend, panels);
  } else if (kind == "plane") {
    AddPlanePanel(data, legend, panels);
  } else if (kind == "bending") {
    AddLengthPanel(data, legend, "tip_disp", "bending distance", kBending, panels);
  } else if (kind == "arc") {
    AddLengthPanel(data, legend, "arc_length", "arc length", kArc, panels);
  } else if (kind == "radius") {
    // Empty fields (a straight actuator has no radius) are gaps, as everywhere.
    AddLengthPanel(data, legend, "radius", "radius of curvature", kMeasured, panels);
  } else if (kind == "xy") {
    // The markers of the first run, in its column order: one panel for x, one for y each; a
    // track-stereo CSV's markers in 3D (<m>_X, _Y, _Z, mm): one panel per coordinate.
    AddCoordinatePanels(data, legend, {"_X", "_Y", "_Z"}, "mm", panels);
    AddCoordinatePanels(data, legend, {"_x", "_y"}, "px", panels);
  } else if (kind == "control") {
    AddControllerPanels(data, legend, panels);
  }
}

// The panels asked for (or the default ones the tables support), top to bottom.
std::vector<PlotPanel> ChoosePanels(const PlotData& data, const PlotOptions& options) {
  Legend legend{data, {}};
  for (size_t t = 0; t < data.table_count(); ++t) legend.names.push_back(Stem(data.table(t).source));
  for (size_t t = 0; t < data.runs.size(); ++t) {
    for (size_t u = 0; u < t; ++u) {
      if (legend.names[t] == legend.names[u]) legend.names[t] = data.runs[t].source;  // Same stem.
    }
  }
  std::vector<PlotPanel> panels;
  if (options.panels.empty()) {
    for (const char* kind : kDefaultPanels) AddPanels(kind, data, legend, &panels);
    return panels;
  }
  for (const std::string& kind : options.panels) {
    if (std::find(std::begin(kPanelKinds), std::end(kPanelKinds), kind) == std::end(kPanelKinds)) {
      throw InputError("--panels: unknown panel '" + kind + "' (choose " + PlotPanelNames() + ")");
    }
    const size_t before = panels.size();
    AddPanels(kind, data, legend, &panels);
    if (panels.size() == before) {
      throw InputError("--panels " + kind + ": " + data.runs.front().source +
                       " has no column for it (" +
                       (kind == "xy" ? std::string("<name>_x and <name>_y")
                        : kind == "radius" ? std::string("radius_px")
                        : kind == "angle" ? std::string("angle_deg")
                        : kind == "plane" ? std::string("out_of_plane_deg, from track-stereo")
                        : kind == "bending" ? std::string("tip_disp_px")
                        : kind == "arc" ? std::string("arc_length_px")
                                        : std::string("pressure or duty columns")) +
                       ")");
    }
  }
  return panels;
}

std::string SvgEscape(const std::string& text) {
  std::string out;
  for (char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

std::string SvgColour(const cv::Scalar& bgr) {
  char buffer[8];
  std::snprintf(buffer, sizeof(buffer), "#%02x%02x%02x", static_cast<int>(bgr[2]),
                static_cast<int>(bgr[1]), static_cast<int>(bgr[0]));
  return buffer;
}


// ---- Raster text helpers -----------------------------------------------------------------------
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.45;

void Text(cv::Mat& image, const std::string& text, cv::Point anchor, double h_align,
          double scale = kFontScale, int thickness = 1) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, thickness, &baseline);
  const cv::Point origin(anchor.x - static_cast<int>(h_align * size.width),
                         anchor.y + size.height / 2);
  cv::putText(image, text, origin, kFont, scale, kBlack, thickness, cv::LINE_AA);
}

}  // namespace

bool PlotOptions::Check(std::string* error) const {
  if (width_px < 300 || width_px > 10000) {
    *error = "width_px must be in 300..10000, got " + std::to_string(width_px);
    return false;
  }
  if (panel_height_px < 100 || panel_height_px > 5000) {
    *error = "panel_height_px must be in 100..5000, got " + std::to_string(panel_height_px);
    return false;
  }
  return true;
}

cv::Point2d PlotPanel::to_pixel(double time_s, double value) const {
  const double fx = (time_s - x_min) / (x_max - x_min);
  const double fy = (value - y_min) / (y_max - y_min);
  return {plot_rect.x + fx * (plot_rect.width - 1),
          plot_rect.y + (1.0 - fy) * (plot_rect.height - 1)};
}

std::vector<double> NiceTicks(double lo, double hi, int max_ticks) {
  std::vector<double> ticks;
  if (!(hi > lo)) return ticks;
  const double step = NiceStep(hi - lo, max_ticks);
  const double eps = step * 1e-9;
  const double first = std::ceil((lo - eps) / step);
  // Counted, not stepped until past `hi`: far from zero (a time of 1e15 s) adding one step may
  // not change a double, and the loop would never end. NiceStep gives at most max_ticks + 1
  // ticks; the bound holds whatever the values.
  const int most = 2 * std::max(1, max_ticks) + 2;
  for (int i = 0; i < most; ++i) {
    double tick = (first + i) * step;
    if (tick > hi + eps) break;
    if (!ticks.empty() && !(tick > ticks.back())) break;  // No resolution left at this magnitude.
    if (std::abs(tick) < eps) tick = 0.0;  // No "-0".
    ticks.push_back(tick);
  }
  return ticks;
}

std::string FormatTick(double value, double step) {
  const int decimals =
      step > 0 ? std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9))) : 0;
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  std::string text = buffer;
  if (text.find_first_not_of("-0.") == std::string::npos && text[0] == '-') text.erase(0, 1);
  return text;
}

std::optional<double> PlotSeriesValue(const CsvTable& table, const PlotSeries& series, size_t row) {
  const std::optional<double>& v = table.values[series.column][row];
  if (!v || !series.cap_column) return v;
  const std::optional<double>& cap = table.values[*series.cap_column][row];
  if (cap && *v >= series.cap_factor * *cap) return std::nullopt;
  return v;
}

const char* PlotPanelNames() { return "angle, plane, bending, arc, radius, xy, control"; }

PlotLayout ComputePlotLayout(const CsvTable& table, const PlotOptions& options) {
  return ComputePlotLayout(PlotData{{table}, std::nullopt}, options);
}

PlotLayout ComputePlotLayout(const PlotData& data, const PlotOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw InputError("plot options: " + error);
  if (data.runs.empty()) throw InputError("plot: no CSV to plot");
  PlotLayout layout;
  Range time;
  for (size_t t = 0; t < data.table_count(); ++t) {
    const CsvTable& table = data.table(t);
    const auto time_column = table.find("time_s");
    if (!time_column) throw InputError(table.source + ": no time_s column to plot against");
    if (table.row_count() == 0) throw InputError(table.source + ": no rows to plot");
    layout.time_columns.push_back(*time_column);
    bool any = false;
    for (const auto& value : table.values[*time_column]) {
      if (value) {
        time.add(*value);
        any = true;
      }
    }
    if (!any) throw InputError(table.source + ": every time_s value is empty");
  }
  layout.time_column = layout.time_columns.front();
  layout.panels = ChoosePanels(data, options);
  if (layout.panels.empty()) {
    throw InputError(data.runs.front().source +
                     ": nothing to plot (no angle_deg, tip_disp_*, arc_length_*, target_deg, "
                     "pressure* or duty* column)");
  }
  if (options.title.empty()) {
    for (const CsvTable& run : data.runs) {
      const size_t slash = run.source.find_last_of('/');
      layout.title += (layout.title.empty() ? "" : ", ") +
                      (slash == std::string::npos ? run.source : run.source.substr(slash + 1));
    }
    if (data.truth) layout.title += " vs truth";
  } else {
    layout.title = options.title;
  }
  if (time.hi - time.lo < 1e-9) {  // One instant: centre it in a one-second axis.
    time.lo -= 0.5;
    time.hi += 0.5;
  }

  const int n = static_cast<int>(layout.panels.size());
  layout.size =
      cv::Size(options.width_px, kTitleHeight + n * options.panel_height_px + kBottomMargin);
  for (int i = 0; i < n; ++i) {
    PlotPanel& panel = layout.panels[i];
    const int top = kTitleHeight + i * options.panel_height_px;
    panel.plot_rect = cv::Rect(kLeftMargin, top + kPanelLabelHeight,
                               options.width_px - kLeftMargin - kRightMargin,
                               options.panel_height_px - kPanelLabelHeight - kTickLabelHeight);
    panel.x_min = time.lo;
    panel.x_max = time.hi;
    panel.x_ticks = NiceTicks(time.lo, time.hi, kXTicks);

    Range values;
    for (const PlotSeries& series : panel.series) {
      const CsvTable& table = data.table(series.table);
      const auto& t = table.values[layout.time_columns[series.table]];
      for (size_t row = 0; row < table.row_count(); ++row) {
        const std::optional<double> v = PlotSeriesValue(table, series, row);
        if (v && t[row]) values.add(*v);
      }
    }
    panel.has_data = !values.empty();
    // The smallest span the axis may have: below it, the curve would show the tracker's noise
    // as if it were motion (a steady arc length jittering by 0.1 px over the whole panel).
    const double min_span = panel.unit == "px"    ? options.min_span_px
                            : panel.unit == "deg" ? options.min_span_deg
                            : panel.unit == "mm"  ? options.min_span_mm
                                                  : 0.0;
    if (!panel.has_data) {
      values.lo = 0.0;
      values.hi = 1.0;
    } else if (values.hi - values.lo < min_span) {
      const double centre = 0.5 * (values.lo + values.hi);
      values.lo = centre - 0.5 * min_span;
      values.hi = centre + 0.5 * min_span;
    } else if (values.hi - values.lo < 1e-9) {
      const double pad = std::max(1.0, std::abs(values.lo) * 0.05);
      values.lo -= pad;
      values.hi += pad;
    }
    // Round axis ends at the enclosing ticks, with a little headroom so lines clear the frame.
    const double pad = 0.04 * (values.hi - values.lo);
    const double step = NiceStep(values.hi - values.lo + 2 * pad, kYTicks);
    panel.y_min = std::floor((values.lo - pad) / step) * step;
    panel.y_max = std::ceil((values.hi + pad) / step) * step;
    panel.y_ticks = NiceTicks(panel.y_min, panel.y_max, kYTicks);
  }
  return layout;
}

cv::Mat RenderPlotImage(const CsvTable& table, const PlotLayout& layout) {
  return RenderPlotImage(PlotData{{table}, std::nullopt}, layout);
}

std::string RenderPlotSvg(const CsvTable& table, const PlotLayout& layout) {
  return RenderPlotSvg(PlotData{{table}, std::nullopt}, layout);
}

cv::Mat RenderPlotImage(const PlotData& data, const PlotLayout& layout) {
  cv::Mat image(layout.size, CV_8UC3, kWhite);
  Text(image, layout.title, {layout.size.width / 2, kTitleHeight / 2}, 0.5, 0.6, 1);
  for (size_t p = 0; p < layout.panels.size(); ++p) {
    const PlotPanel& panel = layout.panels[p];
    const cv::Rect& r = panel.plot_rect;
    const int bottom = r.y + r.height - 1;
    const int right = r.x + r.width - 1;
    const double x_step = panel.x_ticks.size() > 1 ? panel.x_ticks[1] - panel.x_ticks[0] : 1.0;
    const double y_step = panel.y_ticks.size() > 1 ? panel.y_ticks[1] - panel.y_ticks[0] : 1.0;
    for (double t : panel.x_ticks) {
      const int x = cvRound(panel.to_pixel(t, panel.y_min).x);
      cv::line(image, {x, r.y}, {x, bottom}, kGrid, 1);
      cv::line(image, {x, bottom}, {x, bottom + 4}, kBlack, 1);
      Text(image, FormatTick(t, x_step), {x, bottom + 13}, 0.5);
    }
    for (double v : panel.y_ticks) {
      const int y = cvRound(panel.to_pixel(panel.x_min, v).y);
      cv::line(image, {r.x, y}, {right, y}, kGrid, 1);
      cv::line(image, {r.x - 4, y}, {r.x, y}, kBlack, 1);
      Text(image, FormatTick(v, y_step), {r.x - 7, y}, 1.0);
    }
    cv::rectangle(image, r, kBlack, 1);
    Text(image, panel.y_label, {r.x, r.y - kPanelLabelHeight / 2}, 0.0, 0.5, 1);
    if (!panel.has_data) {
      Text(image, "(no values)", {r.x + r.width / 2, r.y + r.height / 2}, 0.5);
    }

    // Legend, right-aligned in the label strip: a line sample and the series label.
    int legend_right = right;
    for (auto it = panel.series.rbegin(); it != panel.series.rend(); ++it) {
      int baseline = 0;
      const int width = cv::getTextSize(it->label, kFont, kFontScale, 1, &baseline).width;
      const int y = r.y - kPanelLabelHeight / 2;
      Text(image, it->label, {legend_right, y}, 1.0);
      cv::line(image, {legend_right - width - 30, y}, {legend_right - width - 6, y}, it->bgr, 2,
               cv::LINE_AA);
      legend_right -= width + 46;
    }

    // Curves, sub-pixel (shift) and anti-aliased, clipped to the plot area.
    cv::Mat area = image(r);
    constexpr int kShift = 4;
    for (const PlotSeries& series : panel.series) {
      for (const auto& run : Runs(data, layout, panel, series)) {
        std::vector<cv::Point> points;
        points.reserve(run.size());
        for (const cv::Point2d& p : run) {
          points.emplace_back(cvRound((p.x - r.x) * (1 << kShift)),
                              cvRound((p.y - r.y) * (1 << kShift)));
        }
        if (points.size() == 1) {
          cv::circle(area, points[0], 3 << kShift, series.bgr, cv::FILLED, cv::LINE_AA, kShift);
        } else {
          cv::polylines(area, points, false, series.bgr, 2, cv::LINE_AA, kShift);
        }
      }
    }
  }
  if (!layout.panels.empty()) {
    const cv::Rect& r = layout.panels.back().plot_rect;
    Text(image, "time [s]", {r.x + r.width / 2, layout.size.height - kBottomMargin / 2}, 0.5, 0.5);
  }
  return image;
}

std::string RenderPlotSvg(const PlotData& data, const PlotLayout& layout) {
  std::ostringstream svg;
  const int w = layout.size.width, h = layout.size.height;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h
      << "\" viewBox=\"0 0 " << w << ' ' << h << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<rect x=\"0\" y=\"0\" width=\"" << w << "\" height=\"" << h << "\" fill=\"white\"/>\n"
      << "<text x=\"" << w / 2 << "\" y=\"" << kTitleHeight / 2 + 5
      << "\" text-anchor=\"middle\" font-size=\"15\">" << SvgEscape(layout.title) << "</text>\n";
  for (const PlotPanel& panel : layout.panels) {
    const cv::Rect& r = panel.plot_rect;
    const double bottom = r.y + r.height - 1, right = r.x + r.width - 1;
    const double x_step = panel.x_ticks.size() > 1 ? panel.x_ticks[1] - panel.x_ticks[0] : 1.0;
    const double y_step = panel.y_ticks.size() > 1 ? panel.y_ticks[1] - panel.y_ticks[0] : 1.0;
    svg << "<g>\n";
    for (double t : panel.x_ticks) {
      const double x = panel.to_pixel(t, panel.y_min).x;
      svg << "<line x1=\"" << FixedNumber(x, 2) << "\" y1=\"" << r.y << "\" x2=\"" << FixedNumber(x, 2) << "\" y2=\""
          << FixedNumber(bottom, 2) << "\" stroke=\"#e1e1e1\"/>\n"
          << "<text x=\"" << FixedNumber(x, 2) << "\" y=\"" << FixedNumber(bottom + 17, 2) << "\" text-anchor=\"middle\">"
          << FormatTick(t, x_step) << "</text>\n";
    }
    for (double v : panel.y_ticks) {
      const double y = panel.to_pixel(panel.x_min, v).y;
      svg << "<line x1=\"" << r.x << "\" y1=\"" << FixedNumber(y, 2) << "\" x2=\"" << FixedNumber(right, 2) << "\" y2=\""
          << FixedNumber(y, 2) << "\" stroke=\"#e1e1e1\"/>\n"
          << "<text x=\"" << r.x - 7 << "\" y=\"" << FixedNumber(y + 4, 2) << "\" text-anchor=\"end\">"
          << FormatTick(v, y_step) << "</text>\n";
    }
    svg << "<rect x=\"" << r.x << "\" y=\"" << r.y << "\" width=\"" << r.width - 1 << "\" height=\""
        << r.height - 1 << "\" fill=\"none\" stroke=\"black\"/>\n"
        << "<text x=\"" << r.x << "\" y=\"" << r.y - 8 << "\" font-size=\"13\">"
        << SvgEscape(panel.y_label) << "</text>\n";
    if (!panel.has_data) {
      svg << "<text x=\"" << r.x + r.width / 2 << "\" y=\"" << r.y + r.height / 2
          << "\" text-anchor=\"middle\">(no values)</text>\n";
    }
    int legend_right = r.x + r.width - 1;
    for (auto it = panel.series.rbegin(); it != panel.series.rend(); ++it) {
      // Approximate width of sans-serif at 12 px: 6.5 px per character.
      const int width = static_cast<int>(6.5 * it->label.size());
      svg << "<text x=\"" << legend_right << "\" y=\"" << r.y - 8 << "\" text-anchor=\"end\">"
          << SvgEscape(it->label) << "</text>\n"
          << "<line x1=\"" << legend_right - width - 30 << "\" y1=\"" << r.y - 12 << "\" x2=\""
          << legend_right - width - 6 << "\" y2=\"" << r.y - 12 << "\" stroke=\""
          << SvgColour(it->bgr) << "\" stroke-width=\"2\"/>\n";
      legend_right -= width + 46;
    }
    for (const PlotSeries& series : panel.series) {
      const std::string colour = SvgColour(series.bgr);
      for (const auto& run : Runs(data, layout, panel, series)) {
        if (run.size() == 1) {
          svg << "<circle cx=\"" << FixedNumber(run[0].x, 2) << "\" cy=\"" << FixedNumber(run[0].y, 2)
              << "\" r=\"3\" fill=\"" << colour << "\"/>\n";
          continue;
        }
        svg << "<polyline fill=\"none\" stroke=\"" << colour
            << "\" stroke-width=\"2\" stroke-linejoin=\"round\" points=\"";
        for (size_t i = 0; i < run.size(); ++i) {
          svg << (i ? " " : "") << FixedNumber(run[i].x, 2) << ',' << FixedNumber(run[i].y, 2);
        }
        svg << "\"/>\n";
      }
    }
    svg << "</g>\n";
  }
  if (!layout.panels.empty()) {
    const cv::Rect& r = layout.panels.back().plot_rect;
    svg << "<text x=\"" << r.x + r.width / 2 << "\" y=\"" << h - kBottomMargin / 2 + 5
        << "\" text-anchor=\"middle\" font-size=\"13\">time [s]</text>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

void WritePlot(const std::string& csv_file, const std::string& out_file,
               const PlotOptions& options) {
  WritePlot(std::vector<std::string>{csv_file}, std::nullopt, out_file, options);
}

void WritePlot(const std::vector<std::string>& csv_files,
               const std::optional<std::string>& truth_file, const std::string& out_file,
               const PlotOptions& options) {
  PlotData data;
  for (const std::string& file : csv_files) data.runs.push_back(ReadCsvTable(file));
  if (truth_file) data.truth = ReadCsvTable(*truth_file);
  const PlotLayout layout = ComputePlotLayout(data, options);
  std::string extension;
  const size_t dot = out_file.find_last_of('.');
  if (dot != std::string::npos && out_file.find('/', dot) == std::string::npos) {
    extension = out_file.substr(dot + 1);
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  }
  if (extension == "svg") {
    std::ofstream out(out_file);
    out << RenderPlotSvg(data, layout);
    out.close();
    if (!out) throw InputError(out_file + ": cannot write SVG (" + std::strerror(errno) + ")");
    return;
  }
  if (extension.empty() || !cv::haveImageWriter(out_file)) {
    throw InputError(out_file + ": unknown image type '." + extension +
                     "' (use .png, .jpg or .svg)");
  }
  bool written = false;
  try {
    written = cv::imwrite(out_file, RenderPlotImage(data, layout));
  } catch (const cv::Exception&) {
    written = false;
  }
  if (!written) throw InputError(out_file + ": cannot write image");
}

}  // namespace softsight
