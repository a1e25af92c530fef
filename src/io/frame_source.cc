#include "softsight/io/frame_source.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <string_view>
#include <thread>
#include <variant>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "io/aravis_camera.h"
#include "io/camera_options.h"
#include "io/damaged_band.h"
#include "io/decode_probe.h"
#include "io/decoder_log.h"
#include "io/libav_video_reader.h"
#include "io/sequence_pattern.h"
#include "softsight/core/error.h"
#include "softsight/sim/builtin_scenes.h"

namespace softsight {
namespace fs = std::filesystem;
namespace {

// Decoders hand back gray or BGRA for some files; everything downstream expects 8-bit BGR.
void ToBgr(const cv::Mat& decoded, cv::Mat& bgr) {
  if (decoded.type() == CV_8UC3) {
    if (decoded.data != bgr.data) decoded.copyTo(bgr);
  } else if (decoded.type() == CV_8UC1) {
    cv::cvtColor(decoded, bgr, cv::COLOR_GRAY2BGR);
  } else if (decoded.type() == CV_8UC4) {
    cv::cvtColor(decoded, bgr, cv::COLOR_BGRA2BGR);
  } else {
    cv::Mat eight_bit;
    decoded.convertTo(eight_bit, CV_8U, decoded.depth() == CV_16U ? 1.0 / 256.0 : 1.0);
    ToBgr(eight_bit, bgr);
  }
}

// Which packets of a video are key frames (decodable on their own), read on demand from a second,
// demux-only capture (no decoding: OpenCV's raw mode), in step with the frames asked about. A
// file OpenCV cannot read that way is taken as all key frames (damage stays in its frame), and
// so is a codec that has no other kind (`intra_only`: nothing is read twice).
class KeyFrameIndex {
 public:
  KeyFrameIndex(const std::string& path, bool intra_only) : path_(path), intra_only_(intra_only) {}
  // Whether frame `index` (counted as the decoder counts frames) is a key frame; true when the
  // container cannot say.
  bool is_key(int64_t index) {
    if (!read_to(index)) return true;
    return flags_[static_cast<size_t>(index)];
  }
  // The first key frame after `index`; INT64_MAX when the stream has none after it (the damage
  // lasts to the end).
  int64_t next_after(int64_t index) {
    for (int64_t i = index + 1;; ++i) {
      if (!read_to(i)) return usable_ ? std::numeric_limits<int64_t>::max() : index + 1;
      if (flags_[static_cast<size_t>(i)]) return i;
    }
  }

 private:
  // Demuxes packets up to `index`; false when the index (or the stream) cannot say.
  bool read_to(int64_t index) {
    if (!opened_) {
      opened_ = true;
      usable_ = !intra_only_ && raw_.open(path_, cv::CAP_FFMPEG, {cv::CAP_PROP_FORMAT, -1}) &&
                raw_.isOpened();
    }
    if (!usable_) return false;
    while (static_cast<int64_t>(flags_.size()) <= index) {
      if (ended_ || !raw_.grab()) {
        ended_ = true;
        return false;
      }
      flags_.push_back(raw_.get(cv::CAP_PROP_LRF_HAS_KEY_FRAME) != 0.0);
    }
    return true;
  }

