// The fast matching kernels against their brute-force references on random images and templates
// of odd and even sizes, gray and colour, including placements touching every image border.
#include "track/match_kernels.h"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace softsight {
namespace {

cv::Mat RandomImage(cv::RNG& rng, cv::Size size, int channels) {
  cv::Mat image(size, CV_8UC(channels));
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

// Number of places where two integer maps differ.
int CountDifferent(const cv::Mat& a, const cv::Mat& b) {
  EXPECT_EQ(a.size(), b.size());
  EXPECT_EQ(a.type(), b.type());
  if (a.size() != b.size() || a.type() != b.type()) return -1;
  return cv::countNonZero(a.reshape(1) != b.reshape(1));
}

// Largest |a - b| over the map; NaN must sit at the same places in both (counted in
// `nan_mismatch`).
double MaxZnccError(const cv::Mat& a, const cv::Mat& b, int* nan_mismatch) {
  double worst = 0.0;
  *nan_mismatch = 0;
  for (int y = 0; y < a.rows; ++y) {
    for (int x = 0; x < a.cols; ++x) {
      const float u = a.at<float>(y, x), v = b.at<float>(y, x);
      if (std::isnan(u) || std::isnan(v)) {
        if (std::isnan(u) != std::isnan(v)) ++*nan_mismatch;
        continue;
      }
      worst = std::max(worst, static_cast<double>(std::abs(u - v)));
    }
  }
  return worst;
}

struct Case {
  int width, height, channels;
};

// Widths cover every layout: too narrow for vectors (scalar path), exactly 8, 16-byte chunks
// only, a tail of 1..7 bytes, a tail of 8..15 bytes; odd and even in both directions.
const Case kCases[] = {{5, 4, 1},  {8, 8, 1},   {9, 7, 1},   {15, 6, 1},  {16, 16, 1},
                       {17, 9, 1}, {21, 21, 1}, {24, 11, 1}, {31, 32, 1}, {32, 32, 1},
                       {33, 5, 1}, {47, 3, 1},  {2, 3, 3},   {3, 3, 3},   {5, 4, 3},
                       {6, 7, 3},  {11, 11, 3}, {16, 9, 3},  {21, 20, 3}, {32, 32, 3}};

std::string Name(const Case& c) {
  return std::to_string(c.width) + "x" + std::to_string(c.height) + "x" +
         std::to_string(c.channels);
}

TEST(MatchKernelsTest, RandomImagesMatchReferencesExactlyOrWithin1e4) {
  cv::RNG rng(20261122);
  PreparedTemplate prepared;
  ZnccScratch scratch;
  cv::Mat fast, reference;
  for (const Case& c : kCases) {
    SCOPED_TRACE(Name(c));
    // Odd and even image sizes; the result map spans every placement, so the first and last
    // rows and columns of the map are placements touching the image borders.
    const cv::Size image_size(c.width + 19 + rng.uniform(0, 2), c.height + 14 + rng.uniform(0, 2));
    const cv::Mat image = RandomImage(rng, image_size, c.channels);
    const cv::Mat templ = RandomImage(rng, {c.width, c.height}, c.channels);
    // Unmasked, and with a random mask keeping about 70 % of the pixels.
    cv::Mat random_mask(templ.size(), CV_8UC1);
    rng.fill(random_mask, cv::RNG::UNIFORM, 0, 10);
    random_mask = random_mask < 7;
    random_mask.at<uint8_t>(0, 0) = 0;  // Never all ones.
    for (const cv::Mat& mask : {cv::Mat(), random_mask}) {
      SCOPED_TRACE(mask.empty() ? "unmasked" : "masked");
      ASSERT_TRUE(prepared.Prepare(templ, mask));
      EXPECT_EQ(prepared.masked(), !mask.empty());

      MatchSad(image, prepared, fast);
      MatchSadReference(image, templ, reference, mask);
      EXPECT_EQ(CountDifferent(fast, reference), 0) << "SAD";

      MatchSsd(image, prepared, fast);
      MatchSsdReference(image, templ, reference, mask);
      EXPECT_EQ(CountDifferent(fast, reference), 0) << "SSD";

      MatchZncc(image, prepared, fast, scratch);
      MatchZnccReference(image, templ, reference, mask);
      int nan_mismatch = 0;
      EXPECT_LE(MaxZnccError(fast, reference, &nan_mismatch), 1e-4) << "ZNCC";
      EXPECT_EQ(nan_mismatch, 0);
    }
  }
}

// The ellipse inscribed in a template of `size`, as the tracker's round mask: one run of pixels
// per row, the masked ZNCC's common case.
cv::Mat EllipseMask(cv::Size size) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
  const double cx = (size.width - 1) / 2.0, cy = (size.height - 1) / 2.0;
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const double u = (x - cx) / (size.width / 2.0), v = (y - cy) / (size.height / 2.0);
      if (u * u + v * v <= 1.0) mask.at<uint8_t>(y, x) = 255;
    }
  }
  return mask;
}

