#include "softsight/io/frame_writer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "io/sequence_pattern.h"
#include "softsight/core/error.h"
#include "softsight/core/file_write.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The lossless codec of softsight's own recordings (synth, demo, track --raw, the live raw
// video): HuffYUV, chosen by measurement (src/io/frame_writer_benchmark.cc, VGA rendered scene,
// one core, process CPU time, FFV1 beside it in the same run on a shared 2-core machine):
//                         encode fps          decode fps          kB/frame
//                         FFV1   HuffYUV      FFV1   HuffYUV      FFV1  HuffYUV
//   clean render            60   623 (10.5x)      60   459 (7.7x)    196   285
//   sensor noise sigma 4    61   486 (8.0x)     55   186 (3.4x)    510   673
// Both read back bit-exact as BGR24 through OpenCV 4.6's FFmpeg backend. FFV1 cannot be made
// faster on one core (its slices only help with threads); UtVideo, MagicYUV, FFVHuff and raw video
// are faster still but OpenCV's writer feeds them YUV 4:2:0, so they are not lossless for BGR.
// HuffYUV files are ~1.3-1.5x larger than FFV1. (One BGR->gray pass over the frame: 75 us CPU in
// that run.) Older FFV1 recordings still read (FFmpeg
// detects the codec from the file); `--codec ffv1` still writes FFV1 when size matters more.
constexpr const char* kLosslessCodec = "hfyu";

}  // namespace

FrameWriter::FrameWriter(FrameWriterOptions options) : options_(std::move(options)) {
  const std::string& path = options_.path;
  if (path.empty()) throw InputError("no output file given for the frames");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent)) {
    throw InputError(path + ": cannot write the frames: folder '" + parent.string() +
                     "' does not exist");
  }
  if (!(options_.fps > 0.0) || !std::isfinite(options_.fps)) {
    throw InputError(path + ": frame rate " + std::to_string(options_.fps) + " is not > 0");
  }
  const std::string ext = Lower(fs::path(path).extension().string());
  if (path.find('%') != std::string::npos) {
    // Parsed, never handed to printf: the user's text is not a format string.
    pattern_ = std::make_shared<const SequencePattern>(ParseSequencePattern(path));
    if (!cv::haveImageWriter("x" + ext)) {
      throw InputError(path + ": no image writer for '" + ext + "' (use .png)");
    }
    images_ = true;
    format_ = ext == ".png" ? "PNG images (lossless)" : "images " + ext;
    return;
  }
  std::string codec = Lower(options_.codec);
  if (codec.empty()) {
    if (ext == ".avi" || ext == ".mkv") {
      codec = kLosslessCodec;
    } else if (ext == ".mp4") {
      codec = "mp4v";
    } else {
      throw InputError(path + ": unknown video type '" + ext +
                       "' (use .avi or .mkv for lossless HuffYUV, .mp4, or an image pattern such "
                       "as frames/%04d.png)");
    }
  }
  if (codec == "ffv1") {
    fourcc_ = cv::VideoWriter::fourcc('F', 'F', 'V', '1');
    format_ = "FFV1 video (lossless, smaller, slower)";
  } else if (codec == "hfyu") {
    fourcc_ = cv::VideoWriter::fourcc('H', 'F', 'Y', 'U');
    format_ = "HuffYUV video (lossless)";
  } else if (codec == "mjpg") {
    fourcc_ = cv::VideoWriter::fourcc('M', 'J', 'P', 'G');
    format_ = "Motion JPEG video (lossy)";
  } else if (codec == "mp4v") {
    fourcc_ = cv::VideoWriter::fourcc('m', 'p', '4', 'v');
    format_ = "MPEG-4 video (lossy)";
  } else {
    throw InputError("codec '" + options_.codec + "' for " + path +
                     ": unknown (choose ffv1, hfyu, mjpg or mp4v)");
  }
  struct stat info {};
  const bool device = ::stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode);
  // A device (/dev/null) cannot be replaced by a rename: written in place.
  const fs::path output(path);
  writing_path_ = device ? path
                         : (output.parent_path() /
                            ("." + output.filename().string() + ".part" + output.extension().string()))
                               .string();
  // Made now (not truncated: another run's may be in it) and locked, so a second writer of this
  // video is refused before it cuts the first one's file; FFmpeg truncates it when it opens.
  lock_fd_ = ::open(writing_path_.c_str(), O_WRONLY | O_CREAT | O_NONBLOCK | O_CLOEXEC, 0666);
  if (lock_fd_ < 0) {
    throw InputError(path + ": cannot write the video (" + std::strerror(errno) + ")");
  }
  try {
    LockOutputOrThrow(lock_fd_, path);
  } catch (...) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw;
  }
}

