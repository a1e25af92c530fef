#include "app/calibrate_command.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <optional>
#include <set>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "app/commands.h"
#include "io/sequence_pattern.h"
#include "softsight/calib/camera_calibration.h"
#include "softsight/core/error.h"

namespace softsight {
namespace fs = std::filesystem;
namespace {

using ViewCallback = std::function<void(const std::string& name, const cv::Mat& image)>;

bool IsImageFile(const fs::path& path) {
  static const std::set<std::string> kExtensions = {".png", ".jpg", ".jpeg", ".bmp", ".tif",
                                                    ".tiff", ".pgm", ".ppm", ".webp"};
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) {
    return static_cast<char>(std::tolower(c));
  });
  return kExtensions.count(ext) > 0;
}

cv::Mat ReadImage(const std::string& file) {
  cv::Mat image = cv::imread(file, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw InputError(file + ": cannot read this image (corrupt or not an image)");
  return image;
}


// Every view in `input`: a folder (its image files in name order), a numbered pattern (every
// file it names, in number order, whatever the first number and gaps) or a video (every
// `step`-th frame). Returns what the report should say about the input (gaps in a pattern's
// numbering), if anything.
std::optional<std::string> ForEachView(const std::string& input, int step,
                                       const ViewCallback& callback) {
  std::error_code error;
  if (fs::is_directory(input, error)) {
    std::vector<fs::path> files;
    for (const fs::directory_entry& entry : fs::directory_iterator(input)) {
      if (entry.is_regular_file() && IsImageFile(entry.path())) files.push_back(entry.path());
    }
    if (files.empty()) throw InputError("--input " + input + ": the folder holds no image files");
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) callback(file.filename().string(), ReadImage(file.string()));
    return std::nullopt;
  }
  if (input.find('%') != std::string::npos && !fs::exists(input, error)) {
    // Parsed, never handed to printf: "%s" in the user's text must not be a format. A gap
    // (OpenCV's left01 .. left14 has no left10) is not the end: every file is a view, named by
    // its file, and the report says which numbers were missing.
    const std::vector<NumberedFile> files = ListSequenceFiles(ParseSequencePattern(input));
    if (files.empty()) throw InputError("--input " + input + ": no file matches the pattern");
    for (const NumberedFile& file : files) {
      callback(fs::path(file.path).filename().string(), ReadImage(file.path));
    }
    const std::optional<std::string> gaps = DescribeNumberingGaps(files);
    if (!gaps) return std::nullopt;
    return "--input " + input + ": " + *gaps + "; every file found is a view, named by its file";
  }
  if (!fs::is_regular_file(input, error)) {
    throw InputError("--input " + input + ": no such file or folder");
  }
  if (IsImageFile(input)) {
    callback(fs::path(input).filename().string(), ReadImage(input));
    return std::nullopt;
  }
  cv::VideoCapture video(input);
  if (!video.isOpened()) {
    throw InputError("--input " + input + ": cannot open as a video (and it is no image)");
  }
  cv::Mat frame;
  for (int index = 0; video.read(frame); ++index) {
    if (index % step == 0) callback("frame " + std::to_string(index), frame);
  }
  return std::nullopt;
}

ChessboardSpec BoardFrom(const CalibrateOptions& options) {
  ChessboardSpec board;
  board.inner_corners = ParseChessboardSize(options.chessboard, "--chessboard");
  board.square_mm = options.square_mm;
  if (!(options.square_mm > 0.0)) {
    throw InputError("--square-mm: must be the printed square's side in mm (> 0), got " +
                     std::to_string(options.square_mm));
  }
  return board;
}

CalibrateSummary CalibrateCameraMode(const CalibrateOptions& options, const ChessboardSpec& board,
                                     std::ostream& report) {
  CalibrationOptions calibration;
  calibration.board = board;
  calibration.estimate_k3 = options.estimate_k3;
  ChessboardCalibrator calibrator(calibration);
  const std::optional<std::string> input_note =
      ForEachView(*options.input, options.step, [&](const std::string& name, const cv::Mat& image) {
        calibrator.add(name, image);
      });
  const CalibrationResult result = calibrator.calibrate();
  SaveCameraCalibration(result, board, options.out_file);

  CalibrateSummary summary;
  summary.images = calibrator.views_seen();
  summary.not_found = result.not_found;
  summary.rms_px = result.rms_px;
  summary.fx_px = result.camera.camera_matrix(0, 0);
  summary.fy_px = result.camera.camera_matrix(1, 1);
  const cv::Matx33d& k = result.camera.camera_matrix;
  if (input_note) report << *input_note << "\n";
  report << std::fixed << std::setprecision(2);
  report << "board " << options.chessboard << " (" << board.square_mm << " mm squares) found in "
         << result.used.size() << " of " << summary.images << " images ("
         << result.camera.image_size.width << "x" << result.camera.image_size.height << ")\n";
  if (!result.not_found.empty()) {
    report << "board not found in " << result.not_found.size() << ":";
    for (const std::string& name : result.not_found) report << " " << name;
    report << "\n";
  }
  report << "focal length: fx " << k(0, 0) << " px, fy " << k(1, 1) << " px; principal point ("
         << k(0, 2) << ", " << k(1, 2) << ") px\n";
  report << std::setprecision(4) << "distortion (k1 k2 p1 p2 k3):";
  for (const double d : result.camera.distortion) report << " " << d;
  report << "\n" << std::setprecision(3) << "reprojection RMS: " << result.rms_px << " px"
         << (result.rms_px > 1.0 ? " (high: blurred views or a wrong --chessboard/--square-mm?)"
                                 : "")
         << "\n";
  report << "wrote " << options.out_file << "\n";
  report.unsetf(std::ios::floatfield);
  return summary;
}