  std::string path_;
  bool intra_only_;
  cv::VideoCapture raw_;
  bool opened_ = false, usable_ = false, ended_ = false;
  std::vector<bool> flags_;  // Per packet read so far: a key frame.
};

// The FourCC as FFmpeg reports it through OpenCV, as its four characters.
std::string FourCcText(double fourcc_property) {
  const auto fourcc = static_cast<uint32_t>(fourcc_property);
  return {static_cast<char>(fourcc & 0xff), static_cast<char>((fourcc >> 8) & 0xff),
          static_cast<char>((fourcc >> 16) & 0xff), static_cast<char>((fourcc >> 24) & 0xff)};
}

// Codecs whose every frame is a key frame.
bool IntraOnlyCodec(double fourcc_property) {
  const std::string code = FourCcText(fourcc_property);
  static const char* kIntraOnly[] = {"HFYU", "FFVH", "FFV1", "MJPG", "mjpg", "AVRn", "MJPA",
                                     "png ", "MPNG", "UYVY", "YUY2", "Y800", "I420", "BGR ",
                                     "RGB ", "utvd", "ULRG", "ULY0", "ULY2", "M8RG", "M8Y0"};
  return std::any_of(std::begin(kIntraOnly), std::end(kIntraOnly),
                     [&](const char* c) { return code == c; });
}

// Motion JPEG (each frame a JPEG), whose decoder conceals a frame's desynchronised data silently.
bool MotionJpegCodec(double fourcc_property) {
  const std::string code = FourCcText(fourcc_property);
  return code == "MJPG" || code == "mjpg" || code == "AVRn" || code == "MJPA";
}

// A video file. Two kinds of damage FFmpeg does not report through OpenCV are caught here:
// - a frame its decoder logged an error for (a corrupt JPEG, a broken slice) or its concealing
//   of damage, or marked as concealed (LibavVideoReader, or DecodeProbe), is damaged: it gets no
//   row (its garbage would be measured as if it were real), later frames keep their numbers,
//   and the end of the run reports how many there were. Intra-only decoders conceal damage
//   without a mark: a Motion JPEG frame whose coded data does not fill its picture
//   (io/jpeg_scan.h, checked by the probe), and an intra-only frame with a band of rows from its
//   edge whose colours all moved at once (io/damaged_band.h), are damaged too;
// - a file cut short: the last frame decoded before the cut may be half a frame or a stale copy
//   of an earlier one (FFmpeg's frame threads hand back an old buffer when the last packet is
//   cut), so frames are read one ahead, and when the stream ends short of the header's frame
//   count that last frame is dropped with the error.
class VideoFileSource : public FrameSource {
 public:
  explicit VideoFileSource(const std::string& path) : path_(path) {
    if (!fs::exists(path)) throw InputError(path + ": no such video file");
    // A pipe or a device can be read only once, and the file is read more than once (its key
    // frames, the decoder's damage marks): a second reader would take frames from the first.
    std::error_code ignored;
    if (!fs::is_regular_file(path, ignored)) {
      throw InputError(path +
                       ": not a regular file (a pipe or a device); save the video to a file first, "
                       "or use --camera for a camera");
    }
    CaptureDecoderErrors();
    // A file whose container names a predicting codec by its tag (an H.264 MP4) is read by
    // LibavVideoReader (below) with the header's figures from it too, when they surely are
    // VideoCapture's: a VideoCapture opened only for them probed the stream and started a decoder
    // a second time (5 ms of CPU at 640x480, 20 ms at 1080p, ~3 MB; issue 45). Any other file
    // (the intra-only recordings, whose header alone was read here) goes the way it went.
    std::unique_ptr<LibavVideoReader> early_reader = std::make_unique<LibavVideoReader>(
        path, [](uint32_t tag) { return !IntraOnlyCodec(tag); });
    std::optional<LibavVideoReader::Header> header;
    if (early_reader->opened()) header = early_reader->unrotated_header();
    if (!header || IntraOnlyCodec(header->fourcc)) {
      early_reader.reset();
      header.reset();
      if (!capture_.open(path, cv::CAP_FFMPEG) || !capture_.isOpened()) {
        throw InputError(path + ": cannot open as a video (unsupported, truncated or corrupt file)");
      }
    }
    const double count = header ? header->frame_count : capture_.get(cv::CAP_PROP_FRAME_COUNT);
    if (count > 0) frame_count_ = static_cast<int64_t>(count);
    const double fps = header ? header->fps : capture_.get(cv::CAP_PROP_FPS);
    if (fps > 0 && fps < 100000) fps_ = fps;
    const double fourcc = header ? header->fourcc : capture_.get(cv::CAP_PROP_FOURCC);
    const bool intra_only = IntraOnlyCodec(fourcc);
    key_frames_ = std::make_unique<KeyFrameIndex>(path, intra_only);
    // OpenCV gives FFmpeg's decoder one thread per processor (4.6's API does not say how many).
    if (!intra_only) {
      decoder_lag_frames_ =
          std::clamp<int64_t>(int64_t{std::thread::hardware_concurrency()} - 1, 0, 15);
      // A predicting codec's frames need the decoder's own word on damage (see the class
      // comment): read by LibavVideoReader, which gives VideoCapture's frames (the header's
      // figures above stay OpenCV's) and, from the same decoding, its marks and messages. A file
      // OpenCV would rotate (metadata), or one the reader cannot open, is read by VideoCapture,
      // its marks from a second decoding (DecodeProbe).
      if (early_reader) {
        reader_ = std::move(early_reader);
      } else if (capture_.get(cv::CAP_PROP_ORIENTATION_META) == 0.0) {
        reader_ = std::make_unique<LibavVideoReader>(path);
        if (reader_->opened()) {
          capture_.release();
        } else {
          reader_.reset();
        }
      }
      if (!reader_) probe_ = std::make_unique<DecodeProbe>(path);
    }
    if (intra_only) damaged_band_.emplace();
    if (MotionJpegCodec(fourcc)) {
      // Its packets' data checked, not decoded (io/jpeg_scan.h): a damaged frame is its own.
      probe_ = std::make_unique<DecodeProbe>(path);
      concealed_damage_ = "a JPEG whose coded data does not fill its picture";
    }
  }

