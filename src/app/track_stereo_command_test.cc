// End to end: an actuator bending 30 degrees out of the image plane, rendered through a rig of
// known pose into two image sequences, tracked by `track-stereo` with the rig's exact
// calibration file; the CSV is read back against the renderer's 3D truth.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>

#include <sys/wait.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "app/program_test_util.h"
#include "app/scene_markers_test_util.h"
#include "app/stereo_test_util.h"
#include "app/track_stereo_command.h"
#include "calib/stereo_test_util.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/geometry/shape3d.h"
#include "softsight/io/csv_reader.h"
#include "softsight/io/plot.h"
#include "softsight/sim/stereo_scene.h"
#include "stream/subscriber_test_util.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::ReadRows;
using testing::StereoMarkersYaml;

class TrackStereoCommandTest : public ::testing::Test {
 protected:
  static constexpr int kFrames = 10;
  static constexpr int kRightLead = 3;  // The right camera started 3 frames earlier.

  static void SetUpTestSuite() {
    dir_ = new testing::TempDir("track_stereo");
    fs::create_directories(dir_->path() / "left");
    fs::create_directories(dir_->path() / "right");
    StereoSceneOptions options;
    options.frame_count = kFrames;
    options.max_bend_deg = 100.0;
    scene_ = new StereoScene(MakeStereoRig(), options);
    cv::Mat left, right;
    char name[32];
    // The right sequence starts with frames of an empty bench (its camera started earlier).
    const cv::Mat empty(480, 640, CV_8UC3, cv::Scalar(105, 110, 115));
    for (int i = 0; i < kRightLead; ++i) {
      std::snprintf(name, sizeof(name), "right/%03d.png", i);
      cv::imwrite(dir_->file(name), empty);
    }
    for (int i = 0; i < kFrames; ++i) {
      truths_.push_back(scene_->render(i, left, right));
      std::snprintf(name, sizeof(name), "left/%03d.png", i);
      cv::imwrite(dir_->file(name), left);
      std::snprintf(name, sizeof(name), "right/%03d.png", i + kRightLead);
      cv::imwrite(dir_->file(name), right);
    }
    StereoCalibrationResult rig;
    rig.stereo = testing::CalibrationOfRig(scene_->rig());
    SaveStereoCalibration(rig, ChessboardSpec{}, dir_->file("stereo.yaml"));
    std::ofstream(dir_->file("markers.yaml")) << StereoMarkersYaml();
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete scene_;
    truths_.clear();
  }
  static TrackStereoOptions Options() {
    TrackStereoOptions options;
    options.config_file = dir_->file("markers.yaml");
    options.left_input = dir_->file("left");
    options.right_input = dir_->file("right");
    options.stereo_file = dir_->file("stereo.yaml");
    options.csv_file = dir_->file("run3d.csv");
    options.frame_offset = kRightLead;
    return options;
  }
  // Renders the 9x6 board of 20 mm at `pose` (the left camera's) into `<name>_left.png` and
  // `<name>_right.png`; returns the two files.
  static std::vector<std::string> WriteBenchBoard(const std::string& name, const BoardPose& pose) {
    ChessboardLook look;
    look.supersample = 2;
    cv::Mat left, right;
    ChessboardRenderer(scene_->rig().left, BenchPattern(), look).render(pose, left);
    ChessboardRenderer(scene_->rig().right, BenchPattern(), look)
        .render(RightBoardPose(scene_->rig(), pose), right);
    const std::vector<std::string> files = {dir_->file(name + "_left.png"),
                                            dir_->file(name + "_right.png")};
    cv::imwrite(files[0], left);
    cv::imwrite(files[1], right);
    return files;
  }
  static ChessboardPattern BenchPattern() {
    ChessboardPattern pattern;
    pattern.inner_corners = cv::Size(9, 6);
    pattern.square_mm = 20.0;
    pattern.margin_mm = 15.0;
    return pattern;
  }
  static testing::TempDir* dir_;
  static StereoScene* scene_;
  static std::vector<StereoSceneTruth> truths_;
};
testing::TempDir* TrackStereoCommandTest::dir_ = nullptr;
StereoScene* TrackStereoCommandTest::scene_ = nullptr;
std::vector<StereoSceneTruth> TrackStereoCommandTest::truths_;

