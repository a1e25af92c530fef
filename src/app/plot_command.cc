// softsight plot: the paper's Figure 4 from a tracking (or control) CSV.
#include <iostream>
#include <memory>
#include <string>

#include "app/cli_checks.h"
#include "app/commands.h"
#include "softsight/io/plot.h"

namespace softsight {

CommandRunner SetupPlotCommand(CLI::App& sub) {
  struct Args {
    std::string csv;
    std::string out;
    PlotOptions options;
  };
  auto args = std::make_shared<Args>();
  sub.footer(
      "Stacked panels against time: angle [deg], bending distance (tip displacement) and arc\n"
      "length, in mm when the CSV has the _mm columns, else px. A CSV written by `softsight\n"
      "control` adds target vs measured angle and the pressure and duty columns. Empty fields\n"
      "(a lost marker) are gaps in the curves.\n"
      "Example: softsight plot out.csv -o run.png");
  sub.add_option("csv", args->csv, "CSV written by `softsight track`, `live` or `control`")
      ->required();
  sub.add_option("-o,--out", args->out, "Output figure: .png, .jpg (raster) or .svg (vector)")
      ->required();
  sub.add_option("--width", args->options.width_px, "Figure width in pixels")
      ->capture_default_str();
  sub.add_option("--panel-height", args->options.panel_height_px,
                 "Height of each stacked panel in pixels")
      ->capture_default_str();
  sub.add_option("--title", args->options.title, "Figure title (default: the CSV's file name)");
  return [args] {
    CheckOutputsAreNotInputs({{"--out", args->out}}, {{"the CSV", args->csv}});
    WritePlot(args->csv, args->out, args->options);
    std::cout << "wrote " << args->out << "\n";
    return 0;
  };
}

}  // namespace softsight