// One placement of a gray template (MatchZnccAt) is the value MatchZncc's map holds there, to
// the bit, at every placement of every layout, masked and not, and near the reference; colour
// and too-narrow templates are left to MatchZncc. One PreparedTemplate is re-prepared with
// masks that alternate (its runs kept only while the mask is the same) and still matches as a
// fresh one does.
// A template re-prepared with new pixels of the same size, channels and mask (the template
// update: only its values laid out again) matches as one prepared afresh, bit for bit: gray and
// colour, masked and not, every width 3-40 (full chunks, 8-byte halves, the scalar layout).
TEST(MatchKernelsTest, RePreparedTemplateMatchesAsAFreshOne) {
  cv::RNG rng(45);
  for (const int type : {CV_8UC1, CV_8UC3}) {
    for (int width = 3; width <= 40; ++width) {
      const cv::Size size(width, 4 + width % 9);
      if (type == CV_8UC3 && size.area() * 3 > kMaxTemplateValues) continue;
      cv::Mat mask(size, CV_8UC1);
      rng.fill(mask, cv::RNG::UNIFORM, 0, 2);
      mask.at<uint8_t>(0, 0) = 1;
      mask.at<uint8_t>(size.height - 1, size.width - 1) = 1;
      for (const bool masked : {false, true}) {
        const cv::Mat m = masked ? mask : cv::Mat();
        cv::Mat first(size, type), second(size, type), image(size.height + 7, size.width + 9, type);
        rng.fill(first, cv::RNG::UNIFORM, 0, 256);
        rng.fill(second, cv::RNG::UNIFORM, 0, 256);
        rng.fill(image, cv::RNG::UNIFORM, 0, 256);
        PreparedTemplate reused, fresh;
        ASSERT_TRUE(reused.Prepare(first, m));
        ASSERT_TRUE(reused.Prepare(second, m));
        ASSERT_TRUE(fresh.Prepare(second, m));
        cv::Mat a, b;
        ZnccScratch scratch;
        MatchSad(image, reused, a);
        MatchSad(image, fresh, b);
        EXPECT_EQ(cv::countNonZero(a != b), 0) << width << " " << masked;
        MatchZncc(image, reused, a, scratch);
        MatchZncc(image, fresh, b, scratch);
        EXPECT_EQ(cv::countNonZero(a != b), 0) << width << " " << masked;
        MatchSsd(image, reused, a, scratch);
        MatchSsd(image, fresh, b, scratch);
        EXPECT_EQ(cv::countNonZero(a != b), 0) << width << " " << masked;
      }
    }
  }
}

