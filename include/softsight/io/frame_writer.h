// Where frames go when they are saved: a video file (FFmpeg through cv::VideoWriter) or one image
// per frame (a printf pattern such as frames/%04d.png). The one writer behind `synth`, the raw and
// annotated videos of `track` and the live window's recordings. A video is written to a temporary
// file beside it (".<name>.part<ext>", the extension kept so FFmpeg picks the container), locked
// for this writer alone, and renamed over the output only by a close() that found every frame in
// it: a full disk, a file size limit, an error or a crash on the way leaves the output as it was
// (an older file of that name intact), never a cut video.
#pragma once

#include <cstdint>
#include <exception>
#include <memory>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace softsight {

struct SequencePattern;

struct FrameWriterOptions {
  // A video (*.avi, *.mkv: HuffYUV lossless by default; *.mp4: MPEG-4, lossy) or an image pattern
  // with one %d or %0Nd field, frames/%04d.png, "%%" for a literal % (one image per frame, named
  // by the frame's index).
  std::string path{};
  // Video codec: hfyu (HuffYUV, lossless, fast: the default), ffv1 (lossless, ~1.4x smaller,
  // 8-10x slower to encode; older recordings), mjpg (Motion JPEG,
  // lossy, small: for videos people watch), mp4v (lossy). Empty: chosen by the extension.
  std::string codec{};
  double fps = 30.0;  // The video's nominal rate (ignored for image patterns). > 0.
};

class FrameWriter {
 public:
  // Checks the path, folder, extension and codec at once (before any frame exists), so a bad
  // output fails before work starts, and makes and locks a video's temporary file. Throws
  // InputError naming the path or codec, or saying another program is writing this video.
  explicit FrameWriter(FrameWriterOptions options);
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // Opens the video for frames of `size` (write() does it on the first frame otherwise).
  // Throws InputError when FFmpeg cannot open it.
  void open(cv::Size size);
  // Writes one 8-bit BGR image; `index` names the file of an image pattern. Every image must have
  // the size of the first. Throws InputError naming the file and frame on failure.
  void write(const cv::Mat& image_bgr, int64_t index);
  // Finishes the video, checks it holds every frame written (FFmpeg reports no write error) and
  // renames it over the output: throws InputError naming the file when it does not (a full disk,
  // a file size limit) or the rename fails, the temporary file removed and the output as it was.
  // A video never opened (no frame) makes no file.
  void close();
  // Abandons the video: its temporary file is removed, the output left as it was. What the
  // destructor does when an exception leaves the writer's scope; leaving it in order finishes
  // the video as close() does, its error swallowed.
  void discard();

  // "HuffYUV video (lossless)", "PNG images (lossless)", ...
  const std::string& format() const { return format_; }
  const std::string& path() const { return options_.path; }
  int64_t written() const { return written_; }

 private:
  FrameWriterOptions options_;
  bool images_ = false;
  int fourcc_ = 0;
  // Where the video is written until close() renames it to the output: the temporary file, or the
  // output itself when that is a device (/dev/null). Its descriptor holds the writer's lock.
  std::string writing_path_;
  int lock_fd_ = -1;
  int uncaught_at_start_ = std::uncaught_exceptions();  // Tells the destructor an unwinding.
  std::string format_;
  cv::Size size_;
  cv::VideoWriter video_;
  // The file names of an image pattern (parsed: the path is never a printf format). Behind a
  // pointer so this header does not need io's private pattern parser.
  std::shared_ptr<const SequencePattern> pattern_;
  int64_t written_ = 0;
};

}  // namespace softsight
