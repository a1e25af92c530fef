// The template tracker's parts, reached without the tracker: the similarity peak's sub-pixel
// offset and the template's centre of symmetry, against exact truth.
#include "track/template_parts.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace softsight::template_internal {
namespace {

TEST(TemplateParts, CappedChebyshevDistanceIsTheReferences) {
  cv::RNG rng(45);
  std::vector<uint8_t> scratch;
  for (int trial = 0; trial < 200; ++trial) {
    const cv::Size size(1 + rng.uniform(0, 40), 1 + rng.uniform(0, 40));
    cv::Mat noise(size, CV_32F);
    rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
    // From a lone pixel or none to nearly full.
    const double density = trial % 4 == 0 ? 0.002 : trial % 4 == 1 ? 0.02 : trial % 4 == 2 ? 0.2 : 0.8;
    const cv::Mat label = noise < density;
    const int x0 = rng.uniform(0, size.width), y0 = rng.uniform(0, size.height);
    const cv::Rect area(x0, y0, rng.uniform(0, size.width - x0 + 1), rng.uniform(0, size.height - y0 + 1));
    cv::Mat fast(size, CV_8UC1, cv::Scalar(99)), reference(size, CV_8UC1, cv::Scalar(99));
    CappedChebyshevDistance(label, area, fast, scratch);
    CappedChebyshevDistanceReference(label, area, reference);
    EXPECT_EQ(cv::countNonZero(fast != reference), 0) << size << " " << area << " " << density;
  }
}

// `fast` and its reference twin `reference` (use_reference) locate the blob at `guess` in `gray`
// alike: the same answer (a fatal failure when not: call under ASSERT_NO_FATAL_FAILURE) and, when
// located, the same centroid, area, box and component. *located: whether they located it. With
// `measure`, MeasureLocated then gives both the same answer (fatal when not), centroid and area.
void ExpectLocatedAsReference(BlobMeter& fast, BlobMeter& reference, const cv::Mat& gray,
                              const cv::Point2d& guess, bool measure, bool* located) {
  cv::Point2d c_fast, c_ref;
  double a_fast = -1, a_ref = -1;
  const bool ok_fast = fast.Locate(gray, cv::Mat(), guess, &c_fast, &a_fast);
  const bool ok_ref = reference.Locate(gray, cv::Mat(), guess, &c_ref, &a_ref);
  *located = ok_fast;
  ASSERT_EQ(ok_fast, ok_ref);
  if (!ok_fast) return;
  EXPECT_EQ(c_fast, c_ref);
  EXPECT_EQ(a_fast, a_ref);
  EXPECT_EQ(fast.blob_box(), reference.blob_box());
  EXPECT_EQ(cv::countNonZero(fast.label() != reference.label()), 0);
  if (!measure) return;
  ASSERT_EQ(fast.MeasureLocated(gray, cv::Mat(), &c_fast, &a_fast),
            reference.MeasureLocated(gray, cv::Mat(), &c_ref, &a_ref));
  EXPECT_EQ(c_fast, c_ref);
  EXPECT_EQ(a_fast, a_ref);
}

// The flood and fill on pixel indices (every frame's blob: unmasked, continuous) are the
// reference's: the same answer, levels, component, box, centroids and areas, on discs bright and
// dark, whole, cut by the patch's edge or touching it, on noise of several strengths, guessed
// on and off their centre; and the disc's centroid is where it was drawn.
TEST(TemplateParts, BlobMeterFastSegmentIsTheReferences) {
  cv::RNG rng(4545);
  int located = 0;
  for (int trial = 0; trial < 600; ++trial) {
    const cv::Size size(8 + rng.uniform(0, 48), 8 + rng.uniform(0, 48));
    const bool bright = trial % 2 == 0;
    const int background = rng.uniform(20, 236), marker = bright ? rng.uniform(background, 256)
                                                                 : rng.uniform(0, background + 1);
    const cv::Point2d centre(rng.uniform(0.0, size.width - 1.0), rng.uniform(0.0, size.height - 1.0));
    const double radius = rng.uniform(0.5, 0.45 * std::min(size.width, size.height));
    cv::Mat gray(size, CV_8UC1);
    cv::Mat noise(size, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, (trial / 2) % 3 == 0 ? 1.0 : (trial / 2) % 3 == 1 ? 4.0 : 12.0);
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x) {
        const double d = std::hypot(x - centre.x, y - centre.y);
        const double inside = std::clamp(radius + 0.5 - d, 0.0, 1.0);
        gray.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(
            background + inside * (marker - background) + noise.at<float>(y, x));
      }
    }
    // A meter of the disc's polarity: learned on a clean disc of its own.
    cv::Mat learn(33, 33, CV_8UC1, cv::Scalar(background));
    cv::circle(learn, {16, 16}, 6, cv::Scalar(marker), cv::FILLED);
    BlobMeter fast;
    cv::Point2d learned;
    if (std::abs(marker - background) < 20 || !fast.Learn(learn, RoundMask(learn.size()), &learned)) {
      continue;
    }
    BlobMeter reference = fast;
    reference.use_reference(true);
    const cv::Point2d guess = centre + cv::Point2d(rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0));
    SCOPED_TRACE(trial);
    bool ok = false;
    ASSERT_NO_FATAL_FAILURE(ExpectLocatedAsReference(fast, reference, gray, guess, true, &ok));
    if (!ok) continue;
    ++located;
    cv::Point2d c_fast, c_ref;
    double a_fast = -1, a_ref = -1;
    ASSERT_EQ(fast.Measure(gray, cv::Mat(), guess, &c_fast, &a_fast),
              reference.Measure(gray, cv::Mat(), guess, &c_ref, &a_ref)) << trial;
    EXPECT_EQ(c_fast, c_ref) << trial;
    // The truth: a clear disc well inside the patch is measured at its centre.
    const bool clear = (trial / 2) % 3 == 0 && radius >= 3 && std::abs(marker - background) >= 60 &&
                       centre.x - radius > 6 && centre.y - radius > 6 &&
                       centre.x + radius < size.width - 7 && centre.y + radius < size.height - 7;
    if (clear) {
      EXPECT_TRUE(fast.Measure(gray, cv::Mat(), guess, &c_fast, &a_fast)) << trial;
      EXPECT_NEAR(c_fast.x, centre.x, 0.1) << trial;
      EXPECT_NEAR(c_fast.y, centre.y, 0.1) << trial;
    }
  }
  EXPECT_GT(located, 100);  // The comparison met many blobs, not only refusals.
}

