#include "softsight/io/plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>

#include "core/test_util.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;

class PlotTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // Writes a tracking CSV with the design document's columns for markers red, blue, green.
  // `angle(t)` etc. return NaN for an empty field.
  std::string WriteCsv(const std::string& name, int rows, double dt,
                       const std::function<double(double)>& angle,
                       const std::function<double(double)>& tip,
                       const std::function<double(double)>& arc, bool metric,
                       const std::string& extra_header = "",
                       const std::function<std::string(double)>& extra = nullptr) {
    const std::string path = Path(name);
    std::ofstream out(path);
    out << "frame,time_s";
    for (const char* m : {"red", "blue", "green"}) {
      out << "," << m << "_x," << m << "_y," << m << "_found," << m << "_score";
    }
    out << ",angle_deg,chord_px,sagitta_px,radius_px,arc_length_px,tip_disp_px";
    if (metric) out << ",chord_mm,sagitta_mm,radius_mm,arc_length_mm,tip_disp_mm";
    out << extra_header << ",proc_ms\n";
    auto field = [](double v) {
      if (std::isnan(v)) return std::string();
      std::ostringstream s;
      s.precision(10);
      s << v;
      return s.str();
    };
    for (int i = 0; i < rows; ++i) {
      const double t = i * dt;
      out << i << "," << field(t);
      for (int m = 0; m < 3; ++m) out << "," << 100 + m << "," << 200 + m << ",1,";
      const double a = angle(t), d = tip(t), l = arc(t);
      // Pixel columns get deliberately different values from the mm ones, so a test can tell
      // which one was plotted.
      out << "," << field(a) << ",50,5,70," << field(metric ? l * 5 : l) << ","
          << field(metric ? d * 5 : d);
      if (metric) out << ",10,1,14," << field(l) << "," << field(d);
      if (extra) out << extra(t);
      out << ",1.5\n";
    }
    return path;
  }

  const testing::TempDir temp_;
  const fs::path dir_ = temp_.path();
};

// True when some pixel within `radius` of `p` has colour `bgr` (within `tolerance` per channel).
bool ColourNear(const cv::Mat& image, cv::Point2d p, const cv::Scalar& bgr, int radius,
                int tolerance = 60) {
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      const int x = cvRound(p.x) + dx, y = cvRound(p.y) + dy;
      if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) continue;
      const cv::Vec3b px = image.at<cv::Vec3b>(y, x);
      if (std::abs(px[0] - bgr[0]) <= tolerance && std::abs(px[1] - bgr[1]) <= tolerance &&
          std::abs(px[2] - bgr[2]) <= tolerance) {
        return true;
      }
    }
  }
  return false;
}

// Number of points in each <polyline> of an SVG document, in document order.
std::vector<int> PolylinePointCounts(const std::string& svg) {
  std::vector<int> counts;
  const std::regex polyline("<polyline [^>]*points=\"([^\"]*)\"[^>]*/>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), polyline);
       it != std::sregex_iterator(); ++it) {
    std::istringstream points((*it)[1].str());
    std::string pair;
    int n = 0;
    while (points >> pair) {
      EXPECT_NE(pair.find(','), std::string::npos) << pair;
      ++n;
    }
    counts.push_back(n);
  }
  return counts;
}

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const auto kLinearAngle = [](double t) { return 100.0 + 8.0 * t; };  // deg, known slope
const auto kLinearTip = [](double t) { return 3.0 * t; };
const auto kLinearArc = [](double t) { return 200.0 - 10.0 * t; };

