// How a run reads its source, decided here for every command and the Python package:
//  - a camera (FrameSource::is_live): read in its own thread, newest frame wins
//    (NewestFrameSource; the frames a slow pipeline skipped are counted in the summary);
//  - a file, image sequence or rendered scene: as the caller's FilePacing says: decoded a few
//    frames ahead on its own thread so decoding overlaps tracking (batch runs), played at its own
//    frame rate like a camera (a window), or read in the caller's thread (lock-step loops).
// A file never loses a frame in any of these.
#pragma once

#include <memory>

#include "softsight/io/frame_source.h"

namespace softsight {

enum class FilePacing {
  kInCallersThread,  // read() decodes (control's lock-step loop, tests' stand-ins).
  kReadAhead,        // ReadAheadSource: track, Python's track and frames.
  kRealTime,         // PacedFrameSource: the live window playing a file.
};

std::unique_ptr<FrameSource> SourceForRun(std::unique_ptr<FrameSource> source, FilePacing files);

}  // namespace softsight