TEST_F(TrackStereoCommandTest, MarkersAndAnglesIn3dMatchTheTruth) {
  std::ostringstream report;
  const TrackStereoSummary summary = RunTrackStereo(Options(), report);
  EXPECT_EQ(summary.pairs, kFrames);
  for (const auto& [name, count] : summary.found) EXPECT_EQ(count, kFrames) << name << report.str();
  EXPECT_THAT(report.str(), HasSubstr("right frame = left frame + 3"));

  const std::vector<std::map<std::string, std::string>> rows = ReadRows(Options().csv_file);
  const CsvTable table = ReadCsvTable(Options().csv_file);
  ASSERT_EQ(rows.size(), static_cast<size_t>(kFrames));
  const auto value = [&](const std::string& column, size_t row) {
    return table.values[*table.find(column)][row];
  };
  double position_sq = 0, angle_sq = 0, worst_single_camera_error_deg = 0;
  int positions = 0, angles = 0;
  for (size_t r = 0; r < rows.size(); ++r) {
    EXPECT_EQ(rows[r].at("right_frame"), std::to_string(r + kRightLead));
    for (const StereoMarkerTruth& m : truths_[r].markers) {
      EXPECT_EQ(rows[r].at(m.name + "_status"), "found") << "frame " << r;
      const cv::Point3d p(*value(m.name + "_X", r), *value(m.name + "_Y", r),
                          *value(m.name + "_Z", r));
      position_sq += std::pow(cv::norm(p - m.position_mm), 2);
      ++positions;
    }
    ASSERT_TRUE(value("angle_deg", r).has_value());
    angle_sq += std::pow(*value("angle_deg", r) - truths_[r].angle_deg, 2);
    ++angles;
    if (r >= 6) {  // Bent 67 degrees or more: the plane is well defined by the three markers.
      EXPECT_NEAR(*value("out_of_plane_deg", r), 30.0, 0.5) << "frame " << r;
      worst_single_camera_error_deg =
          std::max(worst_single_camera_error_deg,
                   std::abs(*value("angle_left_deg", r) - truths_[r].angle_deg));
      EXPECT_NEAR(*value("radius_mm", r), *truths_[r].radius_mm, 0.02 * *truths_[r].radius_mm);
    }
  }
  EXPECT_LT(std::sqrt(position_sq / positions), 0.2);
  EXPECT_LT(std::sqrt(angle_sq / angles), 0.3);
  // One camera sees the bend foreshortened: its angle is off by more than the 3D one.
  EXPECT_GT(worst_single_camera_error_deg, 0.5);
  std::cout << "[ figures  ] track-stereo: marker 3D error " << std::sqrt(position_sq / positions)
            << " mm RMS, 3D angle " << std::sqrt(angle_sq / angles)
            << " deg RMS; the left camera's 2D angle off by up to " << worst_single_camera_error_deg
            << " deg\n";
  EXPECT_FALSE(value("tip_disp_mm", 0).value_or(1.0) > 1e-9);  // The first tip is the reference.

  // `softsight plot` on it: the 3D angle with each camera's, and the out-of-plane angle.
  const PlotLayout layout = ComputePlotLayout(table, PlotOptions{});
  ASSERT_GE(layout.panels.size(), 2u);
  EXPECT_EQ(layout.panels[0].series.size(), 3u);
  EXPECT_EQ(layout.panels[1].y_label, "out-of-plane angle [deg]");
}

TEST_F(TrackStereoCommandTest, WithTheRimFitOnAMarkerMovingAwayIsStillPlacedAtItsCentre) {
  // The default colour config keeps the rim fit: the tip marker moving away from the cameras is
  // seen 12 % smaller by the end. A whole disc seen smaller is not partly hidden (what is off the
  // circle of its first size bulges outwards, where a cut is straight): its centroid stands, and
  // its depth is right. (Before, the circle of its first size placed it about 1 px off in each
  // view: 1.9 mm in depth.)
  std::ofstream(dir_->file("rim.yaml")) << testing::kSceneMarkersYaml;
  TrackStereoOptions options = Options();
  options.config_file = dir_->file("rim.yaml");
  std::ostringstream report;
  RunTrackStereo(options, report);
  const CsvTable table = ReadCsvTable(options.csv_file);
  const StereoMarkerTruth& tip = truths_.back().markers.back();
  EXPECT_LT(std::abs(*table.values[*table.find("green_Z")].back() - tip.position_mm.z), 0.5);
}

