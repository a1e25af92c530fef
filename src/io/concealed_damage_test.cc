// The checks for damage an intra-only decoder conceals (issue 44, D9 and D10): a JPEG whose
// entropy-coded data does not fill its picture (io/jpeg_scan.h), and a band of rows from the
// frame's edge whose colours all moved at once (io/damaged_band.h).
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/damaged_band.h"
#include "io/jpeg_scan.h"

namespace softsight {
namespace {

// A textured picture with a few coloured discs, as a camera's frame of the rig.
cv::Mat Scene(int shift = 0) {
  cv::Mat image(240, 320, CV_8UC3);
  cv::RNG random(7);
  random.fill(image, cv::RNG::UNIFORM, cv::Scalar::all(60), cv::Scalar::all(120));
  cv::GaussianBlur(image, image, {5, 5}, 1.5);
  cv::circle(image, {80 + shift, 60}, 12, {0, 0, 230}, -1);
  cv::circle(image, {160 + shift, 120}, 12, {0, 200, 0}, -1);
  cv::circle(image, {240 + shift, 180}, 12, {230, 0, 0}, -1);
  return image;
}

std::vector<uint8_t> Jpeg(const cv::Mat& image, std::vector<int> params = {}) {
  std::vector<uint8_t> data;
  EXPECT_TRUE(cv::imencode(".jpg", image, data, params));
  return data;
}

// Where the entropy-coded data of a one-scan JPEG begins: after the SOS segment.
size_t ScanStart(const std::vector<uint8_t>& jpeg) {
  for (size_t i = 2; i + 3 < jpeg.size(); ++i) {
    if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xDA) return i + 2 + ((jpeg[i + 2] << 8) | jpeg[i + 3]);
  }
  return 0;
}

TEST(JpegScanCheck, WholePicturesPass) {
  JpegScanCheck check;
  for (const int quality : {50, 95}) {
    const std::vector<uint8_t> jpeg = Jpeg(Scene(), {cv::IMWRITE_JPEG_QUALITY, quality});
    EXPECT_EQ(check.check(jpeg.data(), jpeg.size()), JpegScanCheck::Verdict::kWhole) << quality;
  }
  // With restart markers every 4 MCUs, and of one component (an MCU is one block).
  const std::vector<uint8_t> restarts = Jpeg(Scene(), {cv::IMWRITE_JPEG_RST_INTERVAL, 4});
  EXPECT_EQ(check.check(restarts.data(), restarts.size()), JpegScanCheck::Verdict::kWhole);
  cv::Mat gray;
  cv::cvtColor(Scene(), gray, cv::COLOR_BGR2GRAY);
  const std::vector<uint8_t> one_component = Jpeg(gray);
  EXPECT_EQ(check.check(one_component.data(), one_component.size()),
            JpegScanCheck::Verdict::kWhole);
}

// A flipped bit that changes a code's length puts the decoder out of step: a few codes later it
// is back in step, but the MCUs end away from the data's end. (A flip that keeps every code's
// length, in a value, is not seen: it changes levels, it does not move anything.)
TEST(JpegScanCheck, FlipsThatPutTheCodesOutOfStepAreFound) {
  const std::vector<uint8_t> clean = Jpeg(Scene());
  const size_t start = ScanStart(clean);
  ASSERT_GT(start, 0u);
  JpegScanCheck check;
  int found = 0, tried = 0;
  for (size_t at = start + 40; at + 40 < clean.size(); at += 97) {
    if (clean[at] == 0xFF || clean[at - 1] == 0xFF) continue;  // Leave the byte stuffing alone.
    std::vector<uint8_t> flipped = clean;
    flipped[at] ^= 0x10;
    if (flipped[at] == 0xFF) continue;
    ++tried;
    found += check.check(flipped.data(), flipped.size()) == JpegScanCheck::Verdict::kDamaged;
  }
  ASSERT_GT(tried, 20);
  EXPECT_GT(found, tried / 10);
  // A byte less in the middle of the data: out of step by 8 bits to the end.
  std::vector<uint8_t> short_by_a_byte = clean;
  size_t middle = (start + clean.size()) / 2;
  while (clean[middle] == 0xFF || clean[middle - 1] == 0xFF) ++middle;
  short_by_a_byte.erase(short_by_a_byte.begin() + static_cast<std::ptrdiff_t>(middle));
  EXPECT_EQ(check.check(short_by_a_byte.data(), short_by_a_byte.size()),
            JpegScanCheck::Verdict::kDamaged);
  // A Huffman table with more codes of a length than that length has room for (damaged
  // counts, the total kept): one code more of 2 bits, one less of the longest.
  std::vector<uint8_t> bad_table = clean;
  for (size_t i = 2; i + 21 < start; ++i) {
    if (bad_table[i] == 0xFF && bad_table[i + 1] == 0xC4) {
      uint8_t* counts = &bad_table[i + 4];  // counts[l]: codes of l bits (after Tc/Th).
      int longest = 16;
      while (counts[longest] == 0) --longest;
      ++counts[2];
      --counts[longest];
      break;
    }
  }
  EXPECT_EQ(check.check(bad_table.data(), bad_table.size()), JpegScanCheck::Verdict::kDamaged);
  // A scan header that does not fit its frame (FFmpeg skips the scan and hands back the frame
  // before's picture): more components than the frame has.
  std::vector<uint8_t> bad_header = clean;
  bad_header[start - 2 * 3 - 4] = 5;  // The SOS's component count (3 components, 6 bytes + 3).
  EXPECT_EQ(check.check(bad_header.data(), bad_header.size()), JpegScanCheck::Verdict::kDamaged);
  // Restart markers numbered out of order, or one missing.
  const std::vector<uint8_t> restarts = Jpeg(Scene(), {cv::IMWRITE_JPEG_RST_INTERVAL, 4});
  for (size_t i = ScanStart(restarts); i + 1 < restarts.size(); ++i) {
    if (restarts[i] == 0xFF && restarts[i + 1] == 0xD3) {
      std::vector<uint8_t> misnumbered = restarts;
      misnumbered[i + 1] = 0xD4;
      EXPECT_EQ(check.check(misnumbered.data(), misnumbered.size()),
                JpegScanCheck::Verdict::kDamaged);
      break;
    }
  }
}

// OpenCV's own MJPEG writer cuts the last bytes off some frames (its 32-bit flush); decoders fill
// them with zeros, in the corner MCU alone. Data running out earlier is damage.
TEST(JpegScanCheck, DataCutShortInTheLastMcuOnlyPasses) {
  const std::vector<uint8_t> clean = Jpeg(Scene());
  ASSERT_EQ(clean[clean.size() - 2], 0xFF);  // EOI.
  std::vector<uint8_t> cut = clean;
  cut.erase(cut.end() - 4, cut.end() - 2);
  JpegScanCheck check;
  EXPECT_EQ(check.check(cut.data(), cut.size()), JpegScanCheck::Verdict::kWhole);
  std::vector<uint8_t> half = clean;
  half.erase(half.begin() + static_cast<std::ptrdiff_t>((ScanStart(clean) + clean.size()) / 2),
             half.end() - 2);
  EXPECT_EQ(check.check(half.data(), half.size()), JpegScanCheck::Verdict::kDamaged);
}

TEST(JpegScanCheck, WhatItCannotWalkIsUnchecked) {
  JpegScanCheck check;
  const std::vector<uint8_t> progressive = Jpeg(Scene(), {cv::IMWRITE_JPEG_PROGRESSIVE, 1});
  EXPECT_EQ(check.check(progressive.data(), progressive.size()), JpegScanCheck::Verdict::kUnchecked);
  const std::vector<uint8_t> png = [] {
    std::vector<uint8_t> data;
    cv::imencode(".png", Scene(), data);
    return data;
  }();
  EXPECT_EQ(check.check(png.data(), png.size()), JpegScanCheck::Verdict::kUnchecked);
  EXPECT_EQ(check.check(nullptr, 0), JpegScanCheck::Verdict::kUnchecked);
}

// The pictures' check: a band from an edge whose colours all moved against the frame before.
TEST(DamagedBand, ABandOfRowsOffsetFromTheEdgeIsDamageAndMotionOrLightIsNot) {
  DamagedBand band;
  EXPECT_FALSE(band.damaged(Scene(0)));  // The first frame has nothing to compare with.
  EXPECT_FALSE(band.damaged(Scene(2))) << "the markers moved";
  EXPECT_FALSE(band.damaged(Scene(4)));
  // The rows from 150 down, 6 levels darker in blue: a HuffYUV residual gone wrong (decoded
  // bottom-up, so it is the top that goes wrong there; MJPG, the bottom).
  cv::Mat damaged = Scene(6);
  damaged.rowRange(150, 240) -= cv::Scalar(6, 0, 0);
  EXPECT_TRUE(band.damaged(damaged));
  // The next frame differs from the damaged one by the same band: it is compared with the last
  // clean frame too, and is not damaged.
  EXPECT_FALSE(band.damaged(Scene(8)));
  cv::Mat top = Scene(10);
  top.rowRange(0, 70) += cv::Scalar(0, 0, 9);
  EXPECT_TRUE(band.damaged(top));
  EXPECT_FALSE(band.damaged(Scene(12)));
  // The exposure: all rows brighter at once.
  cv::Mat brighter = Scene(14) + cv::Scalar::all(8);
  EXPECT_FALSE(band.damaged(brighter));
  // A rolling shutter under mains light: the gain varies smoothly along the rows.
  for (int frame = 0; frame < 6; ++frame) {
    cv::Mat flicker = Scene(14);
    for (int y = 0; y < flicker.rows; ++y) {
      const double gain = 1.0 + 0.15 * std::sin(y / 25.0 + 1.3 * frame);
      flicker.row(y).convertTo(flicker.row(y), -1, gain);
    }
    EXPECT_FALSE(band.damaged(flicker)) << "flicker frame " << frame;
  }
}

TEST(DamagedBand, AFrameTheDecoderReportedIsNotComparedWith) {
  DamagedBand band;
  EXPECT_FALSE(band.damaged(Scene(0)));
  cv::Mat garbage(240, 320, CV_8UC3);
  cv::randu(garbage, 0, 256);
  EXPECT_TRUE(band.damaged(garbage, /*known_damaged=*/true));
  EXPECT_FALSE(band.damaged(Scene(2))) << "compared with the frame before the garbage";
  EXPECT_FALSE(band.damaged(cv::Mat(240, 320, CV_8UC1, cv::Scalar(0)))) << "not BGR: unchecked";
  // A damaged first frame is no frame to compare with.
  DamagedBand fresh;
  EXPECT_TRUE(fresh.damaged(garbage, /*known_damaged=*/true));
  EXPECT_FALSE(fresh.damaged(Scene(0)));
  cv::Mat top = Scene(2);
  top.rowRange(0, 70) += cv::Scalar(0, 0, 9);
  EXPECT_TRUE(fresh.damaged(top)) << "compared with the first clean frame";
}

}  // namespace
}  // namespace softsight