TEST(MatchKernelsTest, ZnccAtOnePlacementIsTheMapsValue) {
  cv::RNG rng(4546);
  ZnccScratch scratch;
  PreparedTemplate reused;
  for (const Case& c : kCases) {
    SCOPED_TRACE(Name(c));
    const cv::Mat image = RandomImage(rng, {c.width + 5, c.height + 4}, c.channels);
    for (int trial = 0; trial < 6; ++trial) {
      cv::Mat templ = RandomImage(rng, {c.width, c.height}, c.channels);
      if (trial == 5) templ = image(cv::Rect(2, 1, c.width, c.height)).clone();  // A perfect fit.
      cv::Mat mask;
      if (trial % 3 == 1) {
        mask = cv::Mat::zeros(templ.size(), CV_8UC1);
        cv::ellipse(mask, cv::Point(c.width / 2, c.height / 2),
                    cv::Size(std::max(1, c.width / 2), std::max(1, c.height / 2)), 0, 0, 360,
                    cv::Scalar(255), cv::FILLED);
      } else if (trial % 3 == 2) {
        cv::Mat noise(templ.size(), CV_8UC1);
        rng.fill(noise, cv::RNG::UNIFORM, 0, 4);
        mask = noise > 0;  // Three pixels in four, scattered.
      }
      PreparedTemplate prepared;
      ASSERT_TRUE(prepared.Prepare(templ, mask));
      ASSERT_TRUE(reused.Prepare(templ, mask));
      cv::Mat map, reused_map, reference;
      MatchZncc(image, prepared, map, scratch);
      MatchZncc(image, reused, reused_map, scratch);
      int nan_mismatch = 0;
      EXPECT_EQ(MaxZnccError(map, reused_map, &nan_mismatch), 0.0);
      EXPECT_EQ(nan_mismatch, 0);
      MatchZnccReference(image, templ, reference, mask);
      for (int y = 0; y < map.rows; ++y) {
        for (int x = 0; x < map.cols; ++x) {
          float one = -7;
          const bool done = MatchZnccAt(image, {x, y}, prepared, &one);
          if (c.channels == 3 || c.width < 8) {
            EXPECT_FALSE(done);
            continue;
          }
          ASSERT_TRUE(done);
          const float expected = map.at<float>(y, x);
          if (std::isnan(expected)) {
            EXPECT_TRUE(std::isnan(one));
          } else {
            EXPECT_EQ(one, expected) << x << "," << y;
            EXPECT_NEAR(one, reference.at<float>(y, x), 1e-4);
          }
        }
      }
      if (trial == 5 && c.channels == 1 && c.width >= 8) {
        float one = 0;
        ASSERT_TRUE(MatchZnccAt(image, {2, 1}, prepared, &one));
        EXPECT_FLOAT_EQ(one, 1.0f);  // The template where it was cut from.
      }
    }
  }
}

// Windows matched in an image whose prefix sums are shared (ShareWindowSums: the tracker's
// converted part of the frame, itself a window of the frame) give the maps matched without
// sharing, to the bit: windows inside it, and windows of the frame reaching out of it (which
// must not take the shared sums), for ZNCC and SSD with masked templates; and after
// StopSharingWindowSums the image may change. The cross-correlation reads the shared image's
// widened rows: with the 256-bit kernel and without.
TEST(MatchKernelsTest, SharedWindowSumsGiveTheSameMaps) {
  cv::RNG rng(4547);
  cv::Mat frame = RandomImage(rng, {70, 60}, 1);
  const cv::Rect part(6, 5, 44, 41);
  ZnccScratch shared, fresh;
  for (int trial = 0; trial < 600; ++trial) {
    UseWideCrossKernel(trial < 300 && WideCrossKernelAvailable());
    if (trial % 50 == 0) {
      StopSharingWindowSums(shared);
      rng.fill(frame, cv::RNG::UNIFORM, 0, 256);  // A new frame in the same buffer.
      ShareWindowSums(frame(part), shared);
    }
    const cv::Size tsize(8 + rng.uniform(0, 26), 5 + rng.uniform(0, 26));
    const cv::Mat templ = RandomImage(rng, tsize, 1);
    cv::Mat mask = cv::Mat::zeros(tsize, CV_8UC1);
    cv::ellipse(mask, cv::Point(tsize.width / 2, tsize.height / 2),
                cv::Size(tsize.width / 2, tsize.height / 2), 0, 0, 360, cv::Scalar(255), cv::FILLED);
    PreparedTemplate prepared;
    if (!prepared.Prepare(templ, mask)) continue;
    // Inside the shared part half the time, anywhere in the frame otherwise.
    const cv::Rect area = trial % 2 == 0 ? part : cv::Rect(0, 0, frame.cols, frame.rows);
    const int w = tsize.width + rng.uniform(0, area.width - tsize.width + 1);
    const int h = tsize.height + rng.uniform(0, area.height - tsize.height + 1);
    const cv::Rect window(area.x + rng.uniform(0, area.width - w + 1),
                          area.y + rng.uniform(0, area.height - h + 1), w, h);
    cv::Mat a, b;
    MatchZncc(frame(window), prepared, a, shared);
    MatchZncc(frame(window).clone(), prepared, b, fresh);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(cv::countNonZero((a != b) & (a == a)), 0) << window;  // NaN where both are.
    EXPECT_EQ(cv::countNonZero((a == a) != (b == b)), 0) << window;
    MatchSsd(frame(window), prepared, a, shared);
    MatchSsd(frame(window).clone(), prepared, b, fresh);
    EXPECT_EQ(CountDifferent(a, b), 0) << window;
  }
  UseWideCrossKernel(WideCrossKernelAvailable());
}

