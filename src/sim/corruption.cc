#include "sim/corruption.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"

namespace softsight {

void CorruptFrame(CorruptionKind kind, uint64_t seed, const cv::Mat& other_frame, cv::Mat& image,
                  const cv::Rect& block_px) {
  if (image.empty()) throw InputError("corrupt frame: the image is empty");
  CV_Assert(image.depth() == CV_8U);
  cv::RNG rng(seed * 0xA24BAED4963EE407ull + 0x9FB21C651E98DF25ull);
  const int w = image.cols, h = image.rows;
  switch (kind) {
    case CorruptionKind::kGarbageBlock: {
      cv::Rect block = block_px;
      if (block.empty()) {
        const int bw = std::max(1, w / 2), bh = std::max(1, h / 2);
        // y before x, as GCC evaluated the arguments when they were both draws: the frames
        // must not depend on the compiler, which C++ leaves free to order a call's arguments.
        const int y = rng.uniform(0, h - bh + 1);
        block = cv::Rect(rng.uniform(0, w - bw + 1), y, bw, bh);
      }
      block &= cv::Rect(0, 0, w, h);
      if (!block.empty()) {
        cv::Mat target = image(block);
        rng.fill(target, cv::RNG::UNIFORM, 0, 256);
      }
      break;
    }
    case CorruptionKind::kOtherVideo: {
      if (other_frame.empty()) {
        throw InputError("corrupt frame: 'other video' needs a frame of another video");
      }
      cv::Mat other = other_frame;
      if (other.channels() != image.channels()) {
        cv::Mat converted;
        cv::cvtColor(other, converted, image.channels() == 1 ? cv::COLOR_BGR2GRAY : cv::COLOR_GRAY2BGR);
        other = converted;
      }
      if (other.size() != image.size()) {
        cv::Mat resized;
        cv::resize(other, resized, image.size(), 0, 0, cv::INTER_AREA);
        other = resized;
      }
      other.copyTo(image);
      break;
    }
    case CorruptionKind::kShiftedBand: {
      const int first = rng.uniform(0, std::max(1, h - h / 8));
      const int rows = std::min(h - first, rng.uniform(std::max(1, h / 8), std::max(2, h / 2 + 1)));
      const int shift = std::max(1, static_cast<int>(w * rng.uniform(0.05, 0.3)));
      const double level = rng.uniform(0.8, 1.2);
      cv::Mat band = image.rowRange(first, first + rows);
      cv::Mat shifted(band.size(), band.type());
      // Row y keeps columns [0, w - shift) at [shift, w) and wraps the rest to the front.
      band.colRange(0, w - shift).copyTo(shifted.colRange(shift, w));
      band.colRange(w - shift, w).copyTo(shifted.colRange(0, shift));
      shifted.convertTo(band, -1, level);
      break;
    }
  }
}

const char* CorruptionKindName(CorruptionKind kind) {
  switch (kind) {
    case CorruptionKind::kGarbageBlock: return "garbage_block";
    case CorruptionKind::kOtherVideo: return "other_video";
    case CorruptionKind::kShiftedBand: return "shifted_band";
  }
  return "?";
}

}  // namespace softsight
