#include "io/damaged_band.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

namespace softsight {
namespace {

constexpr int kRowStep = 2, kColumnStep = 4;  // Sample spacing, px.
// A sample changed when it moved by this many levels: above the rounding of a lossless or
// high-quality picture, at the size of the smallest offsets that moved a marker.
constexpr int kChangedLevels = 2;
// A row is in the band when this share of its samples, more than moved the other way, moved one
// way in one colour: the actuator covers far less of a row, a damaged row nearly all of it.
constexpr float kBandShare = 0.5f;
// The rest of the frame matches: in half its rows at least, less than this share moved one way.
constexpr float kCleanShare = 0.2f;
// The band's offset (the median of its rows' median differences) is at least this: a lossy
// camera's or encoder's frames wobble by a level or two in their edge rows now and then (the
// two-carts clip as MJPG: its top 8 rows 2.3 levels brighter in one frame), and an offset that
// small moves no marker's edge.
constexpr float kLeastOffsetLevels = 3.0f;
// Rows (sampled) the band and the rest must each have, at least: one of them is too little to
// tell a band from a marker's edge, or the rest from a stray row.
constexpr int kLeastBandRows = 2, kLeastCleanRows = 4;
// Two bands of the same frame against two references end this close (sampled rows).
constexpr int kSameBandRows = 2;

float Median(std::vector<float>& values) {
  auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

void DamagedBand::sample(const cv::Mat& bgr, cv::Mat& out) const {
  out.create((bgr.rows + kRowStep - 1) / kRowStep, (bgr.cols + kColumnStep - 1) / kColumnStep,
             CV_8UC3);
  for (int y = 0; y < out.rows; ++y) {
    const uint8_t* from = bgr.ptr<uint8_t>(y * kRowStep);
    uint8_t* to = out.ptr<uint8_t>(y);
    for (int x = 0; x < out.cols; ++x) {
      const uint8_t* pixel = from + 3 * x * kColumnStep;
      to[3 * x] = pixel[0];
      to[3 * x + 1] = pixel[1];
      to[3 * x + 2] = pixel[2];
    }
  }
}

float DamagedBand::row_offset(const cv::Mat& now, const cv::Mat& before, int row, int colour) {
  const uint8_t* a = now.ptr<uint8_t>(row) + colour;
  const uint8_t* b = before.ptr<uint8_t>(row) + colour;
  scratch_.clear();
  for (int x = 0; x < now.cols; ++x) scratch_.push_back(float(a[3 * x]) - float(b[3 * x]));
  return Median(scratch_);
}

cv::Vec3f DamagedBand::row_share(const cv::Mat& now, const cv::Mat& before, int row) {
  const uint8_t* a = now.ptr<uint8_t>(row);
  const uint8_t* b = before.ptr<uint8_t>(row);
  int brighter[3] = {}, darker[3] = {};
  for (int i = 0; i < 3 * now.cols; i += 3) {
    for (int c = 0; c < 3; ++c) {
      const int d = int{a[i + c]} - int{b[i + c]};
      brighter[c] += d >= kChangedLevels;
      darker[c] += d <= -kChangedLevels;
    }
  }
  cv::Vec3f share;
  for (int c = 0; c < 3; ++c) {
    share[c] = static_cast<float>(brighter[c] - darker[c]) / static_cast<float>(now.cols);
  }
  return share;
}

int DamagedBand::band_against(const cv::Mat& now, const cv::Mat& before) {
  auto most = [](const cv::Vec3f& share) {
    return std::max({std::abs(share[0]), std::abs(share[1]), std::abs(share[2])});
  };
  const int rows = now.rows;
  // The row at the edge is the last one decoded, in the band whenever there is one: most frames
  // are judged by their first and last rows alone.
  if (most(row_share(now, before, 0)) < kBandShare &&
      most(row_share(now, before, rows - 1)) < kBandShare) {
    return 0;
  }
  shares_.resize(static_cast<size_t>(rows));
  for (int y = 0; y < rows; ++y) shares_[static_cast<size_t>(y)] = row_share(now, before, y);
  // From the top edge (a decoder that writes rows top-down: MJPG) and from the bottom (bottom-up:
  // HuffYUV's RGB, as AVI stores it).
  for (const bool from_top : {true, false}) {
    auto row_index = [&](int k) { return from_top ? k : rows - 1 - k; };
    int band = 0;
    while (band < rows && most(shares_[static_cast<size_t>(row_index(band))]) >= kBandShare) ++band;
    if (band < kLeastBandRows || rows - band < kLeastCleanRows) continue;
    int clean_rows = 0;
    for (int k = band; k < rows; ++k) {
      clean_rows += most(shares_[static_cast<size_t>(row_index(k))]) < kCleanShare;
    }
    if (2 * clean_rows < rows - band) continue;
    // The colour that moved most, and by how much: the median offset of (up to 9 of) the band's
    // rows, and that of its last whole row at the edge (the row at the edge itself may be
    // damaged only from where the damage began). A change of light along the rows grows from
    // nothing at its edge; damage has its whole offset right there.
    int colour = 0;
    float strongest = 0.0f;
    for (int c = 0; c < 3; ++c) {
      float total = 0.0f;
      for (int k = 0; k < band; ++k) total += shares_[static_cast<size_t>(row_index(k))][c];
      if (std::abs(total) > strongest) {
        strongest = std::abs(total);
        colour = c;
      }
    }
    offsets_.clear();
    const int stride = std::max(1, band / 9);
    for (int k = 0; k < band; k += stride) {
      offsets_.push_back(row_offset(now, before, row_index(k), colour));
    }
    const float band_offset = Median(offsets_);
    const float edge_offset = row_offset(now, before, row_index(band - 2), colour);
    if (std::abs(band_offset) >= kLeastOffsetLevels && edge_offset * band_offset > 0.0f &&
        std::abs(edge_offset) >= 0.5f * std::abs(band_offset)) {
      return from_top ? band : -band;
    }
  }
  return 0;
}

bool DamagedBand::damaged(const cv::Mat& bgr, bool known_damaged) {
  if (bgr.type() != CV_8UC3 || bgr.rows < 4 * kRowStep * (kLeastBandRows + kLeastCleanRows) ||
      bgr.cols < 4 * kColumnStep) {
    has_previous_ = false;
    return false;
  }
  sample(bgr, now_);
  if (known_damaged) {
    // Compared with by the next frame only as a damaged one (with no frame before it, not at all).
    if (has_previous_ && now_.size() == previous_.size()) {
      previous_damaged_ = true;
      cv::swap(previous_, now_);
    }
    return true;
  }
  if (!has_previous_ || now_.size() != previous_.size()) {
    now_.copyTo(previous_);
    now_.copyTo(clean_);
    has_previous_ = true;
    previous_damaged_ = false;
    return false;
  }
  // After a damaged frame its band shows against it too: only the last clean frame can tell,
  // by showing this frame's own band (the same rows, give or take a sample row or two).
  const int band = band_against(now_, previous_);
  bool damaged = band != 0;
  if (damaged && previous_damaged_) {
    const int against_clean = band_against(now_, clean_);
    damaged = against_clean != 0 && std::abs(against_clean - band) <= kSameBandRows;
  }
  if (!damaged) now_.copyTo(clean_);
  previous_damaged_ = damaged;
  cv::swap(previous_, now_);
  return damaged;
}

}  // namespace softsight