CalibrateSummary CalibratePlaneMode(const CalibrateOptions& options, const ChessboardSpec& board,
                                    std::ostream& report) {
  std::optional<CameraIntrinsics> camera;
  if (options.camera_file) camera = LoadCameraIntrinsics(*options.camera_file);
  const std::string& image_file = *options.plane_image;
  if (!fs::is_regular_file(image_file)) {
    throw InputError("--plane " + image_file + ": no such image file");
  }
  const cv::Mat image = ReadImage(image_file);
  const PlaneCalibration plane = CalibratePlane(image, image_file, board, camera);
  SavePlaneCalibration(plane, options.out_file);

  CalibrateSummary summary;
  summary.images = 1;
  summary.mm_per_px = plane.mm_per_px;
  summary.rms_mm = plane.rms_mm;
  report << std::setprecision(4) << "board " << options.chessboard << " found in " << image_file
         << (camera ? " (corners undistorted with " + *options.camera_file + ")"
                    : " (no --camera: lens distortion ignored)")
         << "\n";
  report << "scale at the board's centre: " << plane.mm_per_px << " mm/px; homography residual "
         << plane.rms_mm << " mm RMS\n";
  report << "wrote " << options.out_file << " (use `plane: " << options.out_file
         << "` in the tracking config)\n";
  return summary;
}

}  // namespace

CalibrateSummary RunCalibrate(const CalibrateOptions& options, std::ostream& report) {
  if (options.input.has_value() == options.plane_image.has_value()) {
    throw InputError("give either --input FRAMES (camera calibration) or --plane IMAGE (scale in "
                     "the actuator's plane)");
  }
  if (options.camera_file && !options.plane_image) {
    throw InputError("--camera is used with --plane only");
  }
  if (options.out_file.empty()) throw InputError("--out: give the file to write");
  if (options.step < 1) throw InputError("--step: must be >= 1, got " + std::to_string(options.step));
  const ChessboardSpec board = BoardFrom(options);
  return options.input ? CalibrateCameraMode(options, board, report)
                       : CalibratePlaneMode(options, board, report);
}

CommandRunner SetupCalibrateCommand(CLI::App& sub) {
  auto options = std::make_shared<CalibrateOptions>();
  sub.description(
      "Calibrate the camera from chessboard views (intrinsics and lens distortion), or measure\n"
      "the actuator's plane in millimetres from one view of a chessboard lying in it.\n"
      "  softsight calibrate --input shots/ --chessboard 9x6 --square-mm 25 --out camera.yaml\n"
      "  softsight calibrate --plane board_on_table.png --camera camera.yaml --chessboard 9x6 "
      "--square-mm 25 --out plane.yaml\n"
      "Then put `camera: camera.yaml` and `plane: plane.yaml` in the tracking config.\n"
      "Take 10-20 views of the board filling much of the frame at different tilts and\n"
      "positions, including the image corners.");
  auto* input = sub.add_option("--input", options->input,
                               "Chessboard views: a folder of images, a printf pattern "
                               "(shots/%03d.png) or a video file");
  auto* plane = sub.add_option("--plane", options->plane_image,
                               "One image of the chessboard lying flat in the actuator's plane: "
                               "writes the image-to-millimetre homography instead");
  input->excludes(plane);
  sub.add_option("--camera", options->camera_file,
                 "With --plane: the camera file from an earlier `calibrate --input` run, used to "
                 "remove lens distortion")
      ->needs(plane);
  sub.add_option("--chessboard", options->chessboard,
                 "INNER corners per row x per column, e.g. 9x6 for a board of 10 x 7 squares")
      ->required();
  sub.add_option("--square-mm", options->square_mm, "Side of one printed square in millimetres")
      ->required();
  sub.add_option("--out", options->out_file, "File to write (OpenCV YAML)")->required();
  sub.add_option("--step", options->step, "Video input: use every N-th frame (default 1)");
  sub.add_flag("--k3", options->estimate_k3,
               "Also estimate the k3 radial term (wide-angle lenses only)");
  return [options] {
    RunCalibrate(*options, std::cout);
    return 0;
  };
}

}  // namespace softsight
