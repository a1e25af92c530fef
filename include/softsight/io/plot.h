// Plots of softsight CSVs against time, as in the paper's Figure 4: stacked panels for the angle,
// the bending distance (tip displacement) and the arc length, plus the out-of-plane angle of a
// track-stereo CSV and the controller's columns when the CSV has them (target vs measured angle, pressure, valve duty); on request the radius of
// curvature and each marker's x and y. Several runs are overlaid (one colour each) with a truth
// CSV (synth's, the same column names) in black. A y axis never spans less than the minimum span
// of its unit, so a steady value's sub-pixel noise is not blown up to the panel's height.
//
// One layout (panel rectangles, axis ranges, ticks) is computed once and drawn by two back ends:
// a raster image with OpenCV drawing (PNG, JPEG, ...) and hand-written SVG text. Empty CSV fields
// are gaps in the curves, never zeros.
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "softsight/io/csv_reader.h"

namespace softsight {

struct PlotOptions {
  int width_px = 1000;        // Figure width. Narrower than ~400 leaves no room for tick labels.
  int panel_height_px = 240;  // Height of each stacked panel, including its label strip.
  std::string title{};        // Shown on top; empty: the CSVs' file names.
  // Panels, top to bottom: "angle" (a track-stereo CSV's 3D angle with each camera's own),
  // "plane" (track-stereo's out-of-plane angle), "bending" (tip displacement), "arc" (arc
  // length), "radius" (radius of curvature), "xy" (each marker's x and y, or X, Y and Z in 3D,
  // one panel each), "control" (pressures, duty). Empty (default): angle, plane, bending, arc
  // and control, each when the CSV has its columns; a panel asked for by name whose columns no
  // CSV has is an error.
  std::vector<std::string> panels{};
  // Smallest span of a y axis, per unit: values that vary less are shown in an axis this tall,
  // centred on them. Defaults: 2 px (20x the colour tracker's ~0.1 px precision), 1 deg,
  // 0.5 mm. 0: the axis hugs the data.
  double min_span_px = 2.0;
  double min_span_deg = 1.0;
  double min_span_mm = 0.5;
  // Returns true when every field is usable; otherwise false with `error` naming the field.
  bool Check(std::string* error) const;
};

// What is plotted: one or more runs and, optionally, a truth to compare them with.
struct PlotData {
  std::vector<CsvTable> runs{};     // CSVs of `track`, `live`, `control` (at least one).
  std::optional<CsvTable> truth{};  // `synth --truth` CSV: drawn in black, labelled "truth".

  size_t table_count() const { return runs.size() + (truth ? 1 : 0); }
  // Runs first, then the truth.
  const CsvTable& table(size_t index) const { return index < runs.size() ? runs[index] : *truth; }
};

struct PlotSeries {
  std::string label{};  // Legend text ("measured", "target", column name otherwise).
  size_t column = 0;    // Index into CsvTable::values.
  cv::Scalar bgr{};     // Line colour.
  size_t table = 0;     // Which table of the PlotData (0 with a single CSV).
  // A value above cap_factor times this column's value in the same row is drawn as a gap (the
  // radius of a nearly straight actuator: see PlotSeriesValue).
  std::optional<size_t> cap_column{};
  double cap_factor = 0.0;
};

// The value `series` plots at `row` of `table`: absent where the field is empty, or above its
// cap (a radius of 25 arc lengths or more reads "straight", as in the live overlay).
std::optional<double> PlotSeriesValue(const CsvTable& table, const PlotSeries& series, size_t row);

struct PlotPanel {
  std::string y_label{};  // With unit: "angle [deg]", "bending distance [mm]".
  std::vector<PlotSeries> series{};
  cv::Rect plot_rect{};         // The data area in figure pixels.
  double x_min = 0, x_max = 1;  // Time range of the x axis, seconds.
  double y_min = 0, y_max = 1;  // Value range of the y axis.
  std::string unit{};           // Of the y axis ("deg", "px", "mm", ...), for its minimum span.
  std::vector<double> x_ticks{}, y_ticks{};
  bool has_data = false;  // False: every value of every series is absent.

  // Figure pixel of data point (time_s, value). Row 0 is the top of the figure.
  cv::Point2d to_pixel(double time_s, double value) const;
};

struct PlotLayout {
  cv::Size size{};  // Whole figure.
  std::string title{};
  size_t time_column = 0;              // Of the first table.
  std::vector<size_t> time_columns{};  // Of each table of the PlotData.
  std::vector<PlotPanel> panels{};     // Top to bottom.
};

// Chooses the panels the tables support and lays them out. Throws InputError (naming the file)
// when a table has no time_s column or no rows, when nothing can be plotted, or for a panel
// name that is unknown or has no columns in any table.
PlotLayout ComputePlotLayout(const PlotData& data, const PlotOptions& options);
PlotLayout ComputePlotLayout(const CsvTable& table, const PlotOptions& options);

// Draws the layout (8-bit BGR image of layout.size).
cv::Mat RenderPlotImage(const PlotData& data, const PlotLayout& layout);
cv::Mat RenderPlotImage(const CsvTable& table, const PlotLayout& layout);
// The same figure as an SVG document. Each unbroken run of a series is one <polyline>; a run of a
// single point is a <circle>.
std::string RenderPlotSvg(const PlotData& data, const PlotLayout& layout);
std::string RenderPlotSvg(const CsvTable& table, const PlotLayout& layout);

// Reads the CSVs (and the truth) and writes the figure to `out_file`: SVG for ".svg", else any
// image format OpenCV writes (".png", ".jpg"). Throws InputError for bad input or an unwritable
// output.
void WritePlot(const std::vector<std::string>& csv_files,
               const std::optional<std::string>& truth_file, const std::string& out_file,
               const PlotOptions& options = {});
void WritePlot(const std::string& csv_file, const std::string& out_file,
               const PlotOptions& options = {});

// The panel names PlotOptions::panels accepts, comma separated, for messages and help.
const char* PlotPanelNames();

// Round tick positions (1, 2 or 5 times a power of ten) covering [lo, hi], at most about
// `max_ticks` of them. Shared with the live window's strip chart.
std::vector<double> NiceTicks(double lo, double hi, int max_ticks);
// A tick label with as many decimals as the tick spacing needs ("0.25", "120", "-5").
std::string FormatTick(double value, double step);

}  // namespace softsight