// FloodUnmasked's pass from PassByFills (searched from the last patch's pass) is the whole
// flood's: one meter follows a disc through frames whose levels, size, noise and place change
// (the pass moves by 0, 1 or many levels from one to the next), against the reference flood.
// Both ways of the fast flood are taken: the fills, and the flood on to the edge where noise
// breaks the patch into more spans than the fills' budget.
TEST(TemplateParts, BlobMeterPassByFillsIsTheFloods) {
  cv::RNG rng(4546);
  int located = 0, floods = 0, by_fills = 0, given_up = 0;
  BlobMeter fast;
  BlobMeter reference;
  for (int sequence = 0; sequence < 24; ++sequence) {
    const bool bright = sequence % 2 == 0;
    int background = rng.uniform(30, 226);
    int marker = bright ? rng.uniform(std::min(background + 40, 255), 256)
                        : rng.uniform(0, std::max(background - 40, 1));
    cv::Mat learn(33, 33, CV_8UC1, cv::Scalar(background));
    cv::circle(learn, {16, 16}, 6, cv::Scalar(marker), cv::FILLED);
    by_fills += fast.passes_by_fills();
    given_up += fast.fills_given_up();
    fast = BlobMeter();
    cv::Point2d learned;
    ASSERT_TRUE(fast.Learn(learn, RoundMask(learn.size()), &learned)) << sequence;
    reference = fast;
    reference.use_reference(true);
    const cv::Size size(20 + rng.uniform(0, 60), 20 + rng.uniform(0, 60));
    cv::Point2d centre(size.width / 2.0, size.height / 2.0);
    const double radius0 = rng.uniform(2.0, 0.3 * std::min(size.width, size.height));
    for (int frame = 0; frame < 40; ++frame) {
      // Small steps most frames, a jump now and then.
      const bool jump = rng.uniform(0, 8) == 0;
      const int step = jump ? 40 : 3;
      background = std::clamp(background + rng.uniform(-step, step + 1), 0, 255);
      marker = std::clamp(marker + rng.uniform(-step, step + 1), 0, 255);
      centre += cv::Point2d(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
      centre.x = std::clamp(centre.x, 1.0, size.width - 2.0);
      centre.y = std::clamp(centre.y, 1.0, size.height - 2.0);
      const double radius = radius0 * rng.uniform(0.9, 1.1);
      const double sigma = frame % 5 == 4 ? 60.0 : frame % 5 == 3 ? 12.0 : rng.uniform(0.0, 3.0);
      cv::Mat noise(size, CV_32F);
      rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
      cv::Mat gray(size, CV_8UC1);
      for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
          const double d = std::hypot(x - centre.x, y - centre.y);
          const double inside = std::clamp(radius + 0.5 - d, 0.0, 1.0);
          // A gradient across the background: the pass lies on one side.
          const double shade = 0.3 * (x - size.width / 2.0);
          gray.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(
              background + shade + inside * (marker - background - shade) + noise.at<float>(y, x));
        }
      }
      const cv::Point2d guess =
          centre + cv::Point2d(rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0));
      ++floods;
      SCOPED_TRACE(std::to_string(sequence) + " " + std::to_string(frame));
      bool ok = false;
      ASSERT_NO_FATAL_FAILURE(ExpectLocatedAsReference(fast, reference, gray, guess, false, &ok));
      if (ok) ++located;
    }
  }
  by_fills += fast.passes_by_fills();
  given_up += fast.fills_given_up();
  EXPECT_GT(located, 300);  // Of 960 floods: 836 blobs; 925 passes by fills, 35 given up.
  EXPECT_GT(by_fills, 480);
  EXPECT_GT(given_up, 10);
}