TEST_F(TrackStereoCommandTest, WithoutTheOffsetTheEmptyRightFramesLeaveMarkersMissing) {
  TrackStereoOptions options = Options();
  options.frame_offset = 0;
  options.max_frames = kRightLead;
  std::ostringstream report;
  const TrackStereoSummary summary = RunTrackStereo(options, report);
  for (const auto& [name, count] : summary.found) EXPECT_EQ(count, 0) << name;
  const auto rows = ReadRows(options.csv_file);
  ASSERT_EQ(rows.size(), static_cast<size_t>(kRightLead));
  EXPECT_EQ(rows[0].at("red_status"), "right_lost");
  EXPECT_EQ(rows[0].at("red_X"), "");
}

TEST_F(TrackStereoCommandTest, MarkersSwappedInOneViewAreRefusedByTheEpipolarCheck) {
  // The right view's config calls the blue disc red and the red one blue: both views find a
  // "red", but not the same object, 35 mm apart along the body: no point is believed.
  std::string swapped = StereoMarkersYaml();
  const std::string red = "h: [170, 10]", blue = "h: [100, 130]";
  swapped.replace(swapped.find(red), red.size(), "h: [XXX]");
  swapped.replace(swapped.find(blue), blue.size(), red);
  swapped.replace(swapped.find("h: [XXX]"), 8, blue);
  std::ofstream(dir_->file("swapped.yaml")) << swapped;
  TrackStereoOptions options = Options();
  options.right_config_file = dir_->file("swapped.yaml");
  options.max_frames = 4;
  std::ostringstream report;
  const TrackStereoSummary summary = RunTrackStereo(options, report);
  EXPECT_EQ(summary.found[0].second, 0);  // red
  EXPECT_EQ(summary.epipolar[0].second, 4);
  EXPECT_EQ(summary.epipolar[1].second, 4);  // blue
  EXPECT_EQ(summary.found[2].second, 4);     // green is the same object in both.
  const auto rows = ReadRows(options.csv_file);
  EXPECT_EQ(rows[0].at("red_status"), "epipolar");
  EXPECT_EQ(rows[0].at("angle_deg"), "");
  EXPECT_THAT(report.str(),
              HasSubstr("red: found in 3D in 0 of 4 (4 refused by the epipolar check)"));
}

