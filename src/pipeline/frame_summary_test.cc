#include "pipeline/frame_summary.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "softsight/sim/scene.h"

namespace softsight {
namespace {

// Every field of every cell the same to the last bit (the detector's thresholds see the same
// numbers, so it decides the same), with the cell named when one differs.
void ExpectSummariesEqual(const std::vector<FrameCell>& fast,
                          const std::vector<FrameCell>& reference, const std::string& what) {
  ASSERT_EQ(fast.size(), reference.size()) << what;
  for (size_t i = 0; i < fast.size(); ++i) {
    SCOPED_TRACE(what + ", cell " + std::to_string(i));
    EXPECT_EQ(fast[i].b, reference[i].b);
    EXPECT_EQ(fast[i].g, reference[i].g);
    EXPECT_EQ(fast[i].r, reference[i].r);
    EXPECT_EQ(fast[i].texture, reference[i].texture);
    EXPECT_EQ(fast[i].gray, reference[i].gray);
  }
}

// `fast` is the caller's, reused from frame to frame as the detector reuses its cells (what an
// earlier frame of another size left there must not show).
void ExpectSummarisedAsReference(FrameSummariser& summariser, const cv::Mat& bgr,
                                 std::vector<FrameCell>& fast, const std::string& what) {
  const CellGrid grid = CellGrid::For(bgr.size());
  std::vector<FrameCell> reference;
  summariser.summarise(bgr, grid, fast);
  SummariseFrameReference(bgr, grid, reference);
  ASSERT_EQ(reference.size(), static_cast<size_t>(grid.cols) * grid.rows) << what;
  ExpectSummariesEqual(fast, reference, what);
}

std::string SizeName(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

TEST(FrameSummary, RandomFramesOfEverySizeAreSummarisedBitForBitAsTheReference) {
  // Sizes whose sample grids end exactly on a cell, just past one, or hold less than one cell
  // (one cell taking every sample), with steps 1 to 18.
  const cv::Size sizes[] = {{1, 1},     {2, 3},     {7, 5},     {8, 8},     {9, 17},
                            {31, 17},   {33, 200},  {200, 33},  {119, 121}, {241, 240},
                            {479, 641}, {640, 480}, {641, 481}, {959, 541}, {1280, 720},
                            {1279, 719}, {1920, 1080}, {3, 2}};
  cv::RNG rng(26);
  FrameSummariser summariser;  // One for all sizes: its scratch rows follow the size.
  std::vector<FrameCell> fast;
  for (const cv::Size& size : sizes) {
    cv::Mat bgr(size, CV_8UC3);
    rng.fill(bgr, cv::RNG::UNIFORM, 0, 256);
    ExpectSummarisedAsReference(summariser, bgr, fast, "random bytes " + SizeName(size));
    // Smooth content too: small differences, whose divisions by 3 and 6 round.
    cv::Mat smooth;
    cv::GaussianBlur(bgr, smooth, cv::Size(0, 0), 3.0);
    ExpectSummarisedAsReference(summariser, smooth, fast, "smooth " + SizeName(size));
  }
}

TEST(FrameSummary, RenderedFramesAndAWindowOfALargerImageAreSummarisedAsTheReference) {
  FrameSummariser summariser;
  std::vector<FrameCell> fast;
  for (const cv::Size& size : {cv::Size(640, 480), cv::Size(1280, 720)}) {
    SceneOptions options;
    options.size = size;
    NoiseOptions noise;
    noise.sigma = 2.0;
    SyntheticScene scene(options, noise);
    cv::Mat bgr;
    scene.render(7, bgr);
    ExpectSummarisedAsReference(summariser, bgr, fast, "rendered " + SizeName(size));
    // Rows that are not contiguous in memory: a window of the frame.
    ExpectSummarisedAsReference(summariser, bgr(cv::Rect(13, 5, size.width / 2, size.height / 3)),
                                fast, "window of rendered " + SizeName(size));
  }
}

TEST(FrameSummary, AUniformFrameHasItsColourAndNoTextureInEveryCell) {
  const cv::Mat bgr(480, 640, CV_8UC3, cv::Scalar(10, 100, 221));
  const CellGrid grid = CellGrid::For(bgr.size());
  EXPECT_EQ(grid.step, 8);
  EXPECT_EQ(grid.cols, 20);
  EXPECT_EQ(grid.rows, 15);
  std::vector<FrameCell> cells;
  FrameSummariser().summarise(bgr, grid, cells);
  ASSERT_EQ(cells.size(), 300u);
  for (const FrameCell& cell : cells) {
    EXPECT_EQ(cell.b, 10.0f);
    EXPECT_EQ(cell.g, 100.0f);
    EXPECT_EQ(cell.r, 221.0f);
    EXPECT_EQ(cell.texture, 0.0f);
    for (uint8_t v : cell.gray) EXPECT_EQ(v, 110);
  }
}

TEST(FrameSummary, TextureIsTheMeanDifferenceOfNeighbouringSamples) {
  // Columns alternating 0 and 90 in every channel from one sample to the next (step 8 at VGA):
  // every sample but the first column's differs by 90 from its left neighbour and by 0 from the
  // one above, so a cell's texture is the mean of 90 / 2 over its samples with two neighbours,
  // 90 for the first row's (left only) and 0 for the first column's.
  cv::Mat bgr(480, 640, CV_8UC3);
  for (int x = 0; x < bgr.cols; ++x) {
    bgr.col(x).setTo(cv::Scalar::all((x / 8) % 2 == 0 ? 0 : 90));
  }
  const CellGrid grid = CellGrid::For(bgr.size());
  ASSERT_EQ(grid.step, 8);
  std::vector<FrameCell> cells;
  FrameSummariser().summarise(bgr, grid, cells);
  // An inner cell: 16 samples of 45.
  EXPECT_FLOAT_EQ(cells[static_cast<size_t>(5 * grid.cols + 5)].texture, 45.0f);
  // The top-left cell: 3 first-row samples of 90, 3 x 3 of 45, the first column's 4 of 0.
  EXPECT_FLOAT_EQ(cells[0].texture, (3 * 90.0f + 9 * 45.0f) / 16.0f);
  EXPECT_FLOAT_EQ(cells[0].b, 45.0f);
}

}  // namespace
}  // namespace softsight