// One meter measuring many patches of one size, as the tracker's does frame after frame: its
// flood's visited tags (cleared only when they wrap, every 255 floods) and its fill's label
// (cleared only where the last component was) leave nothing of one patch in the next: each
// patch's answer, levels, component and box are those of a reference meter fresh for it.
TEST(TemplateParts, BlobMeterKeepsNothingFromPatchToPatch) {
  cv::RNG rng(4547);
  cv::Mat learn(33, 33, CV_8UC1, cv::Scalar(60));
  cv::circle(learn, {16, 16}, 6, cv::Scalar(200), cv::FILLED);
  BlobMeter fast;
  cv::Point2d learned;
  ASSERT_TRUE(fast.Learn(learn, RoundMask(learn.size()), &learned));
  const BlobMeter learned_meter = fast;
  const cv::Size size(41, 37);
  int located = 0, refused = 0;
  for (int patch = 0; patch < 1200; ++patch) {
    // Discs of many sizes, every other one at the patch's middle (over the last floods' tags and
    // the last components), the others anywhere, some cut by the patch's edge, on noise of
    // several strengths: components large and small, found and refused, in turn.
    const cv::Point2d centre =
        patch % 2 == 1
            ? cv::Point2d(rng.uniform(2.0, size.width - 3.0), rng.uniform(2.0, size.height - 3.0))
            : cv::Point2d(20.3, 18.6);
    const double radius = rng.uniform(1.0, 14.0);
    const double sigma = patch % 3 == 0 ? 1.0 : patch % 3 == 1 ? 6.0 : 25.0;
    cv::Mat noise(size, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
    cv::Mat gray(size, CV_8UC1);
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x) {
        const double inside = std::clamp(radius + 0.5 - std::hypot(x - centre.x, y - centre.y), 0.0, 1.0);
        gray.at<uint8_t>(y, x) =
            cv::saturate_cast<uint8_t>(60 + 0.5 * x + inside * 140 + noise.at<float>(y, x));
      }
    }
    BlobMeter reference = learned_meter;
    reference.use_reference(true);
    SCOPED_TRACE(patch);
    bool ok = false;
    ASSERT_NO_FATAL_FAILURE(ExpectLocatedAsReference(fast, reference, gray, centre, true, &ok));
    ++(ok ? located : refused);
  }
  EXPECT_GT(located, 300);
  EXPECT_GT(refused, 20);
}

// asymmetry_px, measured on first use from the component Learn kept, is that of the learned
// component however many patches the meter (or a copy of it) measured since: a crescent (a disc
// with a bite out of one side), its centroid away from its enclosing circle's centre.
TEST(TemplateParts, BlobMeterAsymmetryIsTheLearnedBlobs) {
  cv::Mat learn(41, 41, CV_8UC1, cv::Scalar(50));
  cv::circle(learn, {20, 20}, 9, cv::Scalar(210), cv::FILLED);
  cv::circle(learn, {27, 20}, 6, cv::Scalar(50), cv::FILLED);
  BlobMeter meter;
  cv::Point2d learned;
  ASSERT_TRUE(meter.Learn(learn, RoundMask(learn.size()), &learned));
  // What it was measured as at Learn: the learned component's centroid against the centre of
  // the smallest circle enclosing its pixels.
  std::vector<cv::Point> points;
  const cv::Mat blob = meter.label()(meter.blob_box());
  cv::findNonZero(blob, points);
  cv::Point2f centre;
  float radius = 0;
  cv::minEnclosingCircle(points, centre, radius);
  const cv::Moments m = cv::moments(blob, true);
  const double expected =
      cv::norm(cv::Point2d(m.m10 / m.m00, m.m01 / m.m00) - cv::Point2d(centre));
  ASSERT_GT(expected, 1.0);
  BlobMeter copy = meter;
  // Other blobs measured since (a whole disc: symmetric).
  cv::Mat gray(37, 45, CV_8UC1, cv::Scalar(50));
  cv::circle(gray, {22, 18}, 7, cv::Scalar(220), cv::FILLED);
  cv::Point2d at;
  double area = 0;
  for (BlobMeter* m2 : {&meter, &copy}) {
    ASSERT_TRUE(m2->Locate(gray, cv::Mat(), {22, 18}, &at, &area));
    ASSERT_TRUE(m2->Measure(gray, cv::Mat(), {22, 18}, &at, &area));
  }
  EXPECT_EQ(meter.asymmetry_px(), expected);
  EXPECT_EQ(copy.asymmetry_px(), expected);
  EXPECT_EQ(meter.asymmetry_px(), expected);  // Once measured, kept.
  EXPECT_EQ(BlobMeter().asymmetry_px(), 0.0);  // Nothing learned.
}

// CoreColour as it was first written: every pixel of the box tested and summed in doubles.
bool CoreColourPerPixel(const cv::Mat& bgr, const cv::Point2d& centre, double radius,
                        cv::Vec3d* chroma) {
  const double r = std::max(radius, 1.0);
  const cv::Rect box(static_cast<int>(std::floor(centre.x - r)),
                     static_cast<int>(std::floor(centre.y - r)),
                     static_cast<int>(std::ceil(2 * r)) + 2, static_cast<int>(std::ceil(2 * r)) + 2);
  if ((box & cv::Rect(0, 0, bgr.cols, bgr.rows)) != box) return false;
  cv::Vec3d sum(0, 0, 0);
  int n = 0;
  for (int y = box.y; y < box.br().y; ++y) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = box.x; x < box.br().x; ++x) {
      const double dx = x - centre.x, dy = y - centre.y;
      if (dx * dx + dy * dy > r * r) continue;
      sum += cv::Vec3d(row[x][0], row[x][1], row[x][2]);
      ++n;
    }
  }
  if (n == 0) return false;
  const double total = sum[0] + sum[1] + sum[2];
  if (!(total >= kDarkCoreLevels * n)) return false;
  *chroma = sum / total;
  return true;
}

