// The colour kernels against their references: every one of the 2^24 BGR colours for the HSV
// test (vector kernel, scalar reference and OpenCV's cvtColor + inRange all agree), random masks
// and strided views for the morphology.
#include "track/colour_kernels.h"
#include "track/chromaticity.h"
#include "track/colour_tracker_parts.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace softsight {
namespace {

// All colours with blue = `b`: a 256x256 image, green down the rows, red along the columns.
cv::Mat ColoursWithBlue(int b) {
  cv::Mat image(256, 256, CV_8UC3);
  for (int g = 0; g < 256; ++g) {
    cv::Vec3b* row = image.ptr<cv::Vec3b>(g);
    for (int r = 0; r < 256; ++r) row[r] = cv::Vec3b(static_cast<uchar>(b), static_cast<uchar>(g),
                                                      static_cast<uchar>(r));
  }
  return image;
}

std::string Name(const HsvBox& box) {
  return "h [" + std::to_string(box.h.lo) + ", " + std::to_string(box.h.hi) + "] s [" +
         std::to_string(box.s.lo) + ", " + std::to_string(box.s.hi) + "] v [" +
         std::to_string(box.v.lo) + ", " + std::to_string(box.v.hi) + "]";
}

TEST(ColourKernels, ExactHsvIsOpenCvsForEveryColour) {
  cv::Mat hsv;
  for (int b = 0; b < 256; ++b) {
    const cv::Mat image = ColoursWithBlue(b);
    cv::cvtColor(image, hsv, cv::COLOR_BGR2HSV);
    int mismatches = 0;
    for (int g = 0; g < 256; ++g) {
      for (int r = 0; r < 256; ++r) {
        mismatches += BgrToHsvExact(static_cast<uchar>(b), static_cast<uchar>(g),
                                    static_cast<uchar>(r)) != hsv.at<cv::Vec3b>(g, r);
      }
    }
    ASSERT_EQ(mismatches, 0) << "blue " << b;
  }
}

TEST(ColourKernels, VectorHsvTestIsOpenCvsForEveryColour) {
  const HsvBox boxes[] = {
      {{170, 10}, {80, 255}, {40, 255}},   // red, wrapping
      {{45, 85}, {80, 255}, {40, 255}},    // green
      {{100, 130}, {104, 255}, {88, 255}}, // blue, auto_colour-like
      {{0, 179}, {0, 40}, {200, 255}},     // white: any hue
      {{160, 155}, {1, 254}, {1, 254}},    // almost every hue, wrapping across 150
      {{140, 165}, {30, 200}, {10, 250}},  // across the hue 150 seam
      {{0, 0}, {0, 0}, {0, 255}},          // hue 0 only, gray pixels
  };
  cv::Mat fast(256, 256, CV_8U), reference;
  for (const HsvBox& box : boxes) {
    const HsvClassifier classifier(box);
    int mismatches = 0;
    for (int b = 0; b < 256; ++b) {
      const cv::Mat image = ColoursWithBlue(b);
      classifier.Classify(image, fast);
      ClassifyHsvOpenCv(image, box, reference);
      mismatches += cv::countNonZero(fast != reference);
    }
    EXPECT_EQ(mismatches, 0) << Name(box);
  }
}

TEST(ColourKernels, ScalarReferenceAndStridedViews) {
  cv::RNG rng(7);
  cv::Mat big(61, 203, CV_8UC3);
  rng.fill(big, cv::RNG::UNIFORM, 0, 256);
  // Saturated, hue-rich pixels too, not only the gray-ish mean of uniform noise.
  for (int y = 0; y < big.rows; y += 2) {
    for (int x = 0; x < big.cols; ++x) big.at<cv::Vec3b>(y, x)[x % 3] = 255;
  }
  const HsvBox box{{170, 10}, {60, 255}, {40, 255}};
  const HsvClassifier classifier(box);
  for (const cv::Rect& r : {cv::Rect(0, 0, 203, 61), cv::Rect(3, 5, 37, 11), cv::Rect(1, 1, 15, 3),
                            cv::Rect(190, 50, 13, 11)}) {
    const cv::Mat view = big(r);
    cv::Mat fast(view.size(), CV_8U), scalar(view.size(), CV_8U), reference;
    classifier.Classify(view, fast);
    classifier.ClassifyScalar(view, scalar);
    ClassifyHsvOpenCv(view, box, reference);
    EXPECT_EQ(cv::countNonZero(fast != reference), 0) << r;
    EXPECT_EQ(cv::countNonZero(scalar != reference), 0) << r;
  }
}

TEST(ColourKernels, GrayFramesHandedOverAsBgrAreClassifiedAsTheScalarReference) {
  // A gray recording converted to BGR (b == g == r everywhere): whole chunks of 16 flat pixels
  // take the vector path's flat shortcut; rows with a few coloured pixels take the full test.
  // Every level, every box of the other tests' kinds, rows of several widths, views.
  const HsvBox boxes[] = {
      {{0, 179}, {0, 60}, {170, 255}},     // mire-2's white dots
      {{0, 179}, {0, 40}, {200, 255}},     // white: any hue
      {{0, 0}, {0, 0}, {0, 255}},          // hue 0 only, gray pixels
      {{170, 10}, {0, 255}, {40, 200}},    // red, wrapping, saturation from 0
      {{45, 85}, {80, 255}, {40, 255}},    // green: no gray pixel is in
  };
  cv::RNG rng(45);
  cv::Mat levels(40, 300, CV_8U);
  rng.fill(levels, cv::RNG::UNIFORM, 0, 256);
  for (int x = 0; x < 256; ++x) levels.at<uchar>(0, x) = static_cast<uchar>(x);  // Every level.
  cv::Mat gray;
  cv::cvtColor(levels, gray, cv::COLOR_GRAY2BGR);
  cv::Mat mixed = gray.clone();
  for (int y = 1; y < mixed.rows; y += 3) mixed.at<cv::Vec3b>(y, (7 * y) % mixed.cols)[1] ^= 9;
  for (const HsvBox& box : boxes) {
    const HsvClassifier classifier(box);
    for (const cv::Mat* image : {&gray, &mixed}) {
      for (const cv::Rect& r : {cv::Rect(0, 0, 300, 40), cv::Rect(3, 5, 37, 11),
                                cv::Rect(1, 1, 15, 3), cv::Rect(0, 0, 16, 40),
                                cv::Rect(250, 2, 50, 30)}) {
        const cv::Mat view = (*image)(r);
        cv::Mat fast(view.size(), CV_8U), scalar(view.size(), CV_8U), reference;
        classifier.Classify(view, fast);
        classifier.ClassifyScalar(view, scalar);
        ClassifyHsvOpenCv(view, box, reference);
        EXPECT_EQ(cv::countNonZero(fast != scalar), 0) << Name(box) << " " << r;
        EXPECT_EQ(cv::countNonZero(scalar != reference), 0) << Name(box) << " " << r;
      }
    }
  }
}

TEST(ColourKernels, AFlatRegionsPlaneIsClassifiedAsItsBgrPixels) {
  // ExtractFlatPlane finds a gray recording handed over as BGR and gives its plane; ClassifyFlat
  // of the plane is Classify of the BGR pixels (and its scalar reference) for every level and
  // box, in rows of several widths and views. A pixel with b, g, r not all equal anywhere (first
  // chunk, a row's overlapping last chunk, the scalar tail) makes the region not flat.
  const HsvBox boxes[] = {
      {{0, 179}, {0, 60}, {170, 255}},  {{0, 179}, {0, 40}, {200, 255}},
      {{0, 0}, {0, 0}, {0, 255}},       {{170, 10}, {0, 255}, {40, 200}},
      {{45, 85}, {80, 255}, {40, 255}}, {{0, 179}, {1, 255}, {0, 255}},
  };
  cv::RNG rng(45);
  cv::Mat levels(40, 300, CV_8U);
  rng.fill(levels, cv::RNG::UNIFORM, 0, 256);
  for (int x = 0; x < 256; ++x) levels.at<uchar>(0, x) = static_cast<uchar>(x);  // Every level.
  cv::Mat bgr;
  cv::cvtColor(levels, bgr, cv::COLOR_GRAY2BGR);
  for (const cv::Rect& r : {cv::Rect(0, 0, 300, 40), cv::Rect(3, 5, 37, 11), cv::Rect(1, 1, 15, 3),
                            cv::Rect(0, 0, 16, 40), cv::Rect(250, 2, 50, 30)}) {
    const cv::Mat view = bgr(r);
    cv::Mat plane(view.size(), CV_8U), reference_plane(view.size(), CV_8U);
    ASSERT_TRUE(ExtractFlatPlane(view, plane)) << r;
    ASSERT_TRUE(ExtractFlatPlaneReference(view, reference_plane)) << r;
    EXPECT_EQ(cv::countNonZero(plane != levels(r)), 0) << r;
    EXPECT_EQ(cv::countNonZero(reference_plane != levels(r)), 0) << r;
    for (const HsvBox& box : boxes) {
      const HsvClassifier classifier(box);
      cv::Mat flat(view.size(), CV_8U), flat_scalar(view.size(), CV_8U), of_bgr(view.size(), CV_8U);
      classifier.ClassifyFlat(plane, flat);
      classifier.ClassifyFlatScalar(plane, flat_scalar);
      classifier.Classify(view, of_bgr);
      EXPECT_EQ(cv::countNonZero(flat != flat_scalar), 0) << Name(box) << " " << r;
      EXPECT_EQ(cv::countNonZero(flat != of_bgr), 0) << Name(box) << " " << r;
    }
    // One channel of one pixel off: first pixel, middle, a row's end, the last pixel.
    for (const cv::Point at : {cv::Point(0, 0), cv::Point(r.width / 2, r.height / 2),
                               cv::Point(r.width - 1, 0), cv::Point(r.width - 1, r.height - 1)}) {
      for (int channel = 0; channel < 3; ++channel) {
        cv::Mat changed = view.clone();
        changed.at<cv::Vec3b>(at)[channel] ^= 1;
        EXPECT_FALSE(ExtractFlatPlane(changed, plane)) << r << " " << at << " " << channel;
        EXPECT_FALSE(ExtractFlatPlaneReference(changed, plane)) << r << " " << at;
      }
    }
  }
}

TEST(ColourKernels, OpenClose3x3IsMorphologyEx) {
  cv::RNG rng(11);
  cv::Mat scratch;
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(1, 9), cv::Size(9, 1), cv::Size(17, 5),
                              cv::Size(16, 16), cv::Size(31, 7), cv::Size(64, 48),
                              cv::Size(83, 29)}) {
    for (const double density : {0.1, 0.5, 0.9}) {
      for (const bool cross : {true, false}) {
        cv::Mat noise(size, CV_32F), mask;
        rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
        mask = noise < density;
        cv::Mat fast = mask.clone(), reference = mask.clone();
        OpenClose3x3(fast, cross, scratch);
        OpenClose3x3Reference(reference, cross);
        EXPECT_EQ(cv::countNonZero(fast != reference), 0)
            << size << " density " << density << " cross " << cross;
        // On a view into a larger mask: the view's outside counts as the border, its parent's
        // pixels around it are neither read nor written.
        cv::Mat parent(size.height + 4, size.width + 4, CV_8U, cv::Scalar(255));
        const cv::Rect inner(2, 2, size.width, size.height);
        mask.copyTo(parent(inner));
        cv::Mat view = parent(inner);
        OpenClose3x3(view, cross, scratch);
        EXPECT_EQ(cv::countNonZero(parent(inner) != reference), 0) << size << " view";
        EXPECT_EQ(cv::countNonZero(parent == 255), cv::countNonZero(reference) + parent.total() -
                                                       static_cast<size_t>(size.area()))
            << size << " view: parent untouched";
      }
    }
  }
  // The 3x3 ellipse is the cross.
  EXPECT_EQ(cv::countNonZero(cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3)) !=
                             cv::getStructuringElement(cv::MORPH_CROSS, cv::Size(3, 3))),
            0);
}