TEST(MatchKernelsTest, MaskedZnccMatchesReferenceForRoundMasksEmptyRowsAndOnePlacement) {
  // Masks of one run per row, with rows that count nothing, and images of the template's size
  // (one placement: the tracker's drift check); one scratch reused over sizes that shrink and
  // grow, as a tracker reuses it.
  cv::RNG rng(20261202);
  PreparedTemplate prepared;
  ZnccScratch scratch;
  cv::Mat fast, reference;
  for (const Case& c : kCases) {
    SCOPED_TRACE(Name(c));
    const cv::Mat templ = RandomImage(rng, {c.width, c.height}, c.channels);
    cv::Mat round = EllipseMask(templ.size());
    cv::Mat holed = round.clone();
    holed.row(c.height / 2).setTo(0);  // A row without runs.
    if (c.width > 2) holed.at<uint8_t>(0, c.width / 2) = 0;
    for (const cv::Mat& mask : {round, holed}) {
      if (cv::countNonZero(mask) == static_cast<int>(mask.total())) continue;  // Unmasked.
      if (!prepared.Prepare(templ, mask)) continue;  // Flat under this mask.
      ASSERT_TRUE(prepared.masked());
      for (const cv::Size& extra : {cv::Size(0, 0), cv::Size(17, 12), cv::Size(3, 0)}) {
        SCOPED_TRACE(std::to_string(extra.width) + "+" + std::to_string(extra.height));
        const cv::Mat image =
            RandomImage(rng, {c.width + extra.width, c.height + extra.height}, c.channels);
        MatchZncc(image, prepared, fast, scratch);
        MatchZnccReference(image, templ, reference, mask);
        int nan_mismatch = 0;
        EXPECT_LE(MaxZnccError(fast, reference, &nan_mismatch), 1e-4);
        EXPECT_EQ(nan_mismatch, 0);
      }
    }
  }
}

// The window sums come from per-row prefix sums, 8 gray pixels at a time with a tail a pixel at
// a time, and the cross-correlation four placements at a time, the last one to three of a map
// row reading past the image row: SSD (exact, from both) equals its reference bit for bit for
// every image width from the template's to 40 (map rows 1 to 33 wide), masked and not, gray and
// colour, on views; ZNCC within 1e-6.
TEST(MatchKernelsTest, WindowSumsAndCrossCorrelationExactForEveryRowLength) {
  cv::RNG rng(45);
  PreparedTemplate prepared;
  ZnccScratch scratch;
  cv::Mat fast, reference;
  for (const int channels : {1, 3}) {
    for (const cv::Size templ_size : {cv::Size(8, 5), cv::Size(9, 7), cv::Size(13, 6)}) {
      const cv::Mat templ = RandomImage(rng, templ_size, channels);
      for (const cv::Mat& mask : {EllipseMask(templ_size), cv::Mat()}) {
        ASSERT_TRUE(prepared.Prepare(templ, mask));
        for (int width = templ_size.width; width <= 40; ++width) {
          SCOPED_TRACE(std::to_string(channels) + " channels, " +
                       std::to_string(templ_size.width) + " px template, " +
                       (mask.empty() ? "unmasked" : "masked") + ", image width " +
                       std::to_string(width));
          // A view: rows are not continuous; bright pixels make the squares' sums large.
          cv::Mat wide = RandomImage(rng, {width + 5, templ_size.height + 4}, channels);
          if (width % 3 == 0) wide.setTo(cv::Scalar::all(255));
          wide.at<uint8_t>(2, 4 * channels) = 0;  // Not flat.
          const cv::Mat image = wide(cv::Rect(3, 1, width, templ_size.height + 3));
          MatchSsd(image, prepared, fast, scratch);
          MatchSsdReference(image, templ, reference, mask);
          ASSERT_EQ(fast.size(), reference.size());
          EXPECT_EQ(cv::countNonZero(fast != reference), 0);
          MatchZncc(image, prepared, fast, scratch);
          MatchZnccReference(image, templ, reference, mask);
          for (int y = 0; y < fast.rows; ++y) {
            for (int x = 0; x < fast.cols; ++x) {
              const float f = fast.at<float>(y, x), r = reference.at<float>(y, x);
              if (std::isnan(r)) {
                EXPECT_TRUE(std::isnan(f)) << x << "," << y;
              } else {
                EXPECT_NEAR(f, r, 1e-6) << x << "," << y;
              }
            }
          }
        }
      }
    }
  }
}