// CoreColour's runs and integer sums are the per-pixel double sums, bit for bit: random pictures,
// centres on and between pixels, radii from below 1 to beyond the picture, dark cores refused.
TEST(TemplateParts, CoreColourIsThePerPixelSum) {
  cv::RNG rng(45);
  int measured = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    cv::Mat bgr(24 + rng.uniform(0, 40), 24 + rng.uniform(0, 40), CV_8UC3);
    rng.fill(bgr, cv::RNG::UNIFORM, 0, trial % 5 == 0 ? 20 : 256);
    const cv::Point2d centre =
        trial % 3 == 0 ? cv::Point2d(rng.uniform(0, bgr.cols), rng.uniform(0, bgr.rows))
                       : cv::Point2d(rng.uniform(-2.0, bgr.cols + 2.0), rng.uniform(-2.0, bgr.rows + 2.0));
    const double radius = trial % 7 == 0 ? rng.uniform(0.0, 1.5) : rng.uniform(0.5, 20.0);
    cv::Vec3d fast(-1, -1, -1), reference(-1, -1, -1);
    const bool ok = CoreColour(bgr, centre, radius, &fast);
    ASSERT_EQ(ok, CoreColourPerPixel(bgr, centre, radius, &reference)) << trial;
    if (!ok) continue;
    ++measured;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(fast[c], reference[c]) << trial;
  }
  EXPECT_GT(measured, 500);
}

// NoRivalReachable is "RivalIn can find nothing in the whole window": on a map of that window
// flat but for its peak, every placement beyond the rival radius is a distinct peak RivalIn
// takes, so it finds one exactly when NoRivalReachable says one is reachable.
TEST(TemplateParts, NoRivalReachableIsRivalInOnAFlatWindow) {
  for (int margin = 1; margin <= 9; ++margin) {
    for (int radius = 2; radius <= 20; ++radius) {
      for (int dy = -4; dy <= 4; ++dy) {
        for (int dx = -4; dx <= 4; ++dx) {
          if (std::abs(dx) > margin || std::abs(dy) > margin) continue;
          cv::Mat map(2 * margin + 1, 2 * margin + 1, CV_32F, cv::Scalar(0));
          const cv::Point best(margin + dx, margin + dy);
          map.at<float>(best) = 1;
          cv::Point rival;
          EXPECT_EQ(RivalIn(map, best, radius, &rival),
                    !NoRivalReachable(margin, {dx, dy}, radius))
              << margin << " " << radius << " " << dx << " " << dy;
        }
      }
    }
  }
  EXPECT_EQ(RivalRadius(cv::Size(32, 32)), 16);
  EXPECT_EQ(RivalRadius(cv::Size(21, 40)), 10);
  EXPECT_EQ(RivalRadius(cv::Size(3, 3)), 2);
}

// Every 8-bit BGR colour once: a 4096 x 4096 image.
cv::Mat EveryBgrColour() {
  cv::Mat every(4096, 4096, CV_8UC3);
  for (int y = 0; y < every.rows; ++y) {
    cv::Vec3b* row = every.ptr<cv::Vec3b>(y);
    for (int x = 0; x < every.cols; ++x) {
      const int i = y * every.cols + x;
      row[x] = cv::Vec3b(static_cast<uint8_t>(i), static_cast<uint8_t>(i >> 8),
                         static_cast<uint8_t>(i >> 16));
    }
  }
  return every;
}