TEST(ColourKernels, NonZeroBoundsIsTheBoxOfTheNonzeroPixels) {
  cv::RNG rng(9);
  for (int trial = 0; trial < 300; ++trial) {
    const cv::Size size(1 + rng.uniform(0, 70), 1 + rng.uniform(0, 30));
    cv::Mat parent(size.height + 2, size.width + 5, CV_8U, cv::Scalar(255));
    cv::Mat mask = parent(cv::Rect(2, 1, size.width, size.height));
    mask.setTo(0);
    const int dots = rng.uniform(0, 4);
    for (int i = 0; i < dots; ++i) {
      mask.at<uchar>(rng.uniform(0, size.height), rng.uniform(0, size.width)) = 255;
    }
    // The box of the nonzero points themselves.
    std::vector<cv::Point> points;
    cv::findNonZero(mask, points);
    const cv::Rect expected = points.empty() ? cv::Rect() : cv::boundingRect(points);
    EXPECT_EQ(NonZeroBounds(mask), expected) << size << " dots " << dots;
  }
}

TEST(ColourKernels, NonZeroPointsAreFindNonZerosPoints) {
  cv::RNG rng(13);
  std::vector<cv::Point> points, expected;
  for (int trial = 0; trial < 300; ++trial) {
    const cv::Size size(1 + rng.uniform(0, 70), 1 + rng.uniform(0, 30));
    cv::Mat parent(size.height + 2, size.width + 5, CV_8U, cv::Scalar(255));
    cv::Mat mask = parent(cv::Rect(2, 1, size.width, size.height));  // A strided view.
    cv::Mat noise(size, CV_32F);
    rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
    const double density = trial % 3 == 0 ? 0.0 : trial % 3 == 1 ? 0.05 : 0.5;
    cv::Mat(noise < density).copyTo(mask);
    NonZeroPoints(mask, points);
    cv::findNonZero(mask, expected);
    EXPECT_EQ(points, expected) << size << " density " << density;
  }
}

