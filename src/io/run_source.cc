#include "softsight/io/run_source.h"

#include "io/frame_grabber.h"
#include "io/paced_source.h"
#include "io/read_ahead_source.h"

namespace softsight {

std::unique_ptr<FrameSource> SourceForRun(std::unique_ptr<FrameSource> source, FilePacing files) {
  if (source->is_live()) return std::make_unique<NewestFrameSource>(std::move(source));
  switch (files) {
    case FilePacing::kInCallersThread: return source;
    case FilePacing::kReadAhead: return std::make_unique<ReadAheadSource>(std::move(source));
    case FilePacing::kRealTime: return std::make_unique<PacedFrameSource>(std::move(source));
  }
  return source;
}

}  // namespace softsight
