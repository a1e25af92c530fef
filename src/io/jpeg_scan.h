// A flipped bit in a JPEG's entropy-coded data (Motion JPEG's frames) often leaves data FFmpeg's
// decoder still takes without a word: the Huffman codes resynchronise a few codes later, but
// one block's worth of coefficients too many or too few went by, so from that MCU on the picture
// is shifted by an MCU (16 px) and its DC levels are off (brighter or darker). What gives such a
// frame away is where its data ends: decoded bit by bit, an intact scan's last MCU ends within
// the last byte of its entropy-coded segment (and each restart interval ends at its RSTn
// marker), while a resynchronised one ends bytes early or runs past the end. FFmpeg does not
// look at that, so JpegScanCheck walks the Huffman codes of every block (no dequantising, no
// IDCT: a third of the time libjpeg-turbo takes to decode it) and counts the bits.
//
// What it cannot see: a flipped bit that keeps every code's length (a DC or AC value bit, or a
// code swapped for another of the same length) changes one block, or the DC level of the blocks
// after it, without moving anything; that is left to the pictures' checks
// (pipeline/frame_change.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace softsight {

class JpegScanCheck {
 public:
  enum class Verdict {
    kWhole,      // Every scan's codes fill its MCUs exactly.
    kDamaged,    // A code no table has, a block of more than 64 coefficients, a missing or
                 // misnumbered restart marker, or a scan whose MCUs end away from its data's end.
    kUnchecked,  // Not a baseline Huffman JPEG this knows how to walk (progressive, arithmetic
                 // coded, no Huffman tables given, components scanned separately).
  };

  // `jpeg`: one whole JPEG picture (SOI to EOI), as an MJPG packet holds it. Reuses its buffers:
  // no allocation per picture once the first one of a size has been checked.
  Verdict check(const uint8_t* jpeg, size_t size);

 private:
  struct HuffmanTable {
    static constexpr int kLookupBits = 9;
    bool defined = false;
    // By the next kLookupBits bits: (code length << 8) | symbol, 0 for a longer code.
    uint16_t lookup[1 << kLookupBits] = {};
    // Canonical code ranges per length (1..16): codes of length l are min_code[l]..max_code[l]
    // (max_code -1 when none), their symbols start at first_symbol[l] in `symbols`.
    int32_t min_code[17] = {}, max_code[17] = {}, first_symbol[17] = {};
    uint8_t symbols[256] = {};
  };
  struct Component {
    int id = 0, h = 1, v = 1;
    int dc_table = 0, ac_table = 0;
  };

  bool define_tables(const uint8_t* segment, size_t length);
  // Walks the entropy-coded data from `start` to the next marker that is not a restart marker;
  // sets `end` to that marker's position.
  Verdict walk_scan(const uint8_t* jpeg, size_t size, size_t start, size_t& end);

  HuffmanTable dc_[4], ac_[4];
  std::vector<Component> components_;
  int width_ = 0, height_ = 0;
  int restart_interval_ = 0;
  std::vector<uint8_t> segment_;  // One restart interval's data, byte stuffing removed.
};

}  // namespace softsight