TEST(ColourKernels, MarkOutsideIsAFloodFillFromTheBorder) {
  cv::RNG rng(45);
  std::vector<cv::Point> stack;
  for (int trial = 0; trial < 300; ++trial) {
    const cv::Size size(1 + rng.uniform(0, 50), 1 + rng.uniform(0, 40));
    cv::Mat parent(size.height + 2, size.width + 5, CV_8U, cv::Scalar(7));
    cv::Mat mask = parent(cv::Rect(2, 1, size.width, size.height));  // A strided view.
    cv::Mat noise(size, CV_32F);
    rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
    // Blobs of 255 with holes and channels of 0 of every kind, from sparse to nearly full.
    const double density = 0.1 + 0.2 * (trial % 5);
    cv::Mat(noise < density).copyTo(mask);
    if (trial % 2 == 1 && size.width > 4 && size.height > 4) {
      cv::circle(mask, cv::Point(size.width / 2, size.height / 2),
                 std::min(size.width, size.height) / 3, cv::Scalar(255), 1);  // A closed ring.
    }
    cv::Mat expected = mask.clone();
    MarkOutsideReference(expected, 128);
    MarkOutside(mask, 128, stack);
    EXPECT_EQ(cv::countNonZero(mask != expected), 0) << size << " density " << density;
    EXPECT_EQ(cv::countNonZero(parent.row(0) != 7), 0) << "wrote outside the view";
  }
}