// The calibration board laid once on the bench, seen by both cameras: the markers' coordinates
// come out in its frame. The renderer's board pose is the truth: each true marker position is
// carried into the board's frame the same way, and the frame-independent measurements must not
// change at all.
TEST_F(TrackStereoCommandTest, InTheBenchBoardsFrameMarkersMatchTheTruthAndTheShapeIsUnchanged) {
  const BoardPose pose = LookAtBoard(BenchPattern(), 320, 40, 0, 10, 0, 10);
  WriteBenchBoard("bench", pose);
  cv::Matx33d board_rotation;
  cv::Rodrigues(pose.rvec, board_rotation);
  const auto true_in_board = [&](const cv::Point3d& p) {
    const cv::Vec3d q = board_rotation.t() * (cv::Vec3d(p.x, p.y, p.z) - pose.tvec);
    return cv::Point3d(q[0], q[1], q[2]);
  };

  TrackStereoOptions camera_options = Options();
  camera_options.csv_file = dir_->file("camera_frame.csv");
  std::ostringstream camera_report;
  RunTrackStereo(camera_options, camera_report);
  EXPECT_THAT(camera_report.str(), HasSubstr("<m>_X/_Y/_Z in the first camera's frame"));

  TrackStereoOptions options = Options();
  options.csv_file = dir_->file("bench_frame.csv");
  options.bench_board = {dir_->file("bench_left.png"), dir_->file("bench_right.png")};
  options.chessboard = "9x6";
  options.square_mm = 20.0;
  std::ostringstream report;
  const TrackStereoSummary summary = RunTrackStereo(options, report);
  ASSERT_TRUE(summary.bench_board_rms_mm.has_value());
  EXPECT_LT(*summary.bench_board_rms_mm, 0.3);
  EXPECT_THAT(report.str(), HasSubstr("bench board " + options.bench_board[0] + " / " +
                                      options.bench_board[1] + ": 54 corners, fitted to"));
  EXPECT_THAT(report.str(), HasSubstr("<m>_X/_Y/_Z and plane_n* in the bench board's frame"));

  const auto camera_rows = ReadRows(camera_options.csv_file);
  const auto rows = ReadRows(options.csv_file);
  const CsvTable table = ReadCsvTable(options.csv_file);
  ASSERT_EQ(rows.size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(camera_rows.size(), rows.size());
  const auto value = [&](const std::string& column, size_t row) {
    return *table.values[*table.find(column)][row];
  };
  double position_sq = 0;
  int positions = 0;
  double worst_normal_deg = 0;
  for (size_t r = 0; r < rows.size(); ++r) {
    for (const char* column : {"angle_deg", "out_of_plane_deg", "radius_mm", "arc_length_mm",
                               "tip_disp_mm", "angle_left_deg", "angle_right_deg"}) {
      EXPECT_EQ(rows[r].at(column), camera_rows[r].at(column)) << column << ", frame " << r;
    }
    for (const StereoMarkerTruth& m : truths_[r].markers) {
      ASSERT_EQ(rows[r].at(m.name + "_status"), "found") << "frame " << r;
      EXPECT_EQ(rows[r].at(m.name + "_sigma_mm"), camera_rows[r].at(m.name + "_sigma_mm"));
      const cv::Point3d p(value(m.name + "_X", r), value(m.name + "_Y", r),
                          value(m.name + "_Z", r));
      position_sq += std::pow(cv::norm(p - true_in_board(m.position_mm)), 2);
      ++positions;
    }
    if (r >= 6) {  // The bending plane is well defined.
      const cv::Vec3d n(value("plane_nx", r), value("plane_ny", r), value("plane_nz", r));
      const cv::Vec3d truth = board_rotation.t() * truths_[r].plane_normal;
      worst_normal_deg = std::max(
          worst_normal_deg, std::acos(std::min(1.0, std::abs(n.dot(truth)))) * 180.0 / CV_PI);
    }
  }
  const double rms = std::sqrt(position_sq / positions);
  EXPECT_LT(rms, 0.2);
  EXPECT_LT(worst_normal_deg, 0.5);
  std::cout << "[ figures  ] track-stereo --bench-board: board fit " << *summary.bench_board_rms_mm
            << " mm RMS; markers in the board's frame " << rms
            << " mm RMS from the truth; bending plane normal within " << worst_normal_deg
            << " deg\n[ report   ] " << report.str().substr(0, report.str().find('\n') + 1);

  // The stereo file's own board (9x6 of 25 mm here) is not the one on the bench: refused by the
  // fit's residual, before anything is written.
  options.chessboard.clear();
  options.square_mm.reset();
  options.csv_file = dir_->file("refused.csv");
  try {
    RunTrackStereo(options, report);
    ADD_FAILURE() << "a board of the wrong size was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bench_left.png / " + options.bench_board[1] +
                                    ": the triangulated corners fit a flat 9x6 board of 25.00 mm "
                                    "squares to"));
    EXPECT_THAT(e.what(), HasSubstr("(limit 2.00)"));
    std::cout << "[ refusal  ] " << e.what() << "\n";
  }
  EXPECT_FALSE(fs::exists(options.csv_file));
}

