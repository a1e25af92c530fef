#include "calib/calibration_internals.h"

#include <ctime>
#include <filesystem>

#include <opencv2/calib3d.hpp>

#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/core/file_write.h"

namespace softsight::calib_internal {

std::string SizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

cv::Mat DistortionMat(const std::vector<double>& distortion) {
  if (distortion.empty()) return cv::Mat();
  return cv::Mat(distortion, /*copyData=*/true).reshape(1, 1);
}

cv::FileStorage OpenForReading(const std::string& file) {
  // Checked first: FileStorage would also log its own error line for a missing file.
  std::error_code ignored;
  const std::filesystem::file_status status = std::filesystem::status(file, ignored);
  if (!std::filesystem::exists(status)) throw InputError(file + ": cannot open (no such file)");
  if (!std::filesystem::is_regular_file(status)) {
    throw InputError(file + ": not a regular file (expected an OpenCV YAML/XML file)");
  }
  cv::FileStorage fs;
  try {
    if (!fs.open(file, cv::FileStorage::READ)) {
      throw InputError(file + ": cannot open (missing or not an OpenCV YAML/XML file)");
    }
  } catch (const cv::Exception& e) {
    throw InputError(file + ": not a valid OpenCV YAML file (" + e.err + ")");
  }
  return fs;
}

cv::FileStorage OpenForWriting(const std::string& file) {
  // Built in memory, in the format the file's name asks for (XML or JSON by extension, else
  // YAML), and written whole by FinishWriting.
  const std::string ext = std::filesystem::path(file).extension().string();
  const std::string format = ext == ".xml" || ext == ".json" || ext == ".yml" ? ext : ".yaml";
  return cv::FileStorage(format, cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
}

void FinishWriting(cv::FileStorage& fs, const std::string& file) {
  WriteWholeFileOrThrow(file, fs.releaseAndGetString());
}

cv::Mat ReadMatrix(const cv::FileStorage& fs, const std::string& file, const std::string& key,
                   int rows, int cols) {
  cv::Mat m;
  try {
    fs[key] >> m;
  } catch (const cv::Exception&) {
    throw InputError(file + ": " + key + ": not a matrix");
  }
  if (m.empty()) throw InputError(file + ": " + key + ": missing");
  if ((rows > 0 && m.rows != rows) || (cols > 0 && m.cols != cols) || m.channels() != 1) {
    throw InputError(file + ": " + key + ": expected " +
                     WithArticle(std::to_string(rows) + "x" + std::to_string(cols) + " matrix") +
                     ", got " + std::to_string(m.rows) + "x" +
                     std::to_string(m.cols));
  }
  m.convertTo(m, CV_64F);
  if (!cv::checkRange(m)) throw InputError(file + ": " + key + ": has a non-finite entry");
  return m;
}

int ReadPositiveInt(const cv::FileStorage& fs, const std::string& file, const std::string& key) {
  const cv::FileNode node = fs[key];
  if (node.empty() || !node.isInt() || static_cast<int>(node) <= 0) {
    throw InputError(file + ": " + key + ": missing or not a positive integer");
  }
  return static_cast<int>(node);
}

std::string Now() {
  const std::time_t t = std::time(nullptr);
  char text[64];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return text;
}

void WriteCalibrationHeader(cv::FileStorage& fs, const cv::Size& image_size,
                            const ChessboardSpec& board) {
  fs << "calibration_time" << Now();
  fs << "image_width" << image_size.width;
  fs << "image_height" << image_size.height;
  fs << "board_width" << board.inner_corners.width;
  fs << "board_height" << board.inner_corners.height;
  fs << "square_size_mm" << board.square_mm;
}

double CalibrateFromCorners(const CalibrationOptions& options, const cv::Size& image_size,
                            const std::vector<std::vector<cv::Point2f>>& corners,
                            CameraIntrinsics& camera, std::vector<double>* per_view_rms_px) {
  const std::vector<std::vector<cv::Point3f>> object_points(corners.size(),
                                                            ChessboardObjectPoints(options.board));
  cv::Mat camera_matrix, distortion, std_intrinsics, std_extrinsics, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  const int flags = options.estimate_k3 ? 0 : cv::CALIB_FIX_K3;
  const double rms_px =
      cv::calibrateCamera(object_points, corners, image_size, camera_matrix, distortion, rvecs,
                          tvecs, std_intrinsics, std_extrinsics, per_view, flags);
  camera.image_size = image_size;
  camera.camera_matrix = cv::Matx33d(camera_matrix);
  distortion.reshape(1, 1).copyTo(camera.distortion);
  if (per_view_rms_px != nullptr) per_view.reshape(1, 1).copyTo(*per_view_rms_px);
  return rms_px;
}

}  // namespace softsight::calib_internal