TEST(ColourKernels, EdgeZonesAnswerWhatTheChamferDistanceAnswers) {
  // The measurement asks the chamfer distance d of each pixel (ChamferToEdge) d > 6 (every pixel)
  // and d <= 12 (a pixel outside the blob); EdgeZones' stand-in must answer both as d does, and
  // its vector path must be its reference, on masks of blobs, holes (128) and noise, in views.
  cv::RNG rng(4545);
  cv::Mat scratch;
  for (int trial = 0; trial < 600; ++trial) {
    const cv::Size size(1 + rng.uniform(0, 70), 1 + rng.uniform(0, 50));
    cv::Mat parent(size.height + 2, size.width + 7, CV_8U, cv::Scalar(255));
    cv::Mat own = parent(cv::Rect(3, 1, size.width, size.height));  // A strided view.
    own.setTo(0);
    if (trial % 3 == 0) {
      cv::Mat noise(size, CV_32F);
      rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
      cv::Mat(noise < 0.1 + 0.2 * (trial % 5)).copyTo(own);
    } else {
      const cv::Point centre(rng.uniform(0, size.width), rng.uniform(0, size.height));
      const int radius = 1 + rng.uniform(0, std::max(1, std::min(size.width, size.height)));
      cv::ellipse(own, centre, cv::Size(radius, 1 + rng.uniform(0, radius + 1)),
                  rng.uniform(0.0, 180.0), 0, 360, cv::Scalar(255), cv::FILLED);
    }
    for (int k = rng.uniform(0, 4); k > 0; --k) {  // Holes, filled as FillHoles marks them.
      own.at<uchar>(rng.uniform(0, size.height), rng.uniform(0, size.width)) = 128;
    }
    cv::Mat zones(size, CV_8U, cv::Scalar(99)), reference(size, CV_8U, cv::Scalar(77));
    cv::Mat distance(size, CV_16U);
    EdgeZones(own, zones, scratch);
    EdgeZonesReference(own, reference);
    colour_internal::ChamferToEdge(own, distance);
    cv::Mat differ;
    cv::findNonZero(zones != reference, differ);
    ASSERT_TRUE(differ.empty()) << size << " trial " << trial << ": " << differ.total()
                                << " pixels differ, the first at " << differ.at<cv::Point>(0)
                                << " (" << int(zones.at<uchar>(differ.at<cv::Point>(0))) << " for "
                                << int(reference.at<uchar>(differ.at<cv::Point>(0))) << ")";
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x) {
        const int d = distance.at<uint16_t>(y, x), z = zones.at<uchar>(y, x);
        ASSERT_EQ(d > 6, z > 6) << size << " trial " << trial << " at " << x << "," << y;
        ASSERT_EQ(d > 0, z > 0);
        if (own.at<uchar>(y, x) != 255) {
          ASSERT_EQ(d <= 12, z <= 12) << size << " trial " << trial << " at " << x << "," << y;
        }
      }
    }
    EXPECT_EQ(cv::countNonZero(parent.row(0) != 255), 0) << "wrote outside the view";
  }
}

