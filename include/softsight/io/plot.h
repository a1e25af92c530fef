// Plots of a softsight CSV against time, as in the paper's Figure 4: stacked panels for the angle,
// the bending distance (tip displacement) and the arc length, plus the controller's columns when
// the CSV has them (target vs measured angle, pressure, valve duty).
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
  std::string title;          // Shown on top; empty: the CSV's file name.
  // Returns true when every field is usable; otherwise false with `error` naming the field.
  bool Check(std::string* error) const;
};

struct PlotSeries {
  std::string label;  // Legend text ("measured", "target", column name otherwise).
  size_t column = 0;  // Index into CsvTable::values.
  cv::Scalar bgr;     // Line colour.
};

struct PlotPanel {
  std::string y_label;  // With unit: "angle [deg]", "bending distance [mm]".
  std::vector<PlotSeries> series;
  cv::Rect plot_rect;           // The data area in figure pixels.
  double x_min = 0, x_max = 1;  // Time range of the x axis, seconds.
  double y_min = 0, y_max = 1;  // Value range of the y axis.
  std::vector<double> x_ticks, y_ticks;
  bool has_data = false;  // False: every value of every series is absent.

  // Figure pixel of data point (time_s, value). Row 0 is the top of the figure.
  cv::Point2d to_pixel(double time_s, double value) const;
};

struct PlotLayout {
  cv::Size size;  // Whole figure.
  std::string title;
  size_t time_column = 0;
  std::vector<PlotPanel> panels;  // Top to bottom.
};

// Chooses the panels the table supports and lays them out. Throws InputError when the table has
// no time_s column, no rows, or none of the plotted columns.
PlotLayout ComputePlotLayout(const CsvTable& table, const PlotOptions& options);

// Draws the layout (8-bit BGR image of layout.size).
cv::Mat RenderPlotImage(const CsvTable& table, const PlotLayout& layout);
// The same figure as an SVG document. Each unbroken run of a series is one <polyline>; a run of a
// single point is a <circle>.
std::string RenderPlotSvg(const CsvTable& table, const PlotLayout& layout);

// Reads `csv_file` and writes the figure to `out_file`: SVG for ".svg", else any image format
// OpenCV writes (".png", ".jpg"). Throws InputError for bad input or an unwritable output.
void WritePlot(const std::string& csv_file, const std::string& out_file,
               const PlotOptions& options = {});

// Round tick positions (1, 2 or 5 times a power of ten) covering [lo, hi], at most about
// `max_ticks` of them. Shared with the live window's strip chart.
std::vector<double> NiceTicks(double lo, double hi, int max_ticks);
// A tick label with as many decimals as the tick spacing needs ("0.25", "120", "-5").
std::string FormatTick(double value, double step);

}  // namespace softsight