TEST(NiceTicksTest, RoundStepsCoverRange) {
  EXPECT_EQ(NiceTicks(0, 10, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  EXPECT_EQ(NiceTicks(0, 10, 10), (std::vector<double>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
  const std::vector<double> ticks = NiceTicks(-0.37, 1.23, 5);
  // Span 1.6 over at most ~5 ticks: step 0.5, ticks inside the range only.
  EXPECT_EQ(ticks, (std::vector<double>{0.0, 0.5, 1.0}));
  EXPECT_TRUE(NiceTicks(3, 3, 5).empty());
  EXPECT_EQ(FormatTick(0.5, 0.5), "0.5");
  EXPECT_EQ(FormatTick(120, 20), "120");
  EXPECT_EQ(FormatTick(0.05, 0.05), "0.05");
  EXPECT_EQ(FormatTick(-1e-17, 0.1), "0.0");
}

TEST(NiceTicksTest, FarFromZeroTheTicksAreBoundedAndIncreasing) {
  // At 1e15 a step of 0.2 is below a double's resolution: a loop stepping until past `hi` never
  // ended (a 20-byte CSV ran plot out of memory).
  for (const auto& [lo, hi] : {std::pair{1e15, 1e15 + 1.0}, std::pair{-1e300, 1e300},
                               std::pair{1e300, 1.0000001e300}, std::pair{5e15, 5e15 + 8.0}}) {
    const std::vector<double> ticks = NiceTicks(lo, hi, 5);
    EXPECT_LE(ticks.size(), 12u) << lo;
    for (size_t i = 1; i < ticks.size(); ++i) EXPECT_GT(ticks[i], ticks[i - 1]) << lo;
  }
}

TEST_F(PlotTest, PngCurvesLieWhereTheDataSays) {
  const std::string csv =
      WriteCsv("run.csv", 101, 0.1, kLinearAngle, kLinearTip, kLinearArc, false);
  const std::string png = Path("run.png");
  WritePlot(csv, png);
  const cv::Mat image = cv::imread(png);
  ASSERT_FALSE(image.empty());

  const CsvTable table = ReadCsvTable(csv);
  const PlotLayout layout = ComputePlotLayout(table, PlotOptions{});
  EXPECT_EQ(image.size(), layout.size);
  EXPECT_EQ(layout.size, cv::Size(1000, 38 + 3 * 240 + 30));
  ASSERT_EQ(layout.panels.size(), 3u);
  EXPECT_EQ(layout.panels[0].y_label, "angle [deg]");
  EXPECT_EQ(layout.panels[1].y_label, "bending distance [px]");
  EXPECT_EQ(layout.panels[2].y_label, "arc length [px]");

  const std::function<double(double)> truth[] = {kLinearAngle, kLinearTip, kLinearArc};
  for (size_t p = 0; p < 3; ++p) {
    const PlotPanel& panel = layout.panels[p];
    ASSERT_EQ(panel.series.size(), 1u);
    const cv::Scalar colour = panel.series[0].bgr;
    // Axis covers the data: 0..10 s exactly, the values inside the rounded y range.
    EXPECT_DOUBLE_EQ(panel.x_min, 0.0);
    EXPECT_DOUBLE_EQ(panel.x_max, 10.0);
    EXPECT_LE(panel.y_min, std::min(truth[p](0), truth[p](10)));
    EXPECT_GE(panel.y_max, std::max(truth[p](0), truth[p](10)));
    for (double t = 0.05; t < 10; t += 0.25) {
      const cv::Point2d on = panel.to_pixel(t, truth[p](t));
      EXPECT_TRUE(ColourNear(image, on, colour, 1)) << "panel " << p << " t " << t << " at " << on;
      // 10 px above and below the curve is background, not the curve.
      EXPECT_FALSE(ColourNear(image, on + cv::Point2d(0, 10), colour, 2)) << "panel " << p;
      EXPECT_FALSE(ColourNear(image, on - cv::Point2d(0, 10), colour, 2)) << "panel " << p;
    }
  }
  // The pixel mapping itself: the y axis goes up, the plot rect's corners are the axis ends.
  const PlotPanel& angle = layout.panels[0];
  EXPECT_NEAR(angle.to_pixel(angle.x_min, angle.y_min).x, angle.plot_rect.x, 1e-9);
  EXPECT_NEAR(angle.to_pixel(angle.x_min, angle.y_min).y,
              angle.plot_rect.y + angle.plot_rect.height - 1, 1e-9);
  EXPECT_NEAR(angle.to_pixel(angle.x_max, angle.y_max).y, angle.plot_rect.y, 1e-9);
}

TEST_F(PlotTest, EmptyFieldsAreGapsNotZeros) {
  const double nan = std::nan("");
  // Angle missing for t in [4, 6) (rows 40..59): the marker was lost.
  const auto angle = [&](double t) { return (t > 3.95 && t < 5.95) ? nan : kLinearAngle(t); };
  const std::string csv = WriteCsv("gap.csv", 101, 0.1, angle, kLinearTip, kLinearArc, false);

  WritePlot(csv, Path("gap.svg"));
  const std::string svg = ReadFile(Path("gap.svg"));
  // The angle panel's series comes first: two runs of 40 and 41 points, then one run each for
  // the bending distance and the arc length.
  EXPECT_EQ(PolylinePointCounts(svg), (std::vector<int>{40, 41, 101, 101}));

  WritePlot(csv, Path("gap.png"));
  const cv::Mat image = cv::imread(Path("gap.png"));
  const PlotLayout layout = ComputePlotLayout(ReadCsvTable(csv), PlotOptions{});
  const PlotPanel& panel = layout.panels[0];
  const cv::Scalar colour = panel.series[0].bgr;
  // In the middle of the gap no pixel of the plot area's column has the curve's colour: a zero
  // would have drawn a line down to the axis.
  const int x = cvRound(panel.to_pixel(5.0, 0).x);
  for (int y = panel.plot_rect.y; y < panel.plot_rect.y + panel.plot_rect.height; ++y) {
    ASSERT_FALSE(ColourNear(image, {double(x), double(y)}, colour, 0)) << "y " << y;
  }
  EXPECT_TRUE(ColourNear(image, panel.to_pixel(3.0, kLinearAngle(3.0)), colour, 1));
  EXPECT_TRUE(ColourNear(image, panel.to_pixel(7.0, kLinearAngle(7.0)), colour, 1));
}

TEST_F(PlotTest, SvgIsWellFormedAndSinglePointsAreDots) {
  const double nan = std::nan("");
  // Angle present only at t = 0.5 (one isolated row) and t >= 0.8.
  const auto angle = [&](double t) {
    return (std::abs(t - 0.5) < 1e-6 || t > 0.75) ? kLinearAngle(t) : nan;
  };
  const std::string csv = WriteCsv("dots.csv", 11, 0.1, angle, kLinearTip, kLinearArc, false);
  WritePlot(csv, Path("dots.SVG"));  // Extension is case-insensitive.
  const std::string svg = ReadFile(Path("dots.SVG"));
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"1000\" height=\"788\""),
            std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_EQ(Count(svg, "<"), Count(svg, ">"));
  EXPECT_EQ(Count(svg, "<g>"), 3u);
  EXPECT_EQ(Count(svg, "</g>"), 3u);
  EXPECT_EQ(Count(svg, "<text"), Count(svg, "</text>"));
  EXPECT_EQ(PolylinePointCounts(svg), (std::vector<int>{3, 11, 11}));
  EXPECT_EQ(Count(svg, "<circle"), 1u);
  EXPECT_NE(svg.find(">angle [deg]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">time [s]</text>"), std::string::npos);
}

TEST_F(PlotTest, MillimetreColumnsWinWhenPresent) {
  const std::string csv = WriteCsv("mm.csv", 21, 0.05, kLinearAngle, kLinearTip, kLinearArc, true);
  const CsvTable table = ReadCsvTable(csv);
  const PlotLayout layout = ComputePlotLayout(table, PlotOptions{});
  ASSERT_EQ(layout.panels.size(), 3u);
  EXPECT_EQ(layout.panels[1].y_label, "bending distance [mm]");
  EXPECT_EQ(layout.panels[2].y_label, "arc length [mm]");
  EXPECT_EQ(table.columns[layout.panels[1].series[0].column], "tip_disp_mm");
  EXPECT_EQ(table.columns[layout.panels[2].series[0].column], "arc_length_mm");
  // The mm values (0..3) set the axis, not the px values (5x larger).
  EXPECT_LE(layout.panels[1].y_max, 4.0);
}

// The columns `softsight control` writes: setpoints and pressures in kPa share one panel.
TEST_F(PlotTest, ControlCommandColumnsGiveAPressurePanel) {
  const std::string csv =
      WriteCsv("control_cmd.csv", 11, 0.1, kLinearAngle, kLinearTip, kLinearArc, false,
               ",target_deg,setpoint_kpa,board_pressure_kpa,duty,board_flags", [](double t) {
                 std::ostringstream s;
                 s << "," << 120 << "," << 20 + t << "," << 18 + t << "," << 0.5 << "," << 0;
                 return s.str();
               });
  const PlotLayout layout = ComputePlotLayout(ReadCsvTable(csv), PlotOptions{});
  ASSERT_EQ(layout.panels.size(), 5u);
  EXPECT_EQ(layout.panels[3].y_label, "pressure [kPa]");
  ASSERT_EQ(layout.panels[3].series.size(), 2u);
  EXPECT_EQ(layout.panels[3].series[0].label, "setpoint_kpa");
  EXPECT_EQ(layout.panels[3].series[1].label, "board_pressure_kpa");
  EXPECT_EQ(layout.panels[4].y_label, "duty");
}

TEST_F(PlotTest, ControllerColumnsAddTargetAndPressurePanels) {
  const std::string csv =
      WriteCsv("control.csv", 31, 0.1, kLinearAngle, kLinearTip, kLinearArc, false,
               ",target_deg,pressure_setpoint_kpa,pressure_kpa,duty_pct", [](double t) {
                 std::ostringstream s;
                 s << "," << 120 << "," << 20 + t << "," << 18 + t << "," << 50;
                 return s.str();
               });
  const CsvTable table = ReadCsvTable(csv);
  const PlotLayout layout = ComputePlotLayout(table, PlotOptions{});
  ASSERT_EQ(layout.panels.size(), 5u);
  ASSERT_EQ(layout.panels[0].series.size(), 2u);
  EXPECT_EQ(layout.panels[0].series[0].label, "target");
  EXPECT_EQ(layout.panels[0].series[1].label, "measured");
  EXPECT_EQ(layout.panels[3].y_label, "pressure [kPa]");
  EXPECT_EQ(layout.panels[3].series.size(), 2u);
  EXPECT_EQ(layout.panels[4].y_label, "duty [%]");

  WritePlot(csv, Path("control.png"));
  const cv::Mat image = cv::imread(Path("control.png"));
  EXPECT_EQ(image.size(), layout.size);
  // The target line is flat at 120 deg (the measured one crosses it at t = 2.5 s).
  const PlotPanel& angle = layout.panels[0];
  for (double t : {0.2, 1.0, 1.8}) {
    EXPECT_TRUE(ColourNear(image, angle.to_pixel(t, 120.0), angle.series[0].bgr, 1)) << t;
  }
}

// A track-stereo CSV: the 3D angle with each camera's own in one panel, the out-of-plane angle
// in its own, the lengths in mm, and (asked for) each marker's X, Y and Z.
TEST_F(PlotTest, TrackStereoColumnsGiveThe3dAngleAndTheOutOfPlanePanel) {
  const std::string csv = Path("run3d.csv");
  {
    std::ofstream out(csv);
    out << "frame,right_frame,time_s,pair_dt_ms,red_X,red_Y,red_Z,red_sigma_mm,red_epipolar_px,"
           "red_status,angle_deg,out_of_plane_deg,plane_nx,plane_ny,plane_nz,radius_mm,"
           "arc_length_mm,tip_disp_mm,angle_left_deg,angle_right_deg,proc_ms\n";
    for (int i = 0; i < 21; ++i) {
      const double t = i * 0.1;
      out << i << "," << i + 3 << "," << t << ",," << 10 + t << "," << 20 << "," << 300 - t
          << ",0.05,0.1,found," << kLinearAngle(t) << "," << 30 - 5 * t << ",0,0.5,0.86,"
          << 60 << "," << kLinearArc(t) << "," << kLinearTip(t) << "," << kLinearAngle(t) - 2
          << "," << kLinearAngle(t) + 1 << ",2.5\n";
    }
  }
  const CsvTable table = ReadCsvTable(csv);
  const PlotLayout layout = ComputePlotLayout(table, PlotOptions{});
  ASSERT_EQ(layout.panels.size(), 4u);
  const PlotPanel& angle = layout.panels[0];
  ASSERT_EQ(angle.series.size(), 3u);
  EXPECT_EQ(angle.series[0].label, "3D");
  EXPECT_EQ(table.columns[angle.series[0].column], "angle_deg");
  EXPECT_EQ(angle.series[1].label, "left camera");
  EXPECT_EQ(table.columns[angle.series[2].column], "angle_right_deg");
  const PlotPanel& plane = layout.panels[1];
  EXPECT_EQ(plane.y_label, "out-of-plane angle [deg]");
  EXPECT_EQ(table.columns[plane.series[0].column], "out_of_plane_deg");
  EXPECT_EQ(layout.panels[2].y_label, "bending distance [mm]");
  EXPECT_EQ(layout.panels[3].y_label, "arc length [mm]");

  // The out-of-plane curve is drawn where the data says: 30 deg at t = 0, 25 at t = 1.
  WritePlot(csv, Path("run3d.png"));
  const cv::Mat image = cv::imread(Path("run3d.png"));
  for (double t : {0.0, 1.0, 1.6}) {
    EXPECT_TRUE(ColourNear(image, plane.to_pixel(t, 30 - 5 * t), plane.series[0].bgr, 1)) << t;
  }

  PlotOptions xyz;
  xyz.panels = {"xy", "plane"};
  const PlotLayout markers = ComputePlotLayout(table, xyz);
  ASSERT_EQ(markers.panels.size(), 4u);
  EXPECT_EQ(markers.panels[0].y_label, "red X [mm]");
  EXPECT_EQ(markers.panels[2].y_label, "red Z [mm]");
  EXPECT_EQ(table.columns[markers.panels[2].series[0].column], "red_Z");

  // A 2D CSV has no out-of-plane angle: asking for it names the column.
  const std::string flat = WriteCsv("flat.csv", 5, 0.1, kLinearAngle, kLinearTip, kLinearArc, false);
  PlotOptions plane_only;
  plane_only.panels = {"plane"};
  try {
    ComputePlotLayout(ReadCsvTable(flat), plane_only);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("out_of_plane_deg"), std::string::npos) << e.what();
  }
}

TEST_F(PlotTest, BadInputIsOneLineNamingTheFile) {
  auto expect_error = [](const std::function<void()>& call, const std::string& needle) {
    try {
      call();
      ADD_FAILURE() << "no InputError, expected one mentioning " << needle;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(needle), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  };
  const std::string missing = Path("missing.csv");
  expect_error([&] { WritePlot(missing, Path("x.png")); }, missing);

  const std::string no_time = Path("no_time.csv");
  std::ofstream(no_time) << "frame,angle_deg\n0,120\n";
  expect_error([&] { WritePlot(no_time, Path("x.png")); }, "no_time.csv: no time_s column");

  const std::string no_rows = Path("no_rows.csv");
  std::ofstream(no_rows) << "frame,time_s,angle_deg\n";
  expect_error([&] { WritePlot(no_rows, Path("x.png")); }, "no_rows.csv: no rows");

  const std::string bad = Path("bad.csv");
  std::ofstream(bad) << "frame,time_s,angle_deg\n0,0,120\n1,0.1,abc\n";
  expect_error([&] { WritePlot(bad, Path("x.png")); }, "bad.csv:3: column angle_deg: 'abc'");

  const std::string ragged = Path("ragged.csv");
  std::ofstream(ragged) << "frame,time_s,angle_deg\n0,0\n";
  expect_error([&] { WritePlot(ragged, Path("x.png")); }, "ragged.csv:2: expected 3 fields");

  const std::string good =
      WriteCsv("good.csv", 5, 0.1, kLinearAngle, kLinearTip, kLinearArc, false);
  expect_error([&] { WritePlot(good, Path("x.unknownext")); }, "x.unknownext");
  expect_error([&] { WritePlot(good, Path("no_such_dir/x.png")); }, "no_such_dir/x.png");
}

}  // namespace
}  // namespace softsight