// The AVX2 cross-correlation (where the processor has it) gives the 128-bit kernel's maps bit for
// bit: SSD exactly the reference's, ZNCC the same floats, for every chunk layout (the cases'
// widths, and mire-2's large dot's 72x54 template at 1.2x), gray and colour, masked or not, maps
// 1 to 9 placements wide (the three-wide remainder reads the widened image's padding).
TEST(MatchKernelsTest, WideCrossKernelGivesTheSameMaps) {
  if (!WideCrossKernelAvailable()) GTEST_SKIP() << "no AVX2 on this processor";
  cv::RNG rng(4545);
  PreparedTemplate prepared;
  ZnccScratch scratch;
  cv::Mat wide_ssd, wide_zncc, narrow_ssd, narrow_zncc, reference;
  std::vector<Case> cases(std::begin(kCases), std::end(kCases));
  cases.push_back({72, 54, 1});
  cases.push_back({86, 65, 1});
  cases.push_back({25, 22, 3});
  for (const Case& c : cases) {
    const cv::Size templ_size(c.width, c.height);
    const cv::Mat templ = RandomImage(rng, templ_size, c.channels);
    for (const cv::Mat& mask : {EllipseMask(templ_size), cv::Mat()}) {
      if (!prepared.Prepare(templ, mask)) continue;
      for (int extra = 0; extra < 9; ++extra) {
        SCOPED_TRACE(Name(c) + (mask.empty() ? " unmasked" : " masked") + ", " +
                     std::to_string(extra + 1) + " placements wide");
        cv::Mat frame = RandomImage(rng, {c.width + extra + 6, c.height + 5}, c.channels);
        if (extra % 4 == 3) frame.setTo(cv::Scalar::all(255));
        frame.at<uint8_t>(1, 2 * c.channels) = 0;  // Not flat.
        const cv::Mat image = frame(cv::Rect(2, 1, c.width + extra, c.height + 3));
        UseWideCrossKernel(true);
        MatchSsd(image, prepared, wide_ssd, scratch);
        MatchZncc(image, prepared, wide_zncc, scratch);
        UseWideCrossKernel(false);
        MatchSsd(image, prepared, narrow_ssd, scratch);
        MatchZncc(image, prepared, narrow_zncc, scratch);
        UseWideCrossKernel(true);
        MatchSsdReference(image, templ, reference, mask);
        EXPECT_EQ(CountDifferent(wide_ssd, reference), 0);
        EXPECT_EQ(CountDifferent(wide_ssd, narrow_ssd), 0);
        ASSERT_EQ(wide_zncc.size(), narrow_zncc.size());
        EXPECT_EQ(std::memcmp(wide_zncc.data, narrow_zncc.data, wide_zncc.total() * sizeof(float)),
                  0);
      }
    }
  }
}