// `--reference-plane board`: the out-of-plane angle against the bench board's plane. The bend
// leans 30 degrees out of the image plane; each board is posed at another angle to it, and the
// renderer's bending-plane normal and board pose give the true angle between the two planes.
TEST_F(TrackStereoCommandTest, AgainstTheBenchBoardsPlaneTheOutOfPlaneAngleIsTheTrueOne) {
  struct Board {
    std::string name;
    BoardPose pose;
  };
  const std::vector<Board> boards = {
      {"tilted_x", LookAtBoard(BenchPattern(), 320, 40, 0, 10, 0, 10)},   // 52.6 deg to the bend.
      {"tilted_y", LookAtBoard(BenchPattern(), 310, 0, -35, -5, 0, 0)},   // 5.7 deg.
      {"steep", LookAtBoard(BenchPattern(), 300, -45, 40, 20, 0, 10)}};  // 74.9 deg.
  // The bending plane from three markers is good to 0.4 deg (the test above: its normal), the
  // board's to 0.03 deg (calib/board_frame_test.cc): the tolerance is the bend's.
  double worst_deg = 0, error_sq = 0;
  int angles = 0;
  for (const Board& board : boards) {
    TrackStereoOptions options = Options();
    options.csv_file = dir_->file("board_plane_" + board.name + ".csv");
    options.bench_board = WriteBenchBoard(board.name, board.pose);
    options.chessboard = "9x6";
    options.square_mm = 20.0;
    options.reference_plane = "board";
    std::ostringstream report;
    RunTrackStereo(options, report);
    EXPECT_THAT(report.str(), HasSubstr("out_of_plane_deg against the bench board's plane"));
    cv::Matx33d board_rotation;
    cv::Rodrigues(board.pose.rvec, board_rotation);
    const cv::Vec3d board_normal(board_rotation(0, 2), board_rotation(1, 2), board_rotation(2, 2));
    const CsvTable table = ReadCsvTable(options.csv_file);
    const std::vector<std::optional<double>>& measured =
        table.values[*table.find("out_of_plane_deg")];
    ASSERT_EQ(measured.size(), static_cast<size_t>(kFrames));
    double truth_deg = 0;
    for (size_t r = 6; r < measured.size(); ++r) {  // The bending plane is well defined.
      truth_deg = *AngleBetweenPlanesDeg(truths_[r].plane_normal, board_normal);
      ASSERT_TRUE(measured[r].has_value()) << board.name << ", frame " << r;
      EXPECT_NEAR(*measured[r], truth_deg, 0.5) << board.name << ", frame " << r;
      worst_deg = std::max(worst_deg, std::abs(*measured[r] - truth_deg));
      error_sq += std::pow(*measured[r] - truth_deg, 2);
      ++angles;
    }
    std::cout << "[ figures  ] --reference-plane board (" << board.name << "): true angle "
              << truth_deg << " deg, measured " << *measured.back() << " deg\n";
  }
  std::cout << "[ figures  ] --reference-plane board: error " << std::sqrt(error_sq / angles)
            << " deg RMS, worst " << worst_deg << " deg\n";

  // Without a bench board there is no board's plane: one line, exit code 2, nothing written.
  TrackStereoOptions options = Options();
  options.reference_plane = "board";
  options.csv_file = dir_->file("no_bench.csv");
  std::ostringstream report;
  try {
    RunTrackStereo(options, report);
    ADD_FAILURE() << "--reference-plane board without --bench-board was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--reference-plane board: the bench board's plane; give "
                                    "--bench-board LEFT RIGHT"));
  }
  const std::string cli = testing::SoftsightBinary() + " track-stereo -c " + options.config_file +
                          " --left " + options.left_input + " --right " + options.right_input +
                          " --stereo " + options.stereo_file + " --csv " + options.csv_file +
                          " --reference-plane board 2> " + dir_->file("board_err.txt");
  EXPECT_EQ(WEXITSTATUS(std::system(cli.c_str())), 2);
  const std::string err = testing::ReadTextFile(dir_->file("board_err.txt"));
  EXPECT_THAT(err, HasSubstr("--reference-plane board: the bench board's plane"));
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(fs::exists(options.csv_file));
}