  bool read(Frame& frame) override {
    if (!started_) {
      started_ = true;
      have_current_ = decode(current_);
    }
    if (pending_error_) throw InputError(*pending_error_);
    if (!have_current_) {
      report_end();
      return false;
    }
    try {
      have_next_ = decode(next_);
    } catch (const InputError& e) {
      // A broken frame further on: this one is good and still gets its row; the error comes next.
      pending_error_ = e.what();
      have_next_ = false;
      return emit(frame);
    }
    if (!have_next_ && frame_count_ && decoded_ < *frame_count_ && !last_decoded_left_out_) {
      // Truncated: `current_` was decoded from the last, cut packet (unless the frame decoded
      // from it was left out as damaged already: then the error comes after this good one).
      throw InputError(path_ + ": only " + std::to_string(decoded_) + " of the " +
                       std::to_string(*frame_count_) +
                       " frames its header lists could be decoded (truncated or corrupt file); "
                       "frame " + std::to_string(current_.index) +
                       ", the last one before the damage, is left out" + damage_summary("; also"));
    }
    return emit(frame);
  }

  std::string description() const override { return "video " + path_; }
  std::vector<std::string> files() const override { return {path_}; }
  std::optional<int64_t> frame_count() const override { return frame_count_; }
  std::optional<double> fps() const override { return fps_; }

  bool seek_to(int64_t position) override {
    // Damaged frames get no row, so positions no longer equal the decoder's frame numbers.
    if (position < 0 || damaged_ > 0 || pending_error_) return false;
    if (frame_count_ && position >= *frame_count_) return false;
    // OpenCV's FFmpeg seek: av_seek_frame to a key frame at or before the target, then decoding
    // forward to it by the frames' timestamps (exact for the intra-only codecs the recordings use,
    // HuffYUV, FFV1, MJPG, in AVI and MKV: FrameSourceTest.SeekToShowsTheFrameReadingForwardShows).
    // LibavVideoReader seeks by the same steps (libav_video_reader.h), and its marks go on.
    if (reader_) {
      reader_->seek(position);
    } else if (!capture_.set(cv::CAP_PROP_POS_FRAMES, static_cast<double>(position))) {
      return false;
    }
    // The probe decodes from the start: a seek would wait for it to get there. From here on the
    // decoder's log alone tells damage.
    probe_.reset();
    if (damaged_band_) damaged_band_->reset();
    started_ = false;
    have_current_ = have_next_ = false;
    next_index_ = position;
    decoded_ = position;  // As if read up to here: the truncation check counts from the start.
    last_time_s_ = -1.0;
    return true;
  }

 private:
  struct Decoded {
    cv::Mat image;
    int64_t index = 0;
    double time_s = 0.0;
  };

  bool emit(Frame& frame) {
    if (current_.image.type() == CV_8UC3) {
      // The decoded buffer goes to the caller and the caller's old one is decoded into next:
      // no copy of the frame (921 kB at VGA), as FFmpeg's BGR output already is the frame.
      cv::swap(current_.image, frame.image);
    } else {
      ToBgr(current_.image, frame.image);
    }
    frame.index = current_.index;
    frame.time_s = current_.time_s;
    frame.key_frame = key_frames_->is_key(current_.index);
    std::swap(current_, next_);
    have_current_ = have_next_;
    return true;
  }

  // The next frame the decoder returns into `image`; false when there is none.
  bool read_frame(cv::Mat& image) {
    if (reader_) return reader_->read(image);
    return capture_.read(image) && !image.empty();
  }

