#include "softsight/io/csv_writer.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/io/csv_columns.h"

#include <stdexcept>

namespace softsight {
namespace {

using ::testing::ElementsAre;
using testing::TempDir;

FrameResult TwoMarkers(bool second_found) {
  FrameResult result;
  result.frame_index = 7;
  result.time_s = 0.25;
  result.markers.push_back({"red", {cv::Point2d(10.5, 20.25), 0.97, 0.125}, TrackState::kConfirmed});
  result.markers.push_back(
      {"blue", second_found ? Observation{cv::Point2d(1, 2), 0.5} : Observation{}});
  result.measurement.angle_deg = 135.0;
  result.measurement.chord_px = 100.0;
  result.measurement.chord_mm = 20.0;
  result.proc_ms = 0.125;
  return result;
}

TEST(CsvWriter, HeaderFollowsTheDocumentedContract) {
  TempDir dir;
  { CsvWriter csv(dir.file("a.csv"), {"red", "blue"}, /*metric=*/false); }
  EXPECT_EQ(testing::ReadLines(dir.file("a.csv")).at(0),
            "frame,time_s,red_x,red_y,red_sigma_px,red_found,red_score,red_status,red_track,blue_x,"
            "blue_y,blue_sigma_px,blue_found,blue_score,blue_status,blue_track,angle_deg,chord_px,sagitta_px,radius_px,arc_length_px,"
            "tip_disp_px,latency_result_ms,latency_row_ms,proc_ms");
  {
    CsvWriter csv(dir.file("b.csv"),
                  TrackingColumns({"red"}, /*metric=*/true,
                                  {NumberColumn("target_deg", [](const FrameResult&) {
                                    return std::optional<double>(120.0);
                                  })}));
  }
  EXPECT_EQ(testing::ReadLines(dir.file("b.csv")).at(0),
            "frame,time_s,red_x,red_y,red_sigma_px,red_found,red_score,red_status,red_track,angle_deg,"
            "chord_px,"
            "sagitta_px,"
            "radius_px,arc_length_px,tip_disp_px,chord_mm,sagitta_mm,radius_mm,arc_length_mm,"
            "tip_disp_mm,target_deg,latency_result_ms,latency_row_ms,proc_ms");
}

TEST(CsvWriter, MissingValuesAreEmptyFieldsAndRowsAreFlushedImmediately) {
  TempDir dir;
  CsvWriter csv(dir.file("run.csv"), {"red", "blue"}, /*metric=*/true);
  csv.write(TwoMarkers(/*second_found=*/false));
  // Read while the writer is still open: the row must already be on disk.
  const std::vector<std::string> lines = testing::ReadLines(dir.file("run.csv"));
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_THAT(testing::SplitCsv(lines[1]),
              ElementsAre("7", "0.250000", "10.5000", "20.2500", "0.1250", "1", "0.9700", "found",
                          "confirmed", "", "", "", "0", "", "lost", "lost", "135.0000", "100.0000", "", "", "", "", "20.0000", "", "", "", "",
                          "", "", "0.1250"));  // No capture time: no latency.
}

TEST(CsvColumnTable, HeaderAndRowsComeFromTheSameColumns) {
  // Extra columns are found by name, wherever the table puts them.
  const CsvColumnTable table = TrackingColumns(
      {"red", "blue"}, /*metric=*/false,
      {NumberColumn("target_deg", [](const FrameResult&) { return std::optional<double>(120.5); }),
       NumberColumn("duty", [](const FrameResult&) { return std::optional<double>(); })});
  const std::vector<std::string> header = testing::SplitCsv(table.header());
  EXPECT_EQ(header, table.names());
  std::string row;
  table.append_row(TwoMarkers(/*second_found=*/true), row);
  const std::vector<std::string> fields = testing::SplitCsv(row);
  ASSERT_EQ(fields.size(), header.size());
  const auto field = [&](const std::string& name) { return fields.at(*table.find(name)); };
  EXPECT_EQ(field("frame"), "7");
  EXPECT_EQ(field("blue_x"), "1.0000");
  EXPECT_EQ(field("blue_found"), "1");
  EXPECT_EQ(field("target_deg"), "120.5");
  EXPECT_EQ(field("duty"), "");
  EXPECT_EQ(field("proc_ms"), "0.1250");
  EXPECT_EQ(header.back(), "proc_ms") << "extra columns go before proc_ms";
  EXPECT_EQ(*table.find("target_deg") + 1, *table.find("duty"));
  EXPECT_FALSE(table.find("chord_mm")) << "no _mm columns without a metric model";
}

TEST(CsvColumnTable, StatusColumnNamesWhyAMarkerHasNoPosition) {
  const CsvColumnTable table = TrackingColumns({"red", "blue"}, /*metric=*/false);
  FrameResult result = TwoMarkers(/*second_found=*/false);
  std::string row;
  const auto field = [&](const std::string& name) {
    table.append_row(result, row);
    return testing::SplitCsv(row + ",").at(*table.find(name));
  };
  EXPECT_EQ(field("red_status"), "found");
  for (MarkerStatus status : {MarkerStatus::kLost, MarkerStatus::kAmbiguous,
                              MarkerStatus::kImplausible, MarkerStatus::kCovered,
                              MarkerStatus::kOutOfFrame, MarkerStatus::kNotStarted}) {
    result.markers[1].observation = Observation::NotFound(status, 2);
    EXPECT_EQ(field("blue_status"), MarkerStatusName(status));
    EXPECT_EQ(field("blue_found"), "0");
    EXPECT_EQ(field("blue_x"), "");
  }
  EXPECT_EQ(field("red_status"), "found");
}

TEST(CsvColumnTable, InsertBeforeNamesItsAnchor) {
  CsvColumnTable table = TrackingColumns({"red"}, /*metric=*/false);
  table.insert_before("angle_deg", NumberColumn("red_status_code", [](const FrameResult&) {
                        return std::optional<double>(0.0);
                      }));
  EXPECT_EQ(*table.find("red_status_code") + 1, *table.find("angle_deg"));
  EXPECT_THROW(table.insert_before("no_such_column", CsvColumn{"x", {}}), std::logic_error);
}

TEST(CsvWriter, UnwritablePathIsAnInputError) {
  EXPECT_THROW(CsvWriter("/nonexistent-folder/run.csv", {"red"}, false), InputError);
}

TEST(CsvWriter, FullDeviceFailsAtTheHeader) {
  EXPECT_THROW(CsvWriter("/dev/full", {"red"}, false), InputError);
}

// A file-size limit in the middle of a row (ulimit -f): the file must end with the last complete
// row. Run in a child process, which alone gets the limit.
TEST(CsvWriter, FileSizeLimitLeavesOnlyCompleteRows) {
  TempDir dir;
  const std::string path = dir.file("out.csv");
  constexpr rlim_t kLimitBytes = 1000;  // Not a multiple of the row length.
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // As main() does: the write fails with EFBIG instead.
    const rlimit limit{kLimitBytes, kLimitBytes};
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(3);
    try {
      CsvWriter csv(path, {"red", "blue"}, true);
      for (int i = 0; i < 1000; ++i) csv.write(TwoMarkers(i % 2 == 0));
    } catch (const InputError& e) {
      _exit(std::string(e.what()).find("intact") != std::string::npos ? 0 : 4);
    }
    _exit(5);  // The limit never struck.
  }
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  ASSERT_EQ(WEXITSTATUS(status), 0);
  const std::string text = testing::ReadTextFile(path);
  ASSERT_FALSE(text.empty());
  EXPECT_LE(text.size(), kLimitBytes);
  EXPECT_EQ(text.back(), '\n') << "the file ends in a partial row";
  const std::vector<std::string> lines = testing::ReadLines(path);
  ASSERT_GE(lines.size(), 3u);
  const size_t columns = testing::SplitCsv(lines[0]).size();
  for (size_t i = 1; i < lines.size(); ++i) {
    EXPECT_EQ(testing::SplitCsv(lines[i]).size(), columns) << "row " << i;
  }
}


// AppendCsvNumber prints "%.Nf" and "%.Ng" with std::to_chars (issue 45): the text must be
// snprintf's, byte for byte, or the CSVs would change.
TEST(CsvColumns, NumbersPrintAsSnprintfPrintsThem) {
  std::vector<double> values = {0.0, -0.0, 0.5, 1.5, 2.5, -2.5, 0.00005, 0.00015, 0.000049999,
                                1e-300, 123.45675, 179.8817, -58102.58215, 1e15, 1e21, 1e22,
                                1e300, -1e300, 9.99995, 0.1 + 0.2, 1.0 / 3.0,
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity(),
                                std::numeric_limits<double>::quiet_NaN(),
                                -std::numeric_limits<double>::quiet_NaN(),
                                std::numeric_limits<double>::denorm_min(),
                                std::numeric_limits<double>::max()};
  uint64_t state = 45;
  for (int i = 0; i < 20000; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const double unit = static_cast<double>(state >> 11) / 9007199254740992.0;
    // Pixel-sized values, and wider magnitudes; on the grid of ties of 3-6 decimals too.
    values.push_back((unit - 0.3) * 4000.0);
    values.push_back(std::ldexp(unit - 0.5, static_cast<int>(state % 120) - 60));
    values.push_back(std::round((unit - 0.5) * 2e7) / 2e4 + 0.00005);
  }
  for (const char* format : {"%.3f", "%.4f", "%.6f", "%.6g", "%.10g", "%.0f", "%.12f", "%.0g"}) {
    for (const double value : values) {
      char expected[64];
      std::snprintf(expected, sizeof(expected), format, value);
      std::string row = "x,";
      AppendCsvNumber(row, value, format);
      ASSERT_EQ(row, std::string("x,") + expected) << format << " of " << value;
    }
  }
  std::string row;
  AppendCsvNumber(row, std::nullopt, "%.4f");
  EXPECT_EQ(row, "");
  AppendCsvNumber(row, 2.0, "%5.1f");  // Not a format of the fast path: snprintf's text.
  EXPECT_EQ(row, "  2.0");
}

}  // namespace
}  // namespace softsight