// `--publish`: while track-stereo runs, a subscriber gets every pair's row with the CSV's
// columns and values (topic frame), a marker's 3D columns (marker/<name>) and the run's end.
TEST_F(TrackStereoCommandTest, PublishSendsEveryRowWithTheCsvsColumnsAsItHappens) {
  TrackStereoOptions options = Options();
  options.csv_file = dir_->file("published.csv");
  PublishOptions publish;
  publish.endpoint = "ipc://" + dir_->file("stereo.ipc");
  publish.wait_subscribers = 1;  // Connected before the first pair: it gets every one.
  options.publish = publish;
  StreamSubscriber records(publish.endpoint, {"hello", "frame", "marker/green", "end"}, "test");
  std::ostringstream report;
  auto run = std::async(std::launch::async, [&] { return RunTrackStereo(options, report); });
  auto received = testing::ReceiveUntilEnd(records);
  const TrackStereoSummary summary = run.get();
  ASSERT_EQ(received["end"].size(), 1u) << "no end record";
  ASSERT_EQ(received["hello"].size(), 1u);
  const nlohmann::ordered_json& hello = received["hello"][0];
  const nlohmann::ordered_json& end = received["end"][0];
  const std::vector<nlohmann::ordered_json>& frames = received["frame"];
  const std::vector<nlohmann::ordered_json>& green = received["marker/green"];
  EXPECT_EQ(end["frames"], kFrames);
  EXPECT_EQ(end["stop_reason"], "end of input");
  EXPECT_THAT(report.str(), HasSubstr("note: --publish " + publish.endpoint));
  EXPECT_THAT(report.str(), HasSubstr("none dropped"));

  std::ifstream csv(options.csv_file);
  std::string line;
  std::getline(csv, line);
  const std::vector<std::string> header = testing::SplitCsv(line);
  EXPECT_EQ(hello["columns"].get<std::vector<std::string>>(), header);
  EXPECT_EQ(hello["markers"].get<std::vector<std::string>>(),
            (std::vector<std::string>{"red", "blue", "green"}));
  ASSERT_EQ(frames.size(), static_cast<size_t>(summary.pairs));
  ASSERT_EQ(frames.size(), static_cast<size_t>(kFrames));
  for (size_t r = 0; r < frames.size(); ++r) {
    ASSERT_TRUE(static_cast<bool>(std::getline(csv, line)));
    testing::ExpectRecordIsRow(frames[r], header, testing::SplitCsv(line),
                               "record " + std::to_string(r));
  }
  ASSERT_EQ(green.size(), frames.size());
  std::vector<std::string> green_keys;
  for (const auto& item : green[0].items()) green_keys.push_back(item.key());
  EXPECT_EQ(green_keys, (std::vector<std::string>{"frame", "time_s", "green_X", "green_Y",
                                                  "green_Z", "green_sigma_mm",
                                                  "green_epipolar_px", "green_status"}));
  EXPECT_EQ(green.back()["green_Z"], frames.back()["green_Z"]);

  // A bad endpoint: one line naming it, before any output is made.
  options.csv_file = dir_->file("not_published.csv");
  options.publish->endpoint = "tcp://nowhere";
  options.publish->wait_subscribers = 0;
  try {
    RunTrackStereo(options, report);
    ADD_FAILURE() << "a bad endpoint was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--publish"));
    EXPECT_THAT(e.what(), HasSubstr("tcp://nowhere"));
  }
  EXPECT_FALSE(fs::exists(options.csv_file));
}