  // Decodes the next undamaged frame into `out`; false at the end of the stream.
  bool decode(Decoded& out) {
    while (true) {
      const uint64_t errors_before = DecoderErrorCount();
      if (!read_frame(out.image)) {
        // Tell "the stream ended" from "a frame failed to decode": a decoder that can still grab
        // a later frame skipped a broken one.
        bool later_frame_decodes = false;
        for (int attempt = 0; attempt < 3 && !later_frame_decodes; ++attempt) {
          later_frame_decodes = reader_ ? reader_->grab() : capture_.grab();
        }
        if (later_frame_decodes) {
          throw InputError(path_ + ": frame " + std::to_string(next_index_) +
                           " failed to decode (corrupt video)" + damage_summary("; also"));
        }
        return false;
      }
      ++decoded_;
      const int64_t index = next_index_++;
      const bool concealed =
          reader_ ? reader_->concealed() : probe_ && probe_->concealed(index).value_or(false);
      const bool reported = DecoderErrorCount() != errors_before || concealed;
      // Told of every frame, so that the next one is compared with this one.
      const bool band = damaged_band_ && damaged_band_->damaged(out.image, reported);
      if (concealed) damage_kind_ = concealed_damage_;
      if (band && !reported) damage_kind_ = kDamagedBand;
      if (reported || band) {
        if (damaged_ == 0) first_damaged_ = index;
        ++damaged_;
        // In a codec that predicts frames from earlier ones (MPEG-4, H.264), the damage goes on
        // in every frame decoded from the damaged one, silently, until the next key frame; and
        // its frame threads decode up to decoder_lag_frames_ frames past the one read() returns
        // (and B-frames' references before them: the reader knows how many) and complain from
        // there, so the damaged frame is this one or one of those.
        const int64_t lag = reader_ ? reader_->frames_decoded_ahead() : decoder_lag_frames_;
        suspect_until_ = std::max(suspect_until_, key_frames_->next_after(index + lag));
        last_decoded_left_out_ = true;
        continue;
      }
      if (index < suspect_until_) {
        ++predicted_from_damaged_;
        last_decoded_left_out_ = true;
        continue;
      }
      last_decoded_left_out_ = false;
      out.index = index;
      const double pos_ms =
          reader_ ? reader_->position_ms() : capture_.get(cv::CAP_PROP_POS_MSEC);
      // Container timestamps when the demuxer has them; the nominal rate otherwise.
      out.time_s = (pos_ms > 0 || index == 0) ? pos_ms / 1000.0 : index / fps_.value_or(30.0);
      if (index > 0 && out.time_s <= last_time_s_) out.time_s = index / fps_.value_or(30.0);
      last_time_s_ = out.time_s;
      return true;
    }
  }

  // "<lead> 3 damaged frames left out (first: frame 16, decoder: mjpeg: ...)", or "".
  std::string damage_summary(const std::string& lead) const {
    if (damaged_ == 0) return "";
    const std::string last_error = LastDecoderError();
    std::string text = lead + " " + std::to_string(damaged_) + " frame" +
                       (damaged_ == 1 ? "" : "s") + " the decoder found damaged " +
                       (damaged_ == 1 ? "is" : "are") + " left out (first: frame " +
                       std::to_string(first_damaged_) + ", decoder: " +
                       (last_error.empty() ? damage_kind_ : last_error) + ")";
    if (predicted_from_damaged_ > 0) {
      text += ", and " + std::to_string(predicted_from_damaged_) +
              " decoded from them up to the next key frame";
    }
    return text;
  }

  // At the end of the stream: damage and a shortfall are errors, reported after every good row.
  void report_end() const {
    if (frame_count_ && decoded_ < *frame_count_) {
      throw InputError(path_ + ": only " + std::to_string(decoded_) + " of the " +
                       std::to_string(*frame_count_) +
                       " frames its header lists could be decoded (truncated or corrupt file)" +
                       damage_summary(";"));
    }
    if (damaged_ > 0) throw InputError(path_ + ":" + damage_summary(""));
  }

