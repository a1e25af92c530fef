// softsight plot: the paper's Figure 4 from one or more tracking (or control) CSVs, optionally
// against a truth CSV.
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/cli_checks.h"
#include "app/commands.h"
#include "app/shared_flags.h"
#include "softsight/io/plot.h"

namespace softsight {

namespace {

// What plot's flags set until it runs.
struct PlotArgs {
  std::vector<std::string> csvs;
  std::optional<std::string> truth;
  std::string out;
  PlotOptions options;
};

const FlagTable<PlotArgs>& PlotFlags() {
  using A = PlotArgs;
  auto in = [](auto PlotOptions::*field) {
    return [field](A& a) -> auto& { return a.options.*field; };
  };
  static const FlagTable<PlotArgs> table = {
      ValueFlag<A>("csv", &A::csvs)
          .Help("One or more CSVs written by `softsight track`, `live`, `control` or "
                "`track-stereo`")
          .Required(),
      OutputFlag<A>(&A::out, "out", "Output figure: .png, .jpg (raster) or .svg (vector)")
          .Required(),
      ValueFlag<A>("--truth", &A::truth)
          .Help("A truth CSV with the same column names (softsight synth --truth), drawn in "
                "black"),
      ValueFlag<A>("--panels", in(&PlotOptions::panels))
          .Help(std::string("Panels top to bottom, comma separated: ") + PlotPanelNames() +
                " (default: angle, bending, arc and control, as the CSV has them)")
          .Finish([](CLI::Option* o) { o->delimiter(','); }),
      ValueFlag<A>("--min-span-px", in(&PlotOptions::min_span_px))
          .Help("Smallest span of a pixel axis (px); 0 lets the axis hug the data")
          .ShowDefault()
          .Check(NumberIn(0, 1e9)),
      ValueFlag<A>("--min-span-deg", in(&PlotOptions::min_span_deg))
          .Help("Smallest span of an angle axis (deg)")
          .ShowDefault()
          .Check(NumberIn(0, 1e9)),
      ValueFlag<A>("--min-span-mm", in(&PlotOptions::min_span_mm))
          .Help("Smallest span of a millimetre axis")
          .ShowDefault()
          .Check(NumberIn(0, 1e9)),
      ValueFlag<A>("--width", in(&PlotOptions::width_px))
          .Help("Figure width in pixels")
          .ShowDefault(),
      ValueFlag<A>("--panel-height", in(&PlotOptions::panel_height_px))
          .Help("Height of each stacked panel in pixels")
          .ShowDefault(),
      ValueFlag<A>("--title", in(&PlotOptions::title))
          .Help("Figure title (default: the CSVs' file names)"),
  };
  return table;
}

}  // namespace

CommandRunner SetupPlotCommand(CLI::App& sub) {
  auto args = std::make_shared<PlotArgs>();
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
  AddFlags(sub, PlotFlags(), args.get());
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
