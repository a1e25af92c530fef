// The CSV reader behind `softsight plot` on arbitrary bytes, then the plot layout and SVG of
// whatever it accepted: an InputError or a figure, never a crash, a hang or a sanitizer report.
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "softsight/core/error.h"
#include "softsight/io/csv_reader.h"
#include "softsight/io/plot.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = softsight::fuzz::WriteScratchFile("run.csv", data, size);
  try {
    const softsight::CsvTable table = softsight::ReadCsvTable(path);
    for (const auto& column : table.values) {
      if (column.size() != table.row_count()) __builtin_trap();
    }
    const softsight::PlotLayout layout = softsight::ComputePlotLayout(table, {});
    softsight::RenderPlotSvg(table, layout);
  } catch (const softsight::InputError&) {
  }
  return 0;
}