  std::string path_;
  cv::VideoCapture capture_;  // Released when reader_ reads the frames.
  // A predicting codec's frames, with the decoder's damage marks (io/libav_video_reader.h).
  std::unique_ptr<LibavVideoReader> reader_;
  Decoded current_, next_;  // One frame ahead (see the class comment); swapped, never copied.
  bool started_ = false, have_current_ = false, have_next_ = false;
  std::optional<std::string> pending_error_;  // Thrown by the read after the frame before it.
  int64_t next_index_ = 0;  // Index of the next frame the decoder returns.
  int64_t decoded_ = 0;     // Frames the decoder returned, damaged ones included.
  int64_t damaged_ = 0;
  int64_t first_damaged_ = 0;
  bool last_decoded_left_out_ = false;  // The last frame the decoder returned was damaged.
  std::unique_ptr<KeyFrameIndex> key_frames_;
  // Which frames the decoder concealed damage in (Motion JPEG, and predicting codecs that
  // reader_ does not read; none after a seek).
  std::unique_ptr<DecodeProbe> probe_;
  // Intra-only codecs: damage concealed from one row on (io/damaged_band.h).
  std::optional<DamagedBand> damaged_band_;
  // What the probe's mark means, and the kind of concealed damage seen last, for the report.
  std::string concealed_damage_ = "concealed damage";
  std::string damage_kind_;
  static constexpr const char* kDamagedBand =
      "a band of rows from the frame's edge whose colours all moved at once (concealed damage)";
  // How many frames a predicting codec's frame threads may be decoding past the one read()
  // returns (0 for intra-only codecs, whose complaints this source takes as the frame's own, as
  // FramesTheDecoderFoundDamagedAreLeftOutAndReported checks for MJPG).
  int64_t decoder_lag_frames_ = 0;
  int64_t suspect_until_ = 0;           // Frames before this index follow a damaged one.
  int64_t predicted_from_damaged_ = 0;  // Left out for that reason.
  double last_time_s_ = -1.0;
  std::optional<int64_t> frame_count_;
  std::optional<double> fps_;
};

bool IsImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  static const char* kExtensions[] = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm",
                                      ".pgm", ".webp"};
  return std::any_of(std::begin(kExtensions), std::end(kExtensions),
                     [&](const char* e) { return ext == e; });
}

// A gap in the numbering is not silent: rows keep the files' numbers (so frame 7 is still the
// seventh file's number after a missing one), and the source says which numbers were missing.
std::optional<std::string> DescribeGaps(const std::vector<NumberedFile>& files) {
  const std::optional<std::string> gaps = DescribeNumberingGaps(files);
  if (!gaps) return std::nullopt;
  return *gaps + "; rows keep each file's number in `frame`";
}

class ImageSequenceSource : public FrameSource {
 public:
  ImageSequenceSource(std::vector<NumberedFile> files, std::string description, double fps)
      : files_(std::move(files)), description_(std::move(description)), fps_(fps),
        gaps_(DescribeGaps(files_)) {}

  bool read(Frame& frame) override {
    if (next_ >= files_.size()) return false;
    const NumberedFile& file = files_[next_];
    decoded_ = cv::imread(file.path, cv::IMREAD_UNCHANGED);
    if (decoded_.empty()) {
      throw InputError(file.path + ": frame " + std::to_string(file.index) +
                       " cannot be read as an image (corrupt or not an image)");
    }
    ToBgr(decoded_, frame.image);
    frame.index = file.index;
    // Time counts from the first file, at the nominal rate, so gaps keep their duration.
    frame.time_s = static_cast<double>(file.index - files_.front().index) / fps_;
    ++next_;
    return true;
  }

  std::string description() const override { return description_; }
  std::optional<int64_t> frame_count() const override {
    return static_cast<int64_t>(files_.size());
  }
  std::optional<double> fps() const override { return fps_; }
  std::optional<std::string> note() const override { return gaps_; }
  std::vector<std::string> files() const override {
    std::vector<std::string> paths;
    for (const NumberedFile& file : files_) paths.push_back(file.path);
    return paths;
  }
  bool seek_to(int64_t position) override {
    if (position < 0 || position > static_cast<int64_t>(files_.size())) return false;
    next_ = static_cast<size_t>(position);
    return true;
  }

 private:
  std::vector<NumberedFile> files_;
  std::string description_;
  double fps_;
  std::optional<std::string> gaps_;
  cv::Mat decoded_;
  size_t next_ = 0;
};