TEST(MatchKernelsTest, MaskedZnccExactOnImagesWhoseRowSumsExceed32Bits) {
  // The masked window sums come from row prefix sums that wrap around on a wide bright image;
  // their differences must not.
  cv::RNG rng(17);
  cv::Mat image(4, 23000, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::Mat noise = RandomImage(rng, {200, 4}, 3);
  noise.copyTo(image(cv::Rect(22800, 0, 200, 4)));
  const cv::Mat templ = noise(cv::Rect(150, 0, 5, 4)).clone();
  const cv::Mat mask = EllipseMask(templ.size());
  PreparedTemplate prepared;
  ASSERT_TRUE(prepared.Prepare(templ, mask));
  ZnccScratch scratch;
  cv::Mat fast, reference;
  const cv::Rect tail(22700, 0, 300, 4);
  MatchZncc(image, prepared, fast, scratch);
  MatchZnccReference(image(tail), templ, reference, mask);
  int nan_mismatch = 0;
  EXPECT_LE(MaxZnccError(fast(cv::Rect(22700, 0, reference.cols, 1)), reference, &nan_mismatch),
            1e-4);
  EXPECT_EQ(nan_mismatch, 0);
  EXPECT_NEAR(fast.at<float>(0, 22950), 1.0f, 1e-6);  // Where the template was cut.
}

TEST(MatchKernelsTest, MaskedPixelsDoNotMatter) {
  // Changing the image under masked-out template pixels changes no score.
  cv::RNG rng(99);
  const cv::Mat templ = RandomImage(rng, {21, 19}, 3);
  cv::Mat mask(templ.size(), CV_8UC1, cv::Scalar(0));
  cv::circle(mask, {10, 9}, 8, cv::Scalar(255), cv::FILLED);
  cv::Mat image = RandomImage(rng, {40, 30}, 3);
  PreparedTemplate prepared;
  ASSERT_TRUE(prepared.Prepare(templ, mask));
  const cv::Point at(7, 5);
  templ.copyTo(image(cv::Rect(at, templ.size())));
  cv::Mat changed = image.clone();
  cv::Mat outside;
  cv::bitwise_not(mask, outside);
  RandomImage(rng, templ.size(), 3).copyTo(changed(cv::Rect(at, templ.size())), outside);
  ZnccScratch scratch;
  cv::Mat a, b;
  MatchSad(image, prepared, a);
  MatchSad(changed, prepared, b);
  EXPECT_EQ(a.at<int>(at), 0);
  EXPECT_EQ(b.at<int>(at), 0);
  MatchSsd(changed, prepared, b);
  EXPECT_EQ(b.at<int>(at), 0);
  MatchZncc(changed, prepared, b, scratch);
  EXPECT_NEAR(b.at<float>(at), 1.0f, 1e-6);
}

TEST(MatchKernelsTest, TemplateCutAtEachBorderIsFoundThereExactly) {
  cv::RNG rng(7);
  PreparedTemplate prepared;
  ZnccScratch scratch;
  cv::Mat sad, ssd, zncc;
  for (const Case& c : kCases) {
    SCOPED_TRACE(Name(c));
    const cv::Mat image = RandomImage(rng, {c.width + 12, c.height + 9}, c.channels);
    const cv::Point corners[] = {{0, 0},
                                 {image.cols - c.width, 0},
                                 {0, image.rows - c.height},
                                 {image.cols - c.width, image.rows - c.height}};
    for (const cv::Point& at : corners) {
      ASSERT_TRUE(prepared.Prepare(image(cv::Rect(at, cv::Size(c.width, c.height)))));
      MatchSad(image, prepared, sad);
      MatchSsd(image, prepared, ssd);
      MatchZncc(image, prepared, zncc, scratch);
      EXPECT_EQ(sad.at<int>(at), 0);
      EXPECT_EQ(ssd.at<int>(at), 0);
      EXPECT_NEAR(zncc.at<float>(at), 1.0f, 1e-6);
      double min_sad, min_ssd, max_zncc;
      cv::Point min_sad_at, min_ssd_at, max_zncc_at;
      cv::minMaxLoc(sad, &min_sad, nullptr, &min_sad_at);
      cv::minMaxLoc(ssd, &min_ssd, nullptr, &min_ssd_at);
      cv::minMaxLoc(zncc, nullptr, &max_zncc, nullptr, &max_zncc_at);
      EXPECT_EQ(min_sad_at, at);
      EXPECT_EQ(min_ssd_at, at);
      EXPECT_EQ(max_zncc_at, at);
    }
  }
}

TEST(MatchKernelsTest, ImageOfTemplateSizeGivesOneScore) {
  cv::RNG rng(3);
  const cv::Mat image = RandomImage(rng, {20, 13}, 1);
  const cv::Mat templ = RandomImage(rng, {20, 13}, 1);
  PreparedTemplate prepared;
  ASSERT_TRUE(prepared.Prepare(templ));
  cv::Mat fast, reference;
  MatchSad(image, prepared, fast);
  MatchSadReference(image, templ, reference);
  ASSERT_EQ(fast.size(), cv::Size(1, 1));
  EXPECT_EQ(fast.at<int>(0, 0), reference.at<int>(0, 0));
  MatchSsd(image, prepared, fast);
  MatchSsdReference(image, templ, reference);
  EXPECT_EQ(fast.at<int>(0, 0), reference.at<int>(0, 0));
}

TEST(MatchKernelsTest, ExtremeValuesDoNotOverflow) {
  // The largest template the accumulators are sized for, with maximal differences everywhere.
  const int side = 181;  // 181 * 181 = 32761 <= kMaxTemplateValues
  cv::Mat image(side + 2, side + 3, CV_8UC1, cv::Scalar(255));
  cv::Mat templ(side, side, CV_8UC1, cv::Scalar(0));
  templ.at<uint8_t>(0, 0) = 1;  // Not flat.
  PreparedTemplate prepared;
  ASSERT_TRUE(prepared.Prepare(templ));
  cv::Mat fast, reference;
  MatchSad(image, prepared, fast);
  MatchSadReference(image, templ, reference);
  EXPECT_EQ(CountDifferent(fast, reference), 0);
  EXPECT_EQ(fast.at<int>(0, 0), 255 * side * side - 1);
  MatchSsd(image, prepared, fast);
  MatchSsdReference(image, templ, reference);
  EXPECT_EQ(CountDifferent(fast, reference), 0);
  EXPECT_EQ(fast.at<int>(0, 0), 255 * 255 * (side * side - 1) + 254 * 254);
}

TEST(MatchKernelsTest, FlatWindowsGiveUndefinedZncc) {
  cv::RNG rng(11);
  cv::Mat image = RandomImage(rng, {60, 40}, 1);
  image(cv::Rect(10, 5, 30, 25)).setTo(77);  // A flat patch larger than the template.
  const cv::Mat templ = RandomImage(rng, {12, 10}, 1);
  PreparedTemplate prepared;
  ASSERT_TRUE(prepared.Prepare(templ));
  ZnccScratch scratch;
  cv::Mat fast, reference;
  MatchZncc(image, prepared, fast, scratch);
  MatchZnccReference(image, templ, reference);
  // Placements fully inside the flat patch: x in 10..28, y in 5..20.
  for (int y = 0; y < fast.rows; ++y) {
    for (int x = 0; x < fast.cols; ++x) {
      const bool flat = x >= 10 && x <= 28 && y >= 5 && y <= 20;
      EXPECT_EQ(std::isnan(fast.at<float>(y, x)), flat) << x << "," << y;
      EXPECT_EQ(std::isnan(reference.at<float>(y, x)), flat) << x << "," << y;
    }
  }
}

TEST(MatchKernelsTest, FlatTemplateIsRefused) {
  PreparedTemplate prepared;
  EXPECT_FALSE(prepared.Prepare(cv::Mat(9, 9, CV_8UC1, cv::Scalar(40))));
  EXPECT_TRUE(prepared.empty());
  EXPECT_FALSE(prepared.Prepare(cv::Mat(9, 9, CV_8UC3, cv::Scalar(40, 90, 200))));
  // One channel varying is enough for colour ZNCC to be defined.
  cv::Mat colour(9, 9, CV_8UC3, cv::Scalar(40, 90, 200));
  colour.at<cv::Vec3b>(4, 4)[1] = 91;
  EXPECT_TRUE(prepared.Prepare(colour));
}

TEST(MatchKernelsTest, AgreesWithOpenCvMatchTemplateDefinitions) {
  // Same definitions as cv::matchTemplate (TM_SQDIFF, TM_CCOEFF_NORMED), which computes in float.
  cv::RNG rng(5);
  PreparedTemplate prepared;
  ZnccScratch scratch;
  for (int channels : {1, 3}) {
    const cv::Mat image = RandomImage(rng, {70, 50}, channels);
    const cv::Mat templ = RandomImage(rng, {13, 12}, channels);
    ASSERT_TRUE(prepared.Prepare(templ));
    cv::Mat ssd, zncc, cv_ssd, cv_zncc;
    MatchSsd(image, prepared, ssd);
    MatchZncc(image, prepared, zncc, scratch);
    cv::matchTemplate(image, templ, cv_ssd, cv::TM_SQDIFF);
    cv::matchTemplate(image, templ, cv_zncc, cv::TM_CCOEFF_NORMED);
    cv::Mat ssd_f;
    ssd.convertTo(ssd_f, CV_32F);
    EXPECT_LE(cv::norm(ssd_f, cv_ssd, cv::NORM_RELATIVE | cv::NORM_INF), 1e-5);
    EXPECT_LE(cv::norm(zncc, cv_zncc, cv::NORM_INF), 1e-3);
  }
}

}  // namespace
}  // namespace softsight
