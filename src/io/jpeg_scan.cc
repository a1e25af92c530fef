#include "io/jpeg_scan.h"

#include <algorithm>

namespace softsight {
namespace {

int BigEndian16(const uint8_t* p) { return (p[0] << 8) | p[1]; }

// Reads a restart interval's unstuffed data, counting the bits consumed: reading past the end
// yields zeros (as FFmpeg's reader does) and shows in the count.
class BitReader {
 public:
  explicit BitReader(const std::vector<uint8_t>& data) : data_(data) {}
  // The next `count` (0..25) bits, not consumed.
  uint32_t peek(int count) {
    while (available_ <= 56) {
      const uint64_t byte = next_ < data_.size() ? data_[next_] : 0;
      ++next_;
      buffer_ |= byte << (56 - available_);
      available_ += 8;
    }
    return count == 0 ? 0 : static_cast<uint32_t>(buffer_ >> (64 - count));
  }
  void skip(int count) {
    peek(count);
    buffer_ <<= count;
    available_ -= count;
    consumed_ += count;
  }
  int64_t consumed() const { return consumed_; }
  bool overread() const { return consumed_ > static_cast<int64_t>(data_.size()) * 8; }

 private:
  const std::vector<uint8_t>& data_;
  size_t next_ = 0;
  uint64_t buffer_ = 0;
  int available_ = 0;
  int64_t consumed_ = 0;
};

// The next symbol of `table`, consumed; -1 for a code the table does not have.
template <typename Table>
int DecodeSymbol(const Table& table, BitReader& reader) {
  const uint16_t fast = table.lookup[reader.peek(Table::kLookupBits)];
  if (fast != 0) {
    reader.skip(fast >> 8);
    return fast & 0xFF;
  }
  const uint32_t bits = reader.peek(16);
  for (int l = Table::kLookupBits + 1; l <= 16; ++l) {
    const int32_t code = static_cast<int32_t>(bits >> (16 - l));
    if (code <= table.max_code[l]) {
      reader.skip(l);
      return table.symbols[table.first_symbol[l] + code - table.min_code[l]];
    }
  }
  return -1;
}

}  // namespace

bool JpegScanCheck::define_tables(const uint8_t* segment, size_t length) {
  size_t at = 0;
  while (at < length) {
    if (at + 17 > length) return false;
    const int table_class = segment[at] >> 4, index = segment[at] & 15;
    if (table_class > 1 || index > 3) return false;
    HuffmanTable& table = table_class == 0 ? dc_[index] : ac_[index];
    int total = 0;
    for (int l = 1; l <= 16; ++l) total += segment[at + static_cast<size_t>(l)];
    if (total > 256 || at + 17 + static_cast<size_t>(total) > length) return false;
    int32_t code = 0, symbol = 0;
    for (int l = 1; l <= 16; ++l) {
      const int count = segment[at + static_cast<size_t>(l)];
      // More codes of a length than there are left (a damaged table): they cannot be told apart.
      if (code + count > (1 << l)) return false;
      table.first_symbol[l] = symbol;
      table.min_code[l] = code;
      table.max_code[l] = count > 0 ? code + count - 1 : -1;
      code = (code + count) << 1;
      symbol += count;
    }
    std::copy(segment + at + 17, segment + at + 17 + total, table.symbols);
    // Codes up to kLookupBits long, looked up at once by the next kLookupBits bits.
    std::fill(std::begin(table.lookup), std::end(table.lookup), uint16_t{0});
    for (int l = 1; l <= HuffmanTable::kLookupBits; ++l) {
      for (int32_t code = table.min_code[l]; code <= table.max_code[l]; ++code) {
        const int shift = HuffmanTable::kLookupBits - l;
        const uint16_t entry = static_cast<uint16_t>(
            (l << 8) | table.symbols[table.first_symbol[l] + code - table.min_code[l]]);
        for (int32_t fill = code << shift; fill < (code + 1) << shift; ++fill) {
          table.lookup[fill] = entry;
        }
      }
    }
    table.defined = true;
    at += 17 + static_cast<size_t>(total);
  }
  return true;
}

JpegScanCheck::Verdict JpegScanCheck::walk_scan(const uint8_t* jpeg, size_t size, size_t start,
                                                size_t& end) {
  int h_max = 1, v_max = 1;
  for (const Component& c : components_) {
    h_max = std::max(h_max, c.h);
    v_max = std::max(v_max, c.v);
  }
  // A picture of one component is scanned a block at a time, whatever its sampling factors.
  const bool single = components_.size() == 1;
  const int mcu_w = single ? 8 : 8 * h_max, mcu_h = single ? 8 : 8 * v_max;
  const int64_t total = int64_t{(width_ + mcu_w - 1) / mcu_w} * ((height_ + mcu_h - 1) / mcu_h);
  const int64_t interval = restart_interval_ > 0 ? restart_interval_ : total;
  size_t at = start;
  int64_t mcu = 0;
  int next_restart = 0;
  while (mcu < total) {
    segment_.clear();
    while (at < size) {
      if (jpeg[at] != 0xFF) {
        segment_.push_back(jpeg[at++]);
      } else if (at + 1 < size && jpeg[at + 1] == 0x00) {
        segment_.push_back(0xFF);
        at += 2;
      } else {
        break;  // A marker.
      }
    }
    BitReader reader(segment_);
    const int64_t last = std::min(total, mcu + interval);
    for (; mcu < last; ++mcu) {
      for (const Component& c : components_) {
        const int blocks = single ? 1 : c.h * c.v;
        const HuffmanTable& dc = dc_[c.dc_table];
        const HuffmanTable& ac = ac_[c.ac_table];
        for (int b = 0; b < blocks; ++b) {
          for (int k = 0; k < 64;) {
            const int symbol = DecodeSymbol(k == 0 ? dc : ac, reader);
            if (symbol < 0) return Verdict::kDamaged;  // No table has this code.
            if (k == 0) {
              if (symbol > 16) return Verdict::kDamaged;
              reader.skip(symbol);
              k = 1;
              continue;
            }
            const int run = symbol >> 4, bits = symbol & 15;
            if (bits == 0 && run != 15) break;  // End of block.
            k += run + 1;
            if (k > 64) return Verdict::kDamaged;  // Past the block's 64 coefficients.
            reader.skip(bits);
          }
          // Data that runs out before the last MCU is out of step. In the last MCU it may be the
          // encoder's: OpenCV's own MJPEG writer cuts the last bytes off one frame in ten (its
          // 32-bit flush), which decoders fill with zeros, in the picture's corner MCU alone.
          if (reader.overread() && mcu + 1 < total) return Verdict::kDamaged;
        }
      }
    }
    // An intact interval ends within its last byte (the rest is padding), or in the last MCU
    // past it (above).
    const int64_t spare = static_cast<int64_t>(segment_.size()) * 8 - reader.consumed();
    if (spare >= 8) return Verdict::kDamaged;
    if (mcu < total) {
      if (at + 1 >= size || jpeg[at + 1] != 0xD0 + next_restart) return Verdict::kDamaged;
      next_restart = (next_restart + 1) & 7;
      at += 2;
    }
  }
  end = at;
  return Verdict::kWhole;
}

JpegScanCheck::Verdict JpegScanCheck::check(const uint8_t* jpeg, size_t size) {
  if (size < 4 || jpeg[0] != 0xFF || jpeg[1] != 0xD8) return Verdict::kUnchecked;
  for (HuffmanTable& t : dc_) t.defined = false;
  for (HuffmanTable& t : ac_) t.defined = false;
  components_.clear();
  width_ = height_ = 0;
  restart_interval_ = 0;
  bool scanned = false;
  size_t at = 2;
  while (at + 1 < size) {
    // Between segments only markers (and their fill bytes); anything else FFmpeg skips, and it
    // is no business of the entropy-coded data's.
    if (jpeg[at] != 0xFF) return scanned ? Verdict::kWhole : Verdict::kUnchecked;
    while (at + 1 < size && jpeg[at + 1] == 0xFF) ++at;
    if (at + 1 >= size) break;
    const int marker = jpeg[at + 1];
    at += 2;
    if (marker == 0xD9) break;  // End of picture.
    if (marker == 0xD8 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;
    if (at + 2 > size) return Verdict::kDamaged;
    const size_t length = static_cast<size_t>(BigEndian16(jpeg + at));
    if (length < 2 || at + length > size) return Verdict::kDamaged;
    const uint8_t* segment = jpeg + at + 2;
    const size_t segment_length = length - 2;
    if (marker == 0xC4) {
      if (!define_tables(segment, segment_length)) return Verdict::kDamaged;
    } else if (marker == 0xC0 || marker == 0xC1) {
      if (segment_length < 6) return Verdict::kDamaged;
      height_ = BigEndian16(segment + 1);
      width_ = BigEndian16(segment + 3);
      const int count = segment[5];
      if (height_ == 0 || width_ == 0 || count == 0 ||
          segment_length < 6 + 3 * static_cast<size_t>(count)) {
        return Verdict::kUnchecked;  // Height given after the scan (DNL), or an odd header.
      }
      for (int i = 0; i < count; ++i) {
        const uint8_t* c = segment + 6 + 3 * i;
        Component component;
        component.id = c[0];
        component.h = c[1] >> 4;
        component.v = c[1] & 15;
        if (component.h < 1 || component.h > 4 || component.v < 1 || component.v > 4) {
          return Verdict::kUnchecked;
        }
        components_.push_back(component);
      }
    } else if ((marker >= 0xC2 && marker <= 0xCF) && marker != 0xC4 && marker != 0xC8 &&
               marker != 0xCC) {
      return Verdict::kUnchecked;  // Progressive, lossless or arithmetic coded.
    } else if (marker == 0xDD) {
      if (segment_length < 2) return Verdict::kDamaged;
      restart_interval_ = BigEndian16(segment);
    } else if (marker == 0xDA) {
      if (components_.empty() || segment_length < 1) return Verdict::kUnchecked;
      const size_t count = segment[0];
      // A scan header that does not fit its frame is damaged (FFmpeg then skips the scan and
      // hands back the picture of the frame before, or none). A scan of some of the components
      // is a legal file this does not walk.
      if (count == 0 || count > components_.size() || segment_length != 1 + 2 * count + 3) {
        return Verdict::kDamaged;
      }
      for (size_t i = 0; i < count; ++i) {
        const int id = segment[1 + 2 * i];
        if (std::none_of(components_.begin(), components_.end(),
                         [&](const Component& c) { return c.id == id; })) {
          return Verdict::kDamaged;
        }
      }
      // One scan of all components, baseline (spectral selection 0..63, no approximation).
      if (count != components_.size()) return Verdict::kUnchecked;
      for (size_t i = 0; i < count; ++i) {
        const uint8_t* s = segment + 1 + 2 * i;
        // Components must come in the frame's order for the MCU walk below.
        if (components_[i].id != s[0]) return Verdict::kUnchecked;
        components_[i].dc_table = s[1] >> 4;
        components_[i].ac_table = s[1] & 15;
        if (components_[i].dc_table > 3 || components_[i].ac_table > 3 ||
            !dc_[components_[i].dc_table].defined || !ac_[components_[i].ac_table].defined) {
          return Verdict::kUnchecked;  // No tables given (FFmpeg would use the standard ones).
        }
      }
      const uint8_t* spectral = segment + 1 + 2 * count;
      if (spectral[0] != 0 || spectral[1] != 63 || spectral[2] != 0) return Verdict::kUnchecked;
      size_t end = 0;
      const Verdict verdict = walk_scan(jpeg, size, at + length, end);
      if (verdict != Verdict::kWhole) return verdict;
      scanned = true;
      at = end;
      continue;
    }
    at += length;
  }
  return scanned ? Verdict::kWhole : Verdict::kUnchecked;
}

}  // namespace softsight