// A folder's files in name order. When every name is one prefix + a number + one suffix
// (shot_0001.png ...), rows carry that number (a missing file is a gap, not a renumbering);
// otherwise they are numbered 0, 1, 2 ... in name order.
std::unique_ptr<FrameSource> OpenFolder(const std::string& folder, double fps) {
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && IsImageFile(entry.path())) {
      names.push_back(entry.path().filename().string());
    }
  }
  if (names.empty()) throw InputError(folder + ": folder holds no image files");
  std::sort(names.begin(), names.end());
  // The number is the last run of digits of the first name; the rest must match in every name.
  std::optional<SequencePattern> numbering;
  const std::string& first = names.front();
  const size_t digits_end = first.find_last_of("0123456789");
  if (digits_end != std::string::npos) {
    size_t digits_start = digits_end;
    while (digits_start > 0 && std::isdigit(static_cast<unsigned char>(first[digits_start - 1]))) {
      --digits_start;
    }
    const size_t digit_count = digits_end + 1 - digits_start;
    SequencePattern padded{first.substr(0, digits_start), first.substr(digits_end + 1),
                           static_cast<int>(digit_count)};
    SequencePattern plain{padded.prefix, padded.suffix, 0};
    for (const SequencePattern& candidate : {padded, plain}) {
      if (std::all_of(names.begin(), names.end(),
                      [&](const std::string& n) { return candidate.Match(n).has_value(); })) {
        numbering = candidate;
        break;
      }
    }
  }
  std::vector<NumberedFile> files;
  for (size_t i = 0; i < names.size(); ++i) {
    files.push_back({numbering ? *numbering->Match(names[i]) : static_cast<int64_t>(i),
                     (fs::path(folder) / names[i]).string()});
  }
  std::sort(files.begin(), files.end(),
            [](const NumberedFile& a, const NumberedFile& b) { return a.index < b.index; });
  return std::make_unique<ImageSequenceSource>(std::move(files), "images " + folder, fps);
}

// Every file the pattern names, in number order, wherever the numbering starts or has gaps.
std::unique_ptr<FrameSource> OpenPattern(const std::string& pattern, double fps) {
  std::vector<NumberedFile> files = ListSequenceFiles(ParseSequencePattern(pattern));
  if (files.empty()) throw InputError(pattern + ": no file matches this pattern");
  return std::make_unique<ImageSequenceSource>(std::move(files), "images " + pattern, fps);
}

// Whether two pictures are the same bytes; stops at the first row that differs.
bool SamePicture(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty() || a.size() != b.size() || a.type() != b.type()) return false;
  const size_t row_bytes = static_cast<size_t>(a.cols) * a.elemSize();
  for (int y = 0; y < a.rows; ++y) {
    if (std::memcmp(a.ptr(y), b.ptr(y), row_bytes) != 0) return false;
  }
  return true;
}

class CameraSource : public FrameSource {
 public:
  CameraSource(int index, const CameraSettings& settings, CameraSettingsReport* report)
      : index_(index) {
    if (!capture_.open(index, cv::CAP_V4L2) || !capture_.isOpened()) {
      throw InputError("camera " + std::to_string(index) +
                       ": cannot open (is it plugged in? try `softsight cameras`)");
    }
    // Before the first frame: the settings (camera_settings.h), read back and reported.
    OpenCvCaptureBackend backend(capture_);
    CameraSettingsReport applied = ApplyCameraSettings(backend, settings, description());
    note_ = applied.summary;
    for (const std::string& line : applied.refused) note_ += "\n" + line;
    if (report) *report = std::move(applied);
    start_ = std::chrono::steady_clock::now();
  }

  bool read(Frame& frame) override {
    if (!capture_.read(decoded_) || decoded_.empty()) {
      throw InputError("camera " + std::to_string(index_) + ": frame " +
                       std::to_string(next_index_) + " could not be captured (unplugged?)");
    }
    // Capture time on this machine's steady clock: two cameras read by one program share it
    // (pairing by time, stereo_input.h).
    frame.captured = std::chrono::steady_clock::now();
    ToBgr(decoded_, frame.image);
    // A sensor's noise makes every real picture differ from the last somewhere in its first rows
    // (the comparison stops there); the very same picture is a driver handing out its last
    // buffer again: no new measurement (Frame::repeated).
    frame.repeated = SamePicture(last_, frame.image);
    frame.image.copyTo(last_);
    frame.index = next_index_++;
    frame.time_s = std::chrono::duration<double>(frame.captured - start_).count();
    return true;
  }

  std::string description() const override { return "camera " + std::to_string(index_); }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override {
    const double fps = capture_.get(cv::CAP_PROP_FPS);
    return fps > 0 ? std::optional<double>(fps) : std::nullopt;
  }
  bool is_live() const override { return true; }
  // What the camera accepted of its settings, and what it refused (for the run's summary).
  std::optional<std::string> note() const override { return note_; }

