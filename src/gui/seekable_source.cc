#include "gui/seekable_source.h"

#include <algorithm>

#include "softsight/core/error.h"

namespace softsight {

SeekableSource::SeekableSource(std::unique_ptr<FrameSource> first, Opener reopen,
                               size_t cache_bytes)
    : source_(std::move(first)), reopen_(std::move(reopen)), cache_bytes_(cache_bytes) {
  if (!source_ || !reopen_) throw InputError("seekable source: no source to play");
}

SeekableSource::Slot* SeekableSource::cached(int64_t position) {
  if (ring_.empty() || position < 0) return nullptr;
  Slot& slot = ring_[static_cast<size_t>(position) % ring_.size()];
  return slot.position == position ? &slot : nullptr;
}

void SeekableSource::remember(int64_t position, const Frame& frame) {
  if (ring_.empty()) {
    const size_t bytes = std::max<size_t>(1, frame.image.total() * frame.image.elemSize());
    ring_.resize(std::clamp<size_t>(cache_bytes_ / bytes, 2, 4096));
  }
  Slot& slot = ring_[static_cast<size_t>(position) % ring_.size()];
  frame.image.copyTo(slot.frame.image);  // Same size every frame: the slot's buffer is reused.
  slot.frame.index = frame.index;
  slot.frame.time_s = frame.time_s;
  slot.position = position;
}

bool SeekableSource::decode_next(Frame& frame) {
  if (length_ && decoded_ >= *length_) return false;
  if (!source_->read(frame)) {
    length_ = decoded_;
    return false;
  }
  remember(decoded_, frame);
  ++decoded_;
  ++decoded_total_;
  return true;
}

bool SeekableSource::read(Frame& frame) {
  if (length_ && position_ >= *length_) return false;
  if (const Slot* slot = cached(position_)) {
    slot->frame.image.copyTo(frame.image);
    frame.index = slot->frame.index;
    frame.time_s = slot->frame.time_s;
    ++position_;
    return true;
  }
  if (position_ < decoded_) {
    // Behind the decoder and no longer in the ring: read again from the first frame.
    source_ = reopen_();
    decoded_ = 0;
  }
  while (decoded_ < position_) {
    if (!decode_next(scratch_)) {
      position_ = decoded_;
      return false;
    }
  }
  if (!decode_next(frame)) return false;
  ++position_;
  return true;
}

void SeekableSource::seek(int64_t position) { position_ = std::max<int64_t>(0, position); }

bool SeekableSource::seek_last() {
  if (!length_) {
    // Read to the end once (through the ring, so the last frames are cached for stepping back).
    position_ = std::max(position_, decoded_);
    while (read(scratch_)) {
    }
  }
  if (*length_ == 0) return false;
  position_ = *length_ - 1;
  return true;
}

}  // namespace softsight