// The vector chroma channel against its scalar reference, within a level: every 8-bit colour, on
// axes whose levels stay inside 0..255 and ones that saturate both ways, then views of every
// width from 1 to 40 px (the 16-pixel loop's tail) on random pixels.
TEST(TemplateParts, ChromaChannelIsTheReferences) {
  const cv::Mat every = EveryBgrColour();
  std::vector<ChromaAxis> axes;
  cv::RNG rng(45);
  for (double span : {kMinChromaSpan, 0.1, 0.3, 0.7, 1.2}) {
    ChromaAxis a;
    const cv::Vec3d bg(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
    a.background = bg / (bg[0] + bg[1] + bg[2]);
    const cv::Vec3d axis(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
    a.axis = axis / std::sqrt(axis.dot(axis));
    a.span = span;
    axes.push_back(a);
  }
  // One learned from a green disc on gray, as the tracker learns it.
  cv::Mat selection(32, 32, CV_8UC3, cv::Scalar(120, 120, 120));
  cv::circle(selection, {16, 16}, 9, cv::Scalar(40, 200, 60), cv::FILLED);
  ChromaAxis learned;
  ASSERT_TRUE(LearnChromaAxis(selection, &learned));
  axes.push_back(learned);
  cv::Mat fast, reference, difference;
  for (const ChromaAxis& a : axes) {
    ChromaChannel(every, a, fast);
    ChromaChannelReference(every, a, reference);
    // Float lanes against the double reference: a level apart at most, and seldom.
    cv::absdiff(fast, reference, difference);
    double most = 0;
    cv::minMaxLoc(difference, nullptr, &most);
    EXPECT_LE(most, 1.0) << a.axis << " " << a.span;
    EXPECT_LE(cv::countNonZero(difference), static_cast<int>(every.total() / 1000))
        << a.axis << " " << a.span;
  }
  cv::Mat noise(24, 60, CV_8UC3);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  for (int width = 1; width <= 40; ++width) {
    for (const ChromaAxis& a : axes) {
      const cv::Mat view = noise(cv::Rect(width % 7, 3, width, 17));
      ChromaChannel(view, a, fast);
      ChromaChannelReference(view, a, reference);
      ASSERT_EQ(fast.size(), view.size());
      cv::absdiff(fast, reference, difference);
      double most = 0;
      cv::minMaxLoc(difference, nullptr, &most);
      EXPECT_LE(most, 1.0) << width << " " << a.span;
    }
  }
}

// The vector projection against its scalar reference, bit for bit (every 8-bit colour, on the
// axes ContrastProjection learns and ones with negative weights; views of every width 1-40 px,
// the overlapping last vector; gray runs, looked up), and against cv::transform within a level.
TEST(TemplateParts, ProjectLevelsIsTheReferences) {
  const cv::Mat every = EveryBgrColour();
  std::vector<cv::Mat> projections;
  cv::Mat selection(32, 32, CV_8UC3, cv::Scalar(120, 120, 120));
  cv::circle(selection, {16, 16}, 9, cv::Scalar(40, 200, 60), cv::FILLED);
  projections.push_back(ContrastProjection(selection));
  cv::Mat gray_selection(32, 32, CV_8UC3, cv::Scalar(30, 30, 30));
  cv::circle(gray_selection, {16, 16}, 9, cv::Scalar(220, 220, 220), cv::FILLED);
  projections.push_back(ContrastProjection(gray_selection));
  projections.push_back((cv::Mat_<float>(1, 4) << 0.5f, -0.3f, 0.2f, 76.5f));
  projections.push_back((cv::Mat_<float>(1, 4) << -0.2f, -0.2f, 0.6f, 102.0f));
  projections.push_back((cv::Mat_<float>(1, 4) << 0.7f, 0.7f, 0.7f, -20.0f));  // Saturates.
  // Equal weights: a gray level projects to itself (the gray runs' bytes are copied).
  projections.push_back((cv::Mat_<float>(1, 4) << 1.0f / 3, 1.0f / 3, 1.0f / 3, 0.0f));
  cv::Mat fast, reference, opencv;
  for (const cv::Mat& m : projections) {
    ASSERT_EQ(m.type(), CV_32FC1);
    ProjectLevels(every, m, fast);
    ProjectLevelsReference(every, m, reference);
    ASSERT_EQ(cv::countNonZero(fast != reference), 0) << m;
    cv::transform(every, opencv, m);
    cv::Mat difference;
    cv::absdiff(fast, opencv, difference);
    double most = 0;
    cv::minMaxLoc(difference, nullptr, &most);
    EXPECT_LE(most, 1.0) << m;
  }
  cv::Mat noise(24, 60, CV_8UC3);
  cv::RNG rng(45);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  for (int width = 1; width <= 40; ++width) {
    for (const cv::Mat& m : projections) {
      const cv::Mat view = noise(cv::Rect(width % 7, 3, width, 17));
      ProjectLevels(view, m, fast);
      ProjectLevelsReference(view, m, reference);
      ASSERT_EQ(fast.size(), view.size());
      EXPECT_EQ(cv::countNonZero(fast != reference), 0) << width << " " << m;
    }
  }
  // Gray pixels (b == g == r, looked up in a table of the projection's levels, 16 at a time)
  // beside colour ones: every level, runs of 16 gray pixels broken by one channel off by one at
  // each place of the run, on each channel; the projections alternating, as the trackers of a
  // session call them.
  cv::Mat levels(24, 64, CV_8U);
  for (int i = 0; i < static_cast<int>(levels.total()); ++i) levels.data[i] = (i * 7) & 255;
  cv::Mat gray;
  cv::cvtColor(levels, gray, cv::COLOR_GRAY2BGR);
  for (int y = 0; y < gray.rows; y += 2) {
    cv::Vec3b& p = gray.at<cv::Vec3b>(y, (5 * y) % gray.cols);
    p[y % 3] = static_cast<uchar>(p[y % 3] ^ 1);
  }
  for (int round = 0; round < 2; ++round) {
    for (int width = 1; width <= 48; ++width) {
      for (const cv::Mat& m : projections) {
        const cv::Mat view = gray(cv::Rect(width % 11, 1, width, 21));
        ProjectLevels(view, m, fast);
        ProjectLevelsReference(view, m, reference);
        ASSERT_EQ(fast.size(), view.size());
        EXPECT_EQ(cv::countNonZero(fast != reference), 0) << width << " " << m;
      }
    }
  }
}

// The fused template blend against getRectSubPix, addWeighted and convertTo: gray patches of
// widths 3-40 (the 8-pixel loop, its scalar tail, the reference below 8) at sub-pixel centres
// and at the image's edge (the reference's border), blended ten times in a row, and colour.
TEST(TemplateParts, BlendPatchIsTheReferences) {
  cv::RNG rng(45);
  cv::Mat gray(60, 70, CV_8UC1), bgr(60, 70, CV_8UC3);
  rng.fill(gray, cv::RNG::UNIFORM, 0, 256);
  rng.fill(bgr, cv::RNG::UNIFORM, 0, 256);
  for (const cv::Mat* image : {&gray, &bgr}) {
    for (int width = 3; width <= 40; ++width) {
      const cv::Size size(width, 5 + width % 11);
      cv::Mat start(size, CV_32FC(image->channels()));
      rng.fill(start, cv::RNG::UNIFORM, 0.0, 255.0);
      cv::Mat fast = start.clone(), reference = start.clone(), fast8, reference8, patch;
      for (int k = 0; k < 10; ++k) {
        const bool edge = k == 9;
        const cv::Point2d centre(edge ? 1.3 : rng.uniform(width / 2.0 + 1, 69.0 - width / 2.0 - 2),
                                 rng.uniform(size.height / 2.0 + 1, 59.0 - size.height / 2.0 - 2));
        const double rate = k % 2 ? 0.5 : rng.uniform(0.05, 0.95);
        BlendPatch(*image, centre, rate, fast, fast8, patch);
        BlendPatchReference(*image, centre, rate, reference, reference8, patch);
        ASSERT_EQ(fast.size(), size);
        ASSERT_EQ(fast8.type(), reference8.type());
        cv::Mat difference;
        cv::absdiff(fast, reference, difference);
        double most = 0;
        cv::minMaxLoc(difference.reshape(1), nullptr, &most);
        EXPECT_LE(most, 1e-3) << width << " " << k;
        cv::absdiff(fast8, reference8, difference);
        cv::minMaxLoc(difference.reshape(1), nullptr, &most);
        EXPECT_LE(most, 1.0) << width << " " << k;
      }
    }
  }
}

// The blob measurement's pixel passes in vector lanes against their references: discs of radius
// 2-14 anywhere in a noisy patch (at its edges too), grown boxes of every width from the blob's
// to the patch's: the rim's sums exactly, the soft centroid's within 1e-12 of themselves.
TEST(TemplateParts, BlobPassesAreTheReferences) {
  cv::RNG rng(45);
  std::vector<uint8_t> scratch;
  for (int trial = 0; trial < 300; ++trial) {
    const cv::Size size(rng.uniform(20, 70), rng.uniform(12, 50));
    cv::Mat gray(size, CV_8UC1);
    rng.fill(gray, cv::RNG::UNIFORM, 0, 256);
    cv::Mat label = cv::Mat::zeros(size, CV_8UC1);
    const int radius = rng.uniform(2, 15);
    const cv::Point centre(rng.uniform(1, size.width - 1), rng.uniform(1, size.height - 1));
    cv::circle(label, centre, radius, cv::Scalar(1), cv::FILLED);
    // A component pixel is off the patch's edge (as BlobMeter's fill leaves it).
    label.row(0).setTo(0);
    label.row(size.height - 1).setTo(0);
    label.col(0).setTo(0);
    label.col(size.width - 1).setTo(0);
    const cv::Rect box = cv::boundingRect(label);
    const int grow = rng.uniform(0, 12);
    const cv::Rect grown = cv::Rect(box.x - grow, box.y - grow, box.width + 2 * grow,
                                    box.height + 2 * grow) & cv::Rect(0, 0, size.width, size.height);
    if (grown.empty()) continue;
    cv::Mat dist(size, CV_8UC1, cv::Scalar(9));
    CappedChebyshevDistance(label, grown, dist, scratch);
    const BlobRimSums fast = RimLevelSums(gray, cv::Mat(), dist, label, grown);
    const BlobRimSums reference = RimLevelSumsReference(gray, cv::Mat(), dist, label, grown);
    EXPECT_EQ(fast.fg_sum, reference.fg_sum) << trial;
    EXPECT_EQ(fast.fg_n, reference.fg_n) << trial;
    EXPECT_EQ(fast.bg_sum, reference.bg_sum) << trial;
    EXPECT_EQ(fast.bg_n, reference.bg_n) << trial;
    const double bg = rng.uniform(0.0, 120.0), fg = bg + (trial % 7 == 0 ? 0.5 : rng.uniform(5.0, 130.0));
    for (const auto& [low, high] : {std::pair{bg, fg}, std::pair{fg, bg}}) {
      const SoftCentroidSums a = SoftCentroid(gray, cv::Mat(), dist, grown, low, high);
      const SoftCentroidSums b = SoftCentroidReference(gray, cv::Mat(), dist, grown, low, high);
      EXPECT_NEAR(a.w, b.w, 1e-12 * std::max(1.0, std::abs(b.w))) << trial;
      EXPECT_NEAR(a.x, b.x, 1e-12 * std::max(1.0, std::abs(b.x))) << trial;
      EXPECT_NEAR(a.y, b.y, 1e-12 * std::max(1.0, std::abs(b.y))) << trial;
      // The weights read from the levels' table are the computed ones, added in the same order.
      const SoftCentroidSums c = SoftCentroidComputed(gray, cv::Mat(), dist, grown, low, high);
      EXPECT_EQ(a.w, c.w) << trial;
      EXPECT_EQ(a.x, c.x) << trial;
      EXPECT_EQ(a.y, c.y) << trial;
    }
  }
}

// The look-alike scan's map against the whole map: on noisy pictures of a template's disc
// among twins, other discs and blobs, every placement the whole map scores min_zncc or more at,
// and its 8 neighbours, hold the whole map's value bit for bit.
TEST(TemplateParts, LookAlikeZnccHoldsTheWholeMapsPeaks) {
  cv::RNG rng(45);
  for (int trial = 0; trial < 12; ++trial) {
    cv::Mat image(160, 200, CV_8UC1, cv::Scalar(rng.uniform(30, 90)));
    const int radius = rng.uniform(5, 12);
    for (int k = 0; k < 6; ++k) {
      const cv::Point at(rng.uniform(20, 180), rng.uniform(20, 140));
      cv::circle(image, at, k < 3 ? radius : rng.uniform(3, 16),
                 cv::Scalar(rng.uniform(150, 250)), cv::FILLED, cv::LINE_AA);
    }
    cv::Mat noise(image.size(), CV_8UC1);
    rng.fill(noise, cv::RNG::NORMAL, 0, 6);
    cv::add(image, noise, image);  // Saturating; noise of one sign only is enough here.
    cv::Mat picture(image.size(), CV_8UC1, cv::Scalar(60));
    cv::circle(picture, {100, 80}, radius, cv::Scalar(200), cv::FILLED, cv::LINE_AA);
    const int side = 2 * radius + 9;
    const cv::Mat cut = picture(cv::Rect(100 - side / 2, 80 - side / 2, side, side));
    PreparedTemplate templ, half;
    ASSERT_TRUE(templ.Prepare(cut, RoundMask(cut.size())));
    cv::Mat down;
    cv::pyrDown(cut, down);
    ASSERT_TRUE(half.Prepare(down, RoundMask(down.size())));
    cv::Mat whole, pruned;
    ZnccScratch zncc;
    LookAlikeScratch scratch;
    MatchZncc(image, templ, whole, zncc);
    LookAlikeZncc(image, templ, &half, 0.8, pruned, scratch, zncc);
    ASSERT_EQ(pruned.size(), whole.size());
    int peaks = 0;
    for (int y = 0; y < whole.rows; ++y) {
      for (int x = 0; x < whole.cols; ++x) {
        if (!(whole.at<float>(y, x) >= 0.8f)) continue;
        ++peaks;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const cv::Point p(x + dx, y + dy);
            if (!cv::Rect(0, 0, whole.cols, whole.rows).contains(p)) continue;
            const float a = whole.at<float>(p), b = pruned.at<float>(p);
            EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << trial << " " << p;
          }
        }
      }
    }
    EXPECT_GT(peaks, 0) << trial;
  }
  // Without a half-resolution level: the whole map.
  cv::Mat image(40, 40, CV_8UC1), whole, pruned;
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  PreparedTemplate templ;
  ASSERT_TRUE(templ.Prepare(image(cv::Rect(5, 5, 9, 9)).clone()));
  ZnccScratch zncc;
  LookAlikeScratch scratch;
  MatchZncc(image, templ, whole, zncc);
  LookAlikeZncc(image, templ, nullptr, 0.8, pruned, scratch, zncc);
  EXPECT_EQ(cv::countNonZero(whole != pruned), 0);
}