FrameWriter::~FrameWriter() {
  // Left by an exception: the video is abandoned. Left in order: finished as close() does (a cut
  // video is then removed, its error lost: a caller that cares calls close()).
  if (std::uncaught_exceptions() > uncaught_at_start_) {
    discard();
    return;
  }
  try {
    close();
  } catch (...) {  // close() removed the temporary file.
  }
}

void FrameWriter::discard() {
  if (video_.isOpened()) video_.release();
  if (lock_fd_ < 0) return;
  if (writing_path_ != options_.path) ::unlink(writing_path_.c_str());
  ::close(lock_fd_);
  lock_fd_ = -1;
}

void FrameWriter::open(cv::Size size) {
  size_ = size;
  if (images_ || video_.isOpened()) return;
  video_.open(writing_path_, cv::CAP_FFMPEG, fourcc_, options_.fps, size, true);
  if (!video_.isOpened()) {
    throw InputError(options_.path + ": cannot open for writing as " + format_ +
                     " (check the folder is writable and the codec fits the container)");
  }
}

void FrameWriter::write(const cv::Mat& image_bgr, int64_t index) {
  if (written_ == 0 && size_.empty()) open(image_bgr.size());
  if (image_bgr.size() != size_ || image_bgr.type() != CV_8UC3) {
    throw InputError(options_.path + ": frame " + std::to_string(index) + " is " +
                     std::to_string(image_bgr.cols) + "x" + std::to_string(image_bgr.rows) +
                     ", the video is " + std::to_string(size_.width) + "x" +
                     std::to_string(size_.height) + " BGR");
  }
  if (!images_) {
    video_.write(image_bgr);
    ++written_;
    return;
  }
  const std::string name = pattern_->Format(index);
  bool ok = false;
  try {
    ok = cv::imwrite(name, image_bgr);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) throw InputError(name + ": cannot write frame " + std::to_string(index));
  ++written_;
}

void FrameWriter::close() {
  if (!video_.isOpened()) {
    discard();  // No frame, no video: nothing to put in place.
    return;
  }
  video_.release();
  // FFmpeg reports no write error (a full disk, a file size limit): the finished file is read
  // back, and one that does not hold every frame written is an error, never a silent cut video.
  double frames = static_cast<double>(written_);
  if (written_ > 0) {
    cv::VideoCapture check;
    frames = -1.0;
    try {
      if (check.open(writing_path_, cv::CAP_FFMPEG)) frames = check.get(cv::CAP_PROP_FRAME_COUNT);
    } catch (const cv::Exception&) {
      frames = -1.0;
    }
  }
  // A Matroska file's count comes from its duration: within a frame of the truth.
  const double tolerance = Lower(fs::path(options_.path).extension().string()) == ".mkv" ? 1.0 : 0.0;
  if (!(frames + tolerance >= static_cast<double>(written_))) {
    discard();
    throw InputError(options_.path + ": the video holds " +
                     (frames >= 0 ? std::to_string(static_cast<int64_t>(frames)) : std::string("no")) +
                     " of the " + std::to_string(written_) +
                     " frames written (a full disk, or a file size limit?); left as it was");
  }
  if (writing_path_ != options_.path &&
      std::rename(writing_path_.c_str(), options_.path.c_str()) != 0) {
    const int error = errno;
    discard();
    throw InputError(options_.path + ": cannot put the finished video in place (" +
                     std::strerror(error) + ")");
  }
  ::close(lock_fd_);  // The lock goes with the finished file.
  lock_fd_ = -1;
}

}  // namespace softsight
