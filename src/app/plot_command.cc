// softsight plot: the paper's Figure 4 from one or more tracking (or control) CSVs, optionally
// against a truth CSV.
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/cli_checks.h"
#include "app/commands.h"
#include "softsight/io/plot.h"

namespace softsight {

CommandRunner SetupPlotCommand(CLI::App& sub) {
  struct Args {
    std::vector<std::string> csvs;
    std::optional<std::string> truth;
    std::string out;
    PlotOptions options;
  };
  auto args = std::make_shared<Args>();
  sub.description(
      "Draw CSVs of `softsight track`, `live` or `control` against time: stacked panels of the\n"
      "angle [deg], bending distance (tip displacement) and arc length (mm when the CSV has the\n"
      "_mm columns, else px); a `control` CSV adds target vs measured angle, pressure and duty;\n"
      "a `track-stereo` CSV the 3D angle beside each camera's own and the out-of-plane angle.\n"
      "Several CSVs are overlaid in one colour each, a --truth CSV (softsight synth --truth) in\n"
      "black. --panels adds the radius of curvature and each marker's x and y. A y axis never\n"
      "spans less than --min-span-px / -deg / -mm, so a steady value's sub-pixel noise is not\n"
      "drawn as motion. Empty fields (a lost marker, a straight actuator's radius) are gaps.\n"
      "Examples:\n"
      "  softsight plot run.csv -o run.png\n"
      "  softsight plot colour.csv zncc.csv --truth truth.csv --panels angle,radius,xy -o cmp.svg");
  sub.add_option("csv", args->csvs, "One or more CSVs written by `softsight track`, `live`, `control` or `track-stereo`")
      ->required();
  sub.add_option("-o,--output,--out", args->out,
                 "Output figure: .png, .jpg (raster) or .svg (vector)")
      ->required();
  sub.add_option("--truth", args->truth,
                 "A truth CSV with the same column names (softsight synth --truth), drawn in black");
  sub.add_option("--panels", args->options.panels,
                 std::string("Panels top to bottom, comma separated: ") + PlotPanelNames() +
                     " (default: angle, bending, arc and control, as the CSV has them)")
      ->delimiter(',');
  sub.add_option("--min-span-px", args->options.min_span_px,
                 "Smallest span of a pixel axis (px); 0 lets the axis hug the data")
      ->capture_default_str()
      ->check(NumberIn(0, 1e9));
  sub.add_option("--min-span-deg", args->options.min_span_deg, "Smallest span of an angle axis (deg)")
      ->capture_default_str()
      ->check(NumberIn(0, 1e9));
  sub.add_option("--min-span-mm", args->options.min_span_mm, "Smallest span of a millimetre axis")
      ->capture_default_str()
      ->check(NumberIn(0, 1e9));
  sub.add_option("--width", args->options.width_px, "Figure width in pixels")
      ->capture_default_str();
  sub.add_option("--panel-height", args->options.panel_height_px,
                 "Height of each stacked panel in pixels")
      ->capture_default_str();
  sub.add_option("--title", args->options.title, "Figure title (default: the CSVs' file names)");
  return [args] {
    std::vector<PathRole> inputs;
    for (const std::string& csv : args->csvs) inputs.push_back({"a CSV", csv});
    if (args->truth) inputs.push_back({"--truth", *args->truth});
    CheckOutputsAreNotInputs({{"--out", args->out}}, inputs);
    WritePlot(args->csvs, args->truth, args->out, args->options);
    std::cout << "wrote " << args->out << "\n";
    return 0;
  };
}

}  // namespace softsight
