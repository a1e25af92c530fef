// SourceForRun: the one place that decides how a run reads its source.
#include "softsight/io/run_source.h"

#include <memory>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "io/frame_grabber.h"
#include "io/paced_source.h"
#include "io/read_ahead_source.h"

namespace softsight {
namespace {

// Five numbered frames, from a file or (live) a camera.
class FiveFrames : public FrameSource {
 public:
  explicit FiveFrames(bool live) : live_(live) {}
  bool read(Frame& frame) override {
    if (next_ >= 5) return false;
    frame.image.create(2, 2, CV_8UC3);
    frame.index = next_++;
    return true;
  }
  std::string description() const override { return live_ ? "camera 0" : "video five.avi"; }
  std::optional<int64_t> frame_count() const override {
    return live_ ? std::nullopt : std::optional<int64_t>(5);
  }
  std::optional<double> fps() const override { return 30.0; }
  bool is_live() const override { return live_; }

 private:
  bool live_;
  int64_t next_ = 0;
};

TEST(SourceForRun, ACameraIsAlwaysReadNewestFrameFirstWhateverTheFilePacing) {
  for (const FilePacing pacing :
       {FilePacing::kInCallersThread, FilePacing::kReadAhead, FilePacing::kRealTime}) {
    const std::unique_ptr<FrameSource> source =
        SourceForRun(std::make_unique<FiveFrames>(true), pacing);
    EXPECT_NE(dynamic_cast<NewestFrameSource*>(source.get()), nullptr);
    EXPECT_TRUE(source->is_live());
  }
}

TEST(SourceForRun, AFileIsReadAsTheCallerAsksAndKeepsEveryFrame) {
  FrameSource* plain = nullptr;
  {
    auto file = std::make_unique<FiveFrames>(false);
    plain = file.get();
    const std::unique_ptr<FrameSource> same =
        SourceForRun(std::move(file), FilePacing::kInCallersThread);
    EXPECT_EQ(same.get(), plain);
  }
  const std::unique_ptr<FrameSource> ahead =
      SourceForRun(std::make_unique<FiveFrames>(false), FilePacing::kReadAhead);
  EXPECT_NE(dynamic_cast<ReadAheadSource*>(ahead.get()), nullptr);
  Frame frame;
  int64_t expected = 0;
  while (ahead->read(frame)) EXPECT_EQ(frame.index, expected++);
  EXPECT_EQ(expected, 5);
  const std::unique_ptr<FrameSource> paced =
      SourceForRun(std::make_unique<FiveFrames>(false), FilePacing::kRealTime);
  EXPECT_NE(dynamic_cast<PacedFrameSource*>(paced.get()), nullptr);
}

}  // namespace
}  // namespace softsight