TEST(ColourKernels, ChromaticityOfLevelsIsChromaticityForEveryColour) {
  int differ = 0;
  for (int b = 0; b < 256; ++b) {
    for (int g = 0; g < 256; ++g) {
      for (int r = 0; r < 256; ++r) {
        const cv::Vec3d table = ChromaticityOfLevels(b, g, r);
        const cv::Vec3d divided = Chromaticity(b, g, r);
        differ += std::memcmp(table.val, divided.val, sizeof(table.val)) != 0;
      }
    }
  }
  EXPECT_EQ(differ, 0);
}

TEST(ColourKernels, RunLabellerFindsConnectedComponentsWithStats) {
  cv::RNG rng(5);
  RunLabeller labeller;
  auto key = [](const RunLabeller::Component& c) {
    return std::vector<int64_t>{c.box.y, c.box.x, c.box.width, c.box.height, c.area,
                                c.m10,   c.m01,   c.m20,       c.m02};
  };
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(40, 1), cv::Size(1, 40), cv::Size(33, 17),
                              cv::Size(64, 64), cv::Size(200, 90)}) {
    // Up to whole rows lit (runs longer than 16 pixels, ending at the row's end).
    for (const double density : {0.0, 0.05, 0.3, 0.6, 0.95, 0.99, 1.0}) {
      cv::Mat noise(size, CV_32F);
      rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
      cv::Mat parent(size.height + 2, size.width + 6, CV_8U, cv::Scalar(255));
      cv::Mat mask = parent(cv::Rect(3, 1, size.width, size.height));  // A strided view.
      cv::Mat(noise < density).copyTo(mask);
      labeller.Label(mask);
      std::vector<RunLabeller::Component> reference = LabelReference(mask);
      std::vector<std::vector<int64_t>> ours, theirs;
      for (const auto& c : labeller.components()) ours.push_back(key(c));
      for (const auto& c : reference) theirs.push_back(key(c));
      std::sort(ours.begin(), ours.end());
      std::sort(theirs.begin(), theirs.end());
      EXPECT_EQ(ours, theirs) << size << " density " << density;
      // Drawing every component gives back the mask.
      cv::Mat drawn(mask.size(), CV_8U, cv::Scalar(0));
      for (size_t i = 0; i < labeller.components().size(); ++i) {
        labeller.Draw(static_cast<int>(i), drawn, cv::Point(0, 0));
      }
      EXPECT_EQ(cv::countNonZero(drawn != mask), 0) << size << " density " << density;
    }
  }
}

}  // namespace
}  // namespace softsight