 private:
  int index_;
  std::string note_;
  cv::VideoCapture capture_;
  cv::Mat decoded_;
  cv::Mat last_;  // The last picture, to tell a repeated one.
  int64_t next_index_ = 0;
  std::chrono::steady_clock::time_point start_;
};

// Any rendered scene (SyntheticScene, PlateScene) as a source.
template <class Scene>
class SyntheticSource : public FrameSource {
 public:
  template <class Options>
  SyntheticSource(const Options& scene, const NoiseOptions& noise, std::string description)
      : scene_(scene, noise), description_(std::move(description)) {}

  bool read(Frame& frame) override {
    if (next_index_ >= scene_.frame_count()) return false;
    const SceneTruth truth = scene_.render(next_index_, frame.image);
    frame.index = next_index_++;
    frame.time_s = truth.time_s;
    return true;
  }
  std::string description() const override { return description_; }
  std::optional<int64_t> frame_count() const override { return scene_.frame_count(); }
  std::optional<double> fps() const override { return scene_.options().fps; }
  bool seek_to(int64_t position) override {
    if (position < 0 || position > scene_.frame_count()) return false;
    next_index_ = static_cast<int>(position);
    return true;
  }

 private:
  Scene scene_;
  std::string description_;
  int next_index_ = 0;
};

}  // namespace

bool IsGrayscale(const cv::Mat& frame_bgr) {
  CV_Assert(frame_bgr.type() == CV_8UC3);
  for (int y = 0; y < frame_bgr.rows; ++y) {
    const cv::Vec3b* row = frame_bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < frame_bgr.cols; ++x) {
      // Compression may leave the chroma a level or two off pure gray.
      if (std::abs(row[x][0] - row[x][1]) > 2 || std::abs(row[x][1] - row[x][2]) > 2) return false;
    }
  }
  return true;
}

std::unique_ptr<FrameSource> OpenFrameSource(const FrameSourceSpec& spec) {
  if (spec.camera && spec.camera->aravis_device) {
    return OpenAravisCamera(*spec.camera, spec.capture, spec.capture_report);
  }
  if (spec.camera) {
    return std::make_unique<CameraSource>(spec.camera->index, spec.capture, spec.capture_report);
  }
  const std::string& input = spec.input;
  if (input.empty()) {
    throw InputError("no input given (use --input VIDEO|FOLDER|PATTERN or --camera N)");
  }
  if (!(std::isfinite(spec.sequence_fps) && spec.sequence_fps > 0)) {
    throw InputError("--fps " + std::to_string(spec.sequence_fps) + ": must be a positive number");
  }
  if (input.rfind(kSyntheticPrefix, 0) == 0) {
    const BuiltinSceneOptions scene =
        ParseBuiltinScene(input.substr(std::string(kSyntheticPrefix).size()));
    return std::visit([](const auto& o) { return OpenSyntheticSource(o, NoiseOptions{}); }, scene);
  }
  if (fs::is_directory(input)) return OpenFolder(input, spec.sequence_fps);
  // A file whose name holds a '%' is still that file; otherwise '%' makes a numbered pattern.
  if (!fs::exists(input)) {
    if (input.find('%') != std::string::npos) return OpenPattern(input, spec.sequence_fps);
    throw InputError(input + ": no such file or folder");
  }
  if (IsImageFile(input)) {
    return std::make_unique<ImageSequenceSource>(std::vector<NumberedFile>{{0, input}},
                                                 "image " + input, spec.sequence_fps);
  }
  return std::make_unique<VideoFileSource>(input);
}

std::unique_ptr<FrameSource> OpenSyntheticSource(const SceneOptions& scene,
                                                 const NoiseOptions& noise) {
  std::string description = std::string("synthetic scene ") + SceneKindName(scene.kind);
  if (scene.background == BackgroundKind::kBench) description += " on the textured bench";
  return std::make_unique<SyntheticSource<SyntheticScene>>(scene, noise, std::move(description));
}

std::unique_ptr<FrameSource> OpenSyntheticSource(const PlateSceneOptions& scene,
                                                 const NoiseOptions& noise) {
  return std::make_unique<SyntheticSource<PlateScene>>(scene, noise, "synthetic scene plate");
}

}  // namespace softsight
