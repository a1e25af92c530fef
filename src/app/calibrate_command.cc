#include "app/calibrate_command.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "app/commands.h"
#include "app/shared_flags.h"
#include "io/sequence_pattern.h"
#include "softsight/calib/camera_calibration.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/core/error.h"
#include "softsight/io/output_guard.h"

namespace softsight {
namespace fs = std::filesystem;
namespace {

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

// The views of one input, read one at a time (a video is never held in memory): a folder (its
// image files in name order), a numbered pattern (every file it names, in number order, whatever
// the first number and gaps), one image, or a video (every `step`-th frame). `option` names the
// input in messages ("--input", "--left").
class ViewSequence {
 public:
  ViewSequence(const std::string& input, const std::string& option, int step)
      : option_(option), step_(step) {
    std::error_code error;
    if (fs::is_directory(input, error)) {
      std::vector<fs::path> files;
      for (const fs::directory_entry& entry : fs::directory_iterator(input)) {
        if (entry.is_regular_file() && IsImageFile(entry.path())) files.push_back(entry.path());
      }
      if (files.empty())
        throw InputError(option + " " + input + ": the folder holds no image files");
      std::sort(files.begin(), files.end());
      for (const fs::path& file : files)
        files_.push_back({file.filename().string(), file.string()});
      return;
    }
    if (input.find('%') != std::string::npos && !fs::exists(input, error)) {
      // Parsed, never handed to printf: "%s" in the user's text must not be a format. A gap
      // (OpenCV's left01 .. left14 has no left10) is not the end: every file is a view, named by
      // its file, and the report says which numbers were missing.
      const std::vector<NumberedFile> files = ListSequenceFiles(ParseSequencePattern(input));
      if (files.empty()) throw InputError(option + " " + input + ": no file matches the pattern");
      for (const NumberedFile& file : files) {
        files_.push_back({fs::path(file.path).filename().string(), file.path});
      }
      if (const std::optional<std::string> gaps = DescribeNumberingGaps(files)) {
        note_ =
            option + " " + input + ": " + *gaps + "; every file found is a view, named by its file";
      }
      return;
    }
    if (!fs::is_regular_file(input, error)) {
      throw InputError(option + " " + input + ": no such file or folder");
    }
    if (IsImageFile(input)) {
      files_.push_back({fs::path(input).filename().string(), input});
      return;
    }
    video_.open(input);
    if (!video_.isOpened()) {
      throw InputError(option + " " + input + ": cannot open as a video (and it is no image)");
    }
    video_file_ = input;
  }

  // The next view; false at the end.
  bool next(std::string& name, cv::Mat& image) {
    if (!video_.isOpened()) {
      if (next_file_ >= files_.size()) return false;
      const NamedFile& file = files_[next_file_++];
      name = file.name;
      image = ReadImage(file.path);
      return true;
    }
    // Every step-th frame; the ones between are read and dropped (grab would not decode
    // them, but a video's frames must be read in order anyway).
    for (; video_.read(image); ++frame_index_) {
      if (frame_index_ % step_ == 0) {
        name = "frame " + std::to_string(frame_index_++);
        return true;
      }
    }
    return false;
  }

  bool is_video() const { return video_.isOpened() || !video_file_.empty(); }
  // Absent for a video (its length is only known at its end).
  std::optional<size_t> file_count() const {
    if (is_video()) return std::nullopt;
    return files_.size();
  }
  // What the report should say about the input (gaps in a pattern's numbering), if anything.
  const std::optional<std::string>& note() const { return note_; }
  // The files read, for the output guard.
  std::vector<PathRole> inputs() const {
    std::vector<PathRole> roles;
    if (is_video()) roles.push_back({option_, video_file_});
    for (const NamedFile& file : files_) roles.push_back({option_, file.path});
    return roles;
  }

