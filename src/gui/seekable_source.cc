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
  const bool after_direct_seek = landed_ == decoded_;
  landed_ = -1;
  bool got = false;
  try {
    got = source_->read(frame);
  } catch (const InputError&) {
    // A header that promised more frames than there are (the seek target is past the real end)
    // looks like a truncated file from here; reading forward from the start tells which it is.
    if (!after_direct_seek) throw;
  }
  if (!got) {
    if (after_direct_seek) return read_forward_to(decoded_, frame);
    length_ = decoded_;
    return false;
  }
  remember(decoded_, frame);
  ++decoded_;
  ++decoded_total_;
  return true;
}

bool SeekableSource::read_forward_to(int64_t position, Frame& frame) {
  source_ = reopen_();
  decoded_ = 0;
  while (decoded_ < position) {
    if (!decode_next(scratch_)) return false;
  }
  return decode_next(frame);
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
  // A few frames ahead, decoding through them costs what a seek does (FFmpeg's seek decodes
  // from a key frame up to the target too); anywhere else the source's own seek, when it has
  // one, and else reading again from the first frame.
  const bool close_ahead = position_ >= decoded_ && position_ - decoded_ <= kReadThroughFrames;
  if (!close_ahead) {
    if (source_->seek_to(position_)) {
      decoded_ = landed_ = position_;
      ++direct_seeks_;
    } else if (position_ < decoded_) {
      source_ = reopen_();
      decoded_ = 0;
    }
  }
  while (decoded_ < position_) {
    if (!decode_next(scratch_)) {
      position_ = decoded_;
      return false;
    }
  }
  if (!decode_next(frame)) {
    position_ = decoded_;
    return false;
  }
  position_ = decoded_;
  return true;
}

void SeekableSource::seek(int64_t position) { position_ = std::max<int64_t>(0, position); }

bool SeekableSource::seek_last() {
  if (!length_) {
    // The header's frame count, checked: its last frame must read and nothing may follow it
    // (reading on from there, through the ring, finds the real end if the count was short).
    position_ = std::max(position_, decoded_);
    const std::optional<int64_t> promised = source_->frame_count();
    if (promised && *promised > 0 && *promised - 1 > position_) position_ = *promised - 1;
    while (read(scratch_)) {
    }
  }
  if (*length_ == 0) return false;
  position_ = *length_ - 1;
  return true;
}

}  // namespace softsight