TEST(TemplateParts, PeakOffsetRecoversTheVertexOfAParabolaAndOfAV) {
  for (const double vertex : {-0.4, -0.1, 0.0, 0.25, 0.45}) {
    const auto parabola = [vertex](double x) { return 10.0 - 3.0 * (x - vertex) * (x - vertex); };
    EXPECT_NEAR(PeakOffset(parabola(-1), parabola(0), parabola(1), false), vertex, 1e-12);
    const auto v = [vertex](double x) { return 10.0 - 2.0 * std::abs(x - vertex); };
    EXPECT_NEAR(PeakOffset(v(-1), v(0), v(1), true), vertex, 1e-12);
  }
}

TEST(TemplateParts, SymmetryCentreOfAnOffCentreDiscIsTheDiscsCentre) {
  // A bright disc drawn at 1/256 px in a 31x31 template, away from its geometric centre (15, 15).
  cv::Mat templ(31, 31, CV_8UC1, cv::Scalar(40));
  const cv::Point2d centre(16.5, 14.25);
  cv::circle(templ, cv::Point(cvRound(centre.x * 256), cvRound(centre.y * 256)), 7 * 256,
             cv::Scalar(220), cv::FILLED, cv::LINE_AA, 8);
  double strength = 0.0;
  const cv::Point2d found = SymmetryCentre(templ, &strength);
  EXPECT_GT(strength, kMinSymmetry);
  EXPECT_NEAR(found.x, centre.x, 0.1);
  EXPECT_NEAR(found.y, centre.y, 0.1);
}