 private:
  struct NamedFile {
    std::string name, path;
  };
  std::string option_;
  int step_ = 1;
  std::vector<NamedFile> files_;
  size_t next_file_ = 0;
  cv::VideoCapture video_;
  std::string video_file_;
  int frame_index_ = 0;
  std::optional<std::string> note_;
};

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
  ViewSequence views(*options.input, "--input", options.step);
  // Before any work: the calibration must not land on a picture, the video or a link to them.
  CheckOutputsAreNotInputs({{"--out", options.out_file}}, views.inputs());
  std::string name;
  cv::Mat image;
  while (views.next(name, image)) calibrator.add(name, image);
  const std::optional<std::string>& input_note = views.note();
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
  // Before any work: the scale must not replace the picture or the camera's intrinsics.
  CheckOutputsAreNotInputs({{"--out", options.out_file}},
                           {{"--plane", *options.plane_image},
                            {"--camera", options.camera_file.value_or("")}});
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

std::string PairName(const StereoPairReport& pair) {
  return pair.left_name + " + " + pair.right_name;
}

// The two sequences pair one to one, and no view is both cameras'; none is an output.
void CheckStereoViews(const CalibrateOptions& options, ViewSequence& left, ViewSequence& right) {
  if (left.file_count() && right.file_count() && *left.file_count() != *right.file_count()) {
    throw InputError("--left has " + std::to_string(*left.file_count()) + " images but --right " +
                     std::to_string(*right.file_count()) +
                     ": the views are paired one to one in order, so each needs its partner");
  }
  std::vector<PathRole> inputs = left.inputs();
  for (PathRole& role : right.inputs()) inputs.push_back(std::move(role));
  // The same views on both sides calibrate two cameras at one place (baseline 0).
  for (const PathRole& l : left.inputs()) {
    for (const PathRole& r : right.inputs()) {
      std::error_code ec;
      if (fs::equivalent(l.path, r.path, ec)) {
        throw InputError("--left and --right: " + EscapeForMessage(l.path) +
                         " is a view of both cameras; give each camera's own views");
      }
    }
  }
  CheckOutputsAreNotInputs(
      {{"--out", options.out_file}, {"--picture", options.picture_file.value_or("")}}, inputs);
}

// What reading the pairs leaves besides the calibrator's corners: why the pairs ended early, and
// the first used pair (for --picture).
struct StereoPairsRead {
  std::optional<std::string> length_note;
  cv::Mat picture_left, picture_right;
  std::string picture_pair;
};

// Every pair to the calibrator, until either sequence ends.
StereoPairsRead AddStereoPairs(const CalibrateOptions& options, ViewSequence& left,
                               ViewSequence& right, StereoCalibrator& calibrator) {
  std::string left_name, right_name;
  cv::Mat left_image, right_image;
  StereoPairsRead read;
  while (true) {
    const bool have_left = left.next(left_name, left_image);
    const bool have_right = right.next(right_name, right_image);
    if (!have_left || !have_right) {
      if (have_left || have_right) {
        read.length_note = std::string(have_left ? "--right" : "--left") +
                           " ended first: the other's views after " +
                           (have_left ? left_name : right_name) +
                           " have no partner and were not used";
      }
      break;
    }
    const StereoPairStatus status = calibrator.add(left_name, left_image, right_name, right_image);
    if (status == StereoPairStatus::kUsed && read.picture_left.empty() && options.picture_file) {
      read.picture_left = left_image.clone();
      read.picture_right = right_image.clone();
      read.picture_pair = left_name + " + " + right_name;
    }
  }
  return read;
}

// Why a pair was left out of the calibration.
std::string WhyLeftOut(const StereoPairReport& pair) {
  switch (pair.status) {
    case StereoPairStatus::kLeftOnly: return "board in the left view only";
    case StereoPairStatus::kRightOnly: return "board in the right view only";
    case StereoPairStatus::kNeither: return "board in neither view";
    case StereoPairStatus::kOutlier: {
      std::ostringstream text;
      text << std::fixed << std::setprecision(3) << "does not fit the other pairs ("
           << *pair.left_rms_px << " / " << *pair.right_rms_px
           << " px: did the board move between the two pictures?)";
      return text.str();
    }
    case StereoPairStatus::kUsed:
      break;
  }
  return "";
}

// --picture: the first used pair rectified side by side.
void WriteRectifiedPicture(const CalibrateOptions& options, const StereoCalibration& stereo,
                           const StereoPairsRead& read, std::ostream& report) {
  const cv::Mat picture = DrawRectifiedPair(stereo, read.picture_left, read.picture_right);
  bool written = false;
  try {
    written = cv::imwrite(*options.picture_file, picture);
  } catch (const cv::Exception&) {
  }
  if (!written) {
    throw InputError(
        "--picture " + *options.picture_file +
        ": cannot write (use an image extension such as .png, in a writable folder)");
  }
  report << "wrote " << *options.picture_file << " (" << read.picture_pair
         << " rectified: each point of the scene should lie on one line in both halves)\n";
}

CalibrateSummary CalibrateStereoMode(const CalibrateOptions& options, const ChessboardSpec& board,
                                     std::ostream& report) {
  ViewSequence left(*options.left, "--left", options.step);
  ViewSequence right(*options.right, "--right", options.step);
  CheckStereoViews(options, left, right);

  StereoCalibrationOptions calibration;
  calibration.camera.board = board;
  calibration.camera.estimate_k3 = options.estimate_k3;
  StereoCalibrator calibrator(calibration);
  const StereoPairsRead read = AddStereoPairs(options, left, right, calibrator);
  const StereoCalibrationResult result = calibrator.calibrate();
  SaveStereoCalibration(result, board, options.out_file);

  CalibrateSummary summary;
  summary.pairs = static_cast<int>(result.pairs.size());
  summary.pairs_used = result.pairs_used();
  summary.baseline_mm = result.stereo.baseline_mm();
  summary.rms_px = result.stereo.rms_px;
  summary.fx_px = result.stereo.left.camera_matrix(0, 0);
  summary.fy_px = result.stereo.left.camera_matrix(1, 1);
  for (const ViewSequence* views : {&left, &right}) {
    if (views->note()) report << *views->note() << "\n";
  }
  if (read.length_note) report << *read.length_note << "\n";
  report << std::fixed << std::setprecision(2);
  report << "board " << options.chessboard << " (" << board.square_mm
         << " mm squares) in both views of " << summary.pairs_used << " of " << summary.pairs
         << " pairs (" << result.stereo.left.image_size.width << "x"
         << result.stereo.left.image_size.height << ")\n";
  report << std::setprecision(3);
  for (const StereoPairReport& pair : result.pairs) {
    if (pair.status == StereoPairStatus::kUsed) {
      report << "  " << PairName(pair) << ": " << *pair.left_rms_px << " / " << *pair.right_rms_px
             << " px\n";
      continue;
    }
    report << "  " << PairName(pair) << ": left out, " << WhyLeftOut(pair) << "\n";
    summary.left_out.push_back(PairName(pair) + ": " + StereoPairStatusName(pair.status));
  }
  const StereoCalibration& s = result.stereo;
  cv::Vec3d rotation;
  cv::Rodrigues(s.R, rotation);
  report << std::setprecision(2) << "left camera: fx " << s.left.camera_matrix(0, 0) << " px, RMS "
         << result.left_rms_px << " px; right camera: fx " << s.right.camera_matrix(0, 0)
         << " px, RMS " << result.right_rms_px << " px\n";
  report << "baseline " << s.baseline_mm() << " mm, cameras turned "
         << cv::norm(rotation) * 180.0 / CV_PI << " deg apart; stereo reprojection RMS "
         << std::setprecision(3) << s.rms_px << " px"
         << (s.rms_px > 1.0 ? " (high: were the pairs taken at the same moment?)" : "") << "\n";
  report << "wrote " << options.out_file << "\n";
  if (options.picture_file) WriteRectifiedPicture(options, s, read, report);
  report.unsetf(std::ios::floatfield);
  return summary;
}

}  // namespace

CalibrateSummary RunCalibrate(const CalibrateOptions& options, std::ostream& report) {
  const bool stereo = options.left.has_value() || options.right.has_value();
  if (stereo && options.left.has_value() != options.right.has_value()) {
    throw InputError(std::string("--") + (options.left ? "right" : "left") +
                     ": stereo calibration needs both --left and --right views");
  }
  if (static_cast<int>(options.input.has_value()) +
          static_cast<int>(options.plane_image.has_value()) + static_cast<int>(stereo) !=
      1) {
    throw InputError(
        "give one of --input FRAMES (camera calibration), --plane IMAGE (scale in "
        "the actuator's plane) or --left FRAMES --right FRAMES (two cameras)");
  }
  if (options.picture_file && !stereo)
    throw InputError("--picture is used with --left and --right only");
  if (options.camera_file && !options.plane_image) {
    throw InputError("--camera is used with --plane only");
  }
  if (options.out_file.empty()) throw InputError("--out: give the file to write");
  if (options.step < 1)
    throw InputError("--step: must be >= 1, got " + std::to_string(options.step));
  const ChessboardSpec board = BoardFrom(options);
  if (stereo) return CalibrateStereoMode(options, board, report);
  return options.input ? CalibrateCameraMode(options, board, report)
                       : CalibratePlaneMode(options, board, report);
}

namespace {

const FlagTable<CalibrateOptions>& CalibrateFlags() {
  using A = CalibrateOptions;
  static const FlagTable<CalibrateOptions> table = {
      ValueFlag<A>(kInputFlag, &A::input)
          .Help("Chessboard views: a folder of images, a printf pattern (shots/%03d.png) or a "
                "video file"),
      ValueFlag<A>("--plane", &A::plane_image)
          .Help("One image of the chessboard lying flat in the actuator's plane: writes the "
                "image-to-millimetre homography instead")
          .Excludes("--input"),
      ValueFlag<A>(kLeftFlag, &A::left)
          .Help("Two cameras: the first camera's chessboard views (folder, pattern or video), "
                "paired one to one in order with --right's")
          .Excludes("--input")
          .Excludes("--plane"),
      ValueFlag<A>(kRightFlag, &A::right)
          .Help("Two cameras: the second camera's views of the same moments")
          .Excludes("--input")
          .Excludes("--plane"),
      ValueFlag<A>("--picture", &A::picture_file)
          .Help("With --left/--right: write the first pair rectified side by side with epipolar "
                "lines (PNG)"),
      ValueFlag<A>("--camera", &A::camera_file)
          .Help("With --plane: the camera file from an earlier `calibrate --input` run, used to "
                "remove lens distortion")
          .Needs("--plane"),
      ValueFlag<A>(kChessboardFlag, &A::chessboard)
          .Help("INNER corners per row x per column, e.g. 9x6 for a board of 10 x 7 "
                "squares")
          .Required(),
      ValueFlag<A>(kSquareMmFlag, &A::square_mm)
          .Help("Side of one printed square in millimetres")
          .Required(),
      OutputFlag<A>(&A::out_file, "out", "File to write (OpenCV YAML)").Required(),
      ValueFlag<A>("--step", &A::step)
          .Help("Video input: use every N-th frame (default 1; with two videos, both)"),
      SwitchFlag<A>("--k3", &A::estimate_k3)
          .Help("Also estimate the k3 radial term (wide-angle lenses only)"),
  };
  return table;
}

}  // namespace

CommandRunner SetupCalibrateCommand(CLI::App& sub) {
  auto options = std::make_shared<CalibrateOptions>();
  sub.description(
      "Calibrate the camera from chessboard views (intrinsics and lens distortion), or measure\n"
      "the actuator's plane in millimetres from one view of a chessboard lying in it.\n"
      "  softsight calibrate --input shots/ --chessboard 9x6 --square-mm 25 --out camera.yaml\n"
      "  softsight calibrate --plane board_on_table.png --camera camera.yaml --chessboard 9x6 "
      "--square-mm 25 --out plane.yaml\n"
      "  softsight calibrate --left left/ --right right/ --chessboard 9x6 --square-mm 25 "
      "--out stereo.yaml --picture epipolar.png\n"
      "Then put `camera: camera.yaml` and `plane: plane.yaml` in the tracking config; a\n"
      "stereo.yaml is for `track-stereo` (docs/stereo.md).\n"
      "Take 10-20 views of the board filling much of the frame at different tilts and\n"
      "positions, including the image corners.");
  AddFlags(sub, CalibrateFlags(), options.get());
  return [options] {
    RunCalibrate(*options, std::cout);
    return 0;
  };
}

}  // namespace softsight
