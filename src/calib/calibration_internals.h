// Inside the calib module: the OpenCV FileStorage helpers and the corner-list calibration that
// the single-camera and the stereo calibration share.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/calib/camera_calibration.h"

namespace softsight::calib_internal {

std::string SizeText(const cv::Size& size);
// The distortion as the 1 x N matrix OpenCV's functions take (empty: none).
cv::Mat DistortionMat(const std::vector<double>& distortion);

// Undistortion of points is iterative; OpenCV's default of 5 iterations is not enough near the
// image corners of a wide lens.
inline const cv::TermCriteria kUndistortCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                                                 50, 1e-10);

// Throw InputError naming the file (missing, not a file, not OpenCV YAML).
cv::FileStorage OpenForReading(const std::string& file);
// A storage for `file` built in memory; FinishWriting writes it whole (core/file_write.h): a
// failure leaves the file that was there, never a cut one, and is an InputError naming it.
cv::FileStorage OpenForWriting(const std::string& file);
void FinishWriting(cv::FileStorage& fs, const std::string& file);
// A finite rows x cols matrix (0: any), as CV_64F; InputError naming file and key otherwise.
cv::Mat ReadMatrix(const cv::FileStorage& fs, const std::string& file, const std::string& key,
                   int rows, int cols);
int ReadPositiveInt(const cv::FileStorage& fs, const std::string& file, const std::string& key);
std::string Now();  // UTC, ISO 8601, for the files' calibration_time.
// What every calibration file starts with: when it was made, the image size and the board.
void WriteCalibrationHeader(cv::FileStorage& fs, const cv::Size& image_size,
                            const ChessboardSpec& board);

// cv::calibrateCamera on the views' corners (board from `options`, k3 as it says); returns the
// reprojection RMS and, when `per_view_rms_px` is given, each view's.
double CalibrateFromCorners(const CalibrationOptions& options, const cv::Size& image_size,
                            const std::vector<std::vector<cv::Point2f>>& corners,
                            CameraIntrinsics& camera,
                            std::vector<double>* per_view_rms_px = nullptr);

}  // namespace softsight::calib_internal