// A disc near one side of a box that also holds a band's bright edge above it and a dark groove
// below (a marker near an actuator's edge): the box's centre of symmetry is pulled off the
// disc, the marker's own is on it.
TEST(TemplateParts, MarkerSymmetryCentreIgnoresWhatElseTheBoxHolds) {
  cv::Mat templ(33, 33, CV_8UC1, cv::Scalar(90));
  cv::rectangle(templ, cv::Rect(0, 0, 33, 5), cv::Scalar(250), cv::FILLED);
  cv::rectangle(templ, cv::Rect(4, 28, 6, 5), cv::Scalar(20), cv::FILLED);
  const cv::Point2d centre(16.25, 16.5);
  cv::circle(templ, cv::Point(cvRound(centre.x * 256), cvRound(centre.y * 256)), 7 * 256,
             cv::Scalar(200), cv::FILLED, cv::LINE_AA, 8);
  double box_strength = 0.0, strength = 0.0;
  const cv::Point2d box = SymmetryCentre(templ, &box_strength);
  EXPECT_GT(cv::norm(box - centre), 0.3) << "the box alone would do: the test shows nothing";
  const cv::Point2d found =
      MarkerSymmetryCentre(templ, centre + cv::Point2d(0.3, -0.2), CV_PI * 49, &strength);
  EXPECT_GT(strength, kMinSymmetry);
  EXPECT_NEAR(found.x, centre.x, 0.1);
  EXPECT_NEAR(found.y, centre.y, 0.1);
}