TEST_F(TrackStereoCommandTest, ABenchBoardImageWithoutTheBoardIsRefusedNamingTheFile) {
  TrackStereoOptions options = Options();
  options.bench_board = {dir_->file("left/000.png"), dir_->file("right/003.png")};
  options.csv_file = dir_->file("no_board.csv");
  std::ostringstream report;
  try {
    RunTrackStereo(options, report);
    ADD_FAILURE() << "no board, yet accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    EXPECT_THAT(e.what(), HasSubstr(options.bench_board[0] +
                                    ": the 9x6 chessboard (inner corners) was not found"));
  }
  EXPECT_FALSE(fs::exists(options.csv_file));
  // The program: one line naming the file, exit code 2, before the frame offset is searched for
  // (no --frame-offset here: the board is looked at first).
  const std::string cli = testing::SoftsightBinary() + " track-stereo -c " + options.config_file +
                          " --left " + options.left_input + " --right " + options.right_input +
                          " --stereo " + options.stereo_file + " --csv " +
                          options.csv_file + " --bench-board " + options.bench_board[0] + " " +
                          options.bench_board[1] + " 2> " + dir_->file("bench_err.txt");
  EXPECT_EQ(WEXITSTATUS(std::system(cli.c_str())), 2);
  const std::string err = testing::ReadTextFile(dir_->file("bench_err.txt"));
  EXPECT_THAT(err, HasSubstr(options.bench_board[0] + ": the 9x6 chessboard (inner corners) was "
                             "not found"));
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  std::cout << "[ refusal  ] " << err;
  EXPECT_FALSE(fs::exists(options.csv_file));
  options.bench_board = {dir_->file("missing_left.png"), dir_->file("right/003.png")};
  EXPECT_THROW(
      {
        try {
          RunTrackStereo(options, report);
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("missing_left.png: cannot read the image"));
          throw;
        }
      },
      InputError);
  options = Options();
  options.square_mm = 20.0;
  EXPECT_THROW(
      {
        try {
          RunTrackStereo(options, report);
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("--square-mm describes the --bench-board board"));
          throw;
        }
      },
      InputError);
}

// Ctrl-C between pairs: every row written is whole, the summary says why it stopped, and the
// exit code is 130 (128 + SIGINT), as for `track`. The built-in scene in both views gives 300
// pairs (its markers fail the epipolar check there, but every pair still gets its row).
TEST_F(TrackStereoCommandTest, CtrlCStopsBetweenPairsWithEveryRowCompleteAndExitCode130) {
  const std::string csv = dir_->file("interrupted.csv");
  const int status = testing::RunAndSignalOnceRowsAreWritten(
      "track-stereo -c " + dir_->file("markers.yaml") +
          " --left synth:bending --right synth:bending --frame-offset 0 --stereo " +
          dir_->file("stereo.yaml") + " --csv " + csv + " > " + dir_->file("interrupted.txt"),
      csv, 6, SIGINT, dir_->file("interrupted_err.txt"));
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping cleanly";
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_THAT(testing::ReadTextFile(dir_->file("interrupted.txt")),
              HasSubstr("stopped by Ctrl-C (SIGINT)"));
  const std::vector<std::string> lines = testing::ReadLines(csv);
  ASSERT_GE(lines.size(), 6u);
  ASSERT_LT(lines.size(), 301u) << "the run ended before the interrupt arrived";
  const size_t columns = testing::SplitCsv(lines[0]).size();
  for (size_t i = 1; i < lines.size(); ++i) {
    EXPECT_EQ(testing::SplitCsv(lines[i]).size(), columns) << "row " << i;
  }
}

TEST_F(TrackStereoCommandTest, BadInputIsOneLineNamingTheCulprit) {
  const auto error_of = [](const TrackStereoOptions& options) -> std::string {
    std::ostringstream report;
    try {
      RunTrackStereo(options, report);
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      return e.what();
    }
    return "(no error)";
  };
  TrackStereoOptions options = Options();
  options.stereo_file = dir_->file("missing.yaml");
  EXPECT_THAT(error_of(options), HasSubstr("missing.yaml: cannot open"));

  options = Options();
  options.csv_file = dir_->file("left/000.png");
  EXPECT_THAT(error_of(options), HasSubstr("left/000.png"));
  EXPECT_FALSE(cv::imread(dir_->file("left/000.png")).empty());

  options = Options();
  options.frame_offset = 100;
  EXPECT_THAT(error_of(options), HasSubstr("--frame-offset 100"));

  options = Options();
  options.reference_plane = "sideways";
  EXPECT_THAT(error_of(options), HasSubstr("--reference-plane: expected image"));

  std::ofstream(dir_->file("two.yaml"))
      << "markers:\n  - name: red\n    hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}\n";
  options = Options();
  options.right_config_file = dir_->file("two.yaml");
  EXPECT_THAT(error_of(options),
              HasSubstr("marker 'blue' is in the left view's config but not in the right view's"));
}

}  // namespace
}  // namespace softsight
