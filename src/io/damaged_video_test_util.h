// For tests of damaged videos (test code only): what the file's frame source, the one `track`
// reads it with, makes of one.
#pragma once

#include <algorithm>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "softsight/core/error.h"
#include "softsight/io/frame_source.h"

namespace softsight::testing {

// Reads the video at `path` through its frame source to the end, which must be the InputError
// that reports damaged frames (its text in `*report`), and expects none of `damaged` among the
// frames read. Gives the indices of the frames read, in order.
inline std::vector<int64_t> ReadExpectingDamageLeftOut(const std::string& path,
                                                       const std::set<int64_t>& damaged,
                                                       std::string* report) {
  auto source = OpenFrameSource({path, {}, 30.0});
  Frame frame;
  std::vector<int64_t> indices;
  try {
    while (source->read(frame)) indices.push_back(frame.index);
    ADD_FAILURE() << "the damaged frames were not reported";
  } catch (const InputError& e) {
    *report = e.what();
    EXPECT_THAT(*report, ::testing::HasSubstr("damaged")) << *report;
  }
  for (const int64_t i : damaged) {
    EXPECT_EQ(std::count(indices.begin(), indices.end(), i), 0) << "frame " << i;
  }
  return indices;
}

}  // namespace softsight::testing