// A quarter turn of a square template about its centre moves every pixel onto another one
// exactly: the turned rung is cv::rotate's picture, and its anchor turns with it.
TEST(TemplateParts, AQuarterTurnIsExactAndTurnsTheAnchorWithThePicture) {
  cv::Mat templ(21, 21, CV_8UC1);
  cv::randu(templ, 0, 256);
  cv::Mat turned, mask, expected;
  cv::Matx23d map;
  TurnedTemplate(templ, templ.size(), 90.0, cv::Mat(), &turned, &mask, &map);
  cv::rotate(templ, expected, cv::ROTATE_90_CLOCKWISE);  // +x towards +y on the screen.
  EXPECT_EQ(cv::norm(turned, expected, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(mask), 21 * 21);
  // The pixel at (x, y) = (17, 4) lands where cv::rotate puts it: (20 - 4, 17).
  const cv::Point2d p(17, 4);
  const cv::Point2d q(map(0, 0) * p.x + map(0, 1) * p.y + map(0, 2),
                      map(1, 0) * p.x + map(1, 1) * p.y + map(1, 2));
  EXPECT_NEAR(q.x, 16.0, 1e-9);
  EXPECT_NEAR(q.y, 17.0, 1e-9);
  EXPECT_EQ(turned.at<uint8_t>(17, 16), templ.at<uint8_t>(4, 17));
}

// A turned rectangle counts only what turned in from inside it (and inside its round shape).
TEST(TemplateParts, ATurnedRectangleMasksWhatCameFromOutsideIt) {
  const cv::Mat templ(11, 41, CV_8UC1, cv::Scalar(100));
  cv::Mat turned, mask;
  cv::Matx23d map;
  TurnedTemplate(templ, templ.size(), 90.0, cv::Mat(), &turned, &mask, &map);
  // Turned a quarter, the 41 x 11 band stands 11 wide and is cut to the 11 rows: an 11 x 11 core.
  EXPECT_EQ(cv::countNonZero(mask), 11 * 11);
  const cv::Mat round = RoundMask(templ.size());
  TurnedTemplate(templ, templ.size(), 30.0, round, &turned, &mask, &map);
  cv::Mat outside;
  cv::bitwise_and(mask, ~round, outside);
  EXPECT_EQ(cv::countNonZero(outside), 0);
  EXPECT_GT(cv::countNonZero(mask), 0);
  EXPECT_LT(cv::countNonZero(mask), cv::countNonZero(round));
}

// Log-chromaticity is what a shadow leaves: a picture whose right half gets 0.4 of its light
// matches the lit one by about 1 in it, where its gray levels no longer match. Another colour
// pattern does not, nor does a picture without variation (it cannot be judged).
TEST(TemplateParts, LogChromaticityMatchesAPictureAcrossAShadow) {
  cv::Mat lit(21, 21, CV_8UC3, cv::Scalar(150, 190, 215));
  cv::circle(lit, cv::Point(10, 10), 6, cv::Scalar(40, 45, 200), cv::FILLED);
  cv::Mat shaded = lit.clone();
  cv::Mat right = shaded(cv::Rect(8, 0, 13, 21));
  right.convertTo(right, -1, 0.4);
  cv::Mat a, b;
  LogChromaticity(lit, a);
  LogChromaticity(shaded, b);
  ASSERT_EQ(a.type(), CV_32FC2);
  EXPECT_GT(TwoChannelZncc(a, b, cv::Mat()), 0.97);
  // Its gray levels: far apart.
  cv::Mat gray_lit, gray_shaded, gray_zncc;
  cv::cvtColor(lit, gray_lit, cv::COLOR_BGR2GRAY);
  cv::cvtColor(shaded, gray_shaded, cv::COLOR_BGR2GRAY);
  cv::matchTemplate(gray_shaded, gray_lit, gray_zncc, cv::TM_CCOEFF_NORMED);
  EXPECT_LT(gray_zncc.at<float>(0, 0), 0.8);
  // A green disc in the red one's place.
  cv::Mat other(21, 21, CV_8UC3, cv::Scalar(150, 190, 215));
  cv::circle(other, cv::Point(10, 10), 6, cv::Scalar(60, 190, 60), cv::FILLED);
  cv::Mat c;
  LogChromaticity(other, c);
  EXPECT_LT(TwoChannelZncc(a, c, cv::Mat()), 0.5);
  // Only the pixels the mask sets count: outside the disc, both are the same bench.
  cv::Mat ring(21, 21, CV_8UC1, cv::Scalar(255));
  cv::circle(ring, cv::Point(10, 10), 8, cv::Scalar(0), cv::FILLED);
  cv::Mat bench(21, 21, CV_8UC3, cv::Scalar(150, 190, 215)), flat;
  LogChromaticity(bench, flat);
  EXPECT_EQ(TwoChannelZncc(a, flat, ring), kNoRival);
}

}  // namespace
}  // namespace softsight::template_internal
