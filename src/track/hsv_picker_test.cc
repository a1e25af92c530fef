#include "softsight/track/hsv_picker.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "softsight/sim/scene.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {
namespace {

// A 61x61 HSV image: grey-green textured background with a disc of radius 12 at (30, 30) whose
// hue is `hue` +- `hue_jitter` (wrapping through 0), saturation ~200, value ~180, plus noise.
cv::Mat HsvPatchImage(int hue, int hue_jitter, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> jitter(-hue_jitter, hue_jitter);
  std::uniform_int_distribution<int> noise(-12, 12);
  cv::Mat hsv(61, 61, CV_8UC3);
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      const bool inside = (x - 30) * (x - 30) + (y - 30) * (y - 30) <= 12 * 12;
      if (inside) {
        const int h = ((hue + jitter(rng)) % 180 + 180) % 180;
        hsv.at<cv::Vec3b>(y, x) = cv::Vec3b(h, cv::saturate_cast<uchar>(200 + noise(rng)),
                                            cv::saturate_cast<uchar>(180 + noise(rng)));
      } else {
        hsv.at<cv::Vec3b>(y, x) = cv::Vec3b(70, cv::saturate_cast<uchar>(20 + noise(rng)),
                                            cv::saturate_cast<uchar>(120 + noise(rng)));
      }
    }
  }
  return hsv;
}

cv::Mat ToBgr(const cv::Mat& hsv) {
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  return bgr;
}

// Fraction of pixels (in BGR image `bgr`, converted to HSV) accepted by the pick, inside or
// outside the disc of radius `r` around `c`.
double AcceptedFraction(const cv::Mat& bgr, const HsvPick& pick, cv::Point2d c, double r,
                        bool inside) {
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  int total = 0, accepted = 0;
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      const double d2 = (x - c.x) * (x - c.x) + (y - c.y) * (y - c.y);
      if ((d2 <= r * r) != inside) continue;
      ++total;
      accepted += HsvInRange(hsv.at<cv::Vec3b>(y, x), pick.h, pick.s, pick.v);
    }
  }
  return total ? static_cast<double>(accepted) / total : 0.0;
}

TEST(HsvPickerTest, GreenMarkerGivesPlainRangeAroundItsHue) {
  const cv::Mat bgr = ToBgr(HsvPatchImage(60, 3, 1));
  const auto pick = PickHsvRange(bgr, {30, 30}, HsvPickOptions{});
  ASSERT_TRUE(pick);
  EXPECT_LT(pick->h.lo, pick->h.hi);
  // Hue 57..63 (+-1 from the BGR round trip), widened by the 6-unit margin.
  EXPECT_GE(pick->h.lo, 48);
  EXPECT_LE(pick->h.lo, 56);
  EXPECT_GE(pick->h.hi, 64);
  EXPECT_LE(pick->h.hi, 72);
  EXPECT_GE(pick->s.lo, 40);  // Never below min_saturation.
  EXPECT_LE(pick->s.lo, 190 - 40);
  EXPECT_EQ(pick->sample_count, 97);  // Pixels whose centres lie within 5.5 px of the click.
  EXPECT_DOUBLE_EQ(AcceptedFraction(bgr, *pick, {30, 30}, 11, true), 1.0);
  EXPECT_DOUBLE_EQ(AcceptedFraction(bgr, *pick, {30, 30}, 13, false), 0.0);
}

TEST(HsvPickerTest, RedMarkerStraddlingZeroGivesWrappedRange) {
  const cv::Mat bgr = ToBgr(HsvPatchImage(0, 4, 2));  // Hues 176..179 and 0..4.
  const auto pick = PickHsvRange(bgr, {30, 30}, HsvPickOptions{});
  ASSERT_TRUE(pick);
  EXPECT_GT(pick->h.lo, pick->h.hi) << pick->h.lo << ".." << pick->h.hi;
  // 5th..95th percentile of 176..4 (+-1 from the BGR round trip), widened by the 6-unit margin.
  EXPECT_GE(pick->h.lo, 163);
  EXPECT_LE(pick->h.lo, 172);
  EXPECT_GE(pick->h.hi, 8);
  EXPECT_LE(pick->h.hi, 17);
  EXPECT_LE(pick->hue_spread, 10.0);  // Measured around the circle, not 0..179.
  EXPECT_DOUBLE_EQ(AcceptedFraction(bgr, *pick, {30, 30}, 11, true), 1.0);
  EXPECT_DOUBLE_EQ(AcceptedFraction(bgr, *pick, {30, 30}, 13, false), 0.0);
}

TEST(HsvPickerTest, RedMarkerJustBelowZeroWrapsOnlyThroughMargin) {
  const cv::Mat bgr = ToBgr(HsvPatchImage(174, 3, 3));  // 171..177, margin reaches past 179.
  const auto pick = PickHsvRange(bgr, {30, 30}, HsvPickOptions{});
  ASSERT_TRUE(pick);
  EXPECT_GT(pick->h.lo, pick->h.hi);
  EXPECT_GE(pick->h.lo, 160);
  EXPECT_LE(pick->h.hi, 5);
}

TEST(HsvPickerTest, FewRimOutliersDoNotStretchTheRange) {
  // Radius 5 disc around a point 4 px from the edge of the red disc: some background pixels and a
  // few blue specks are sampled, but the hue range stays red.
  cv::Mat hsv = HsvPatchImage(0, 2, 4);
  hsv.at<cv::Vec3b>(28, 30) = cv::Vec3b(120, 220, 200);  // Blue specks inside the sampled disc.
  hsv.at<cv::Vec3b>(32, 31) = cv::Vec3b(120, 220, 200);
  std::vector<cv::Vec3b> samples;
  for (int y = 25; y <= 35; ++y) {
    for (int x = 25; x <= 35; ++x) samples.push_back(hsv.at<cv::Vec3b>(y, x));
  }
  const auto pick = PickHsvFromSamples(samples, HsvPickOptions{});
  ASSERT_TRUE(pick);
  EXPECT_GT(pick->h.lo, pick->h.hi);
  EXPECT_FALSE(HsvInRange(cv::Vec3b(120, 220, 200), pick->h, pick->s, pick->v));
  EXPECT_TRUE(HsvInRange(cv::Vec3b(179, 200, 180), pick->h, pick->s, pick->v));
  EXPECT_TRUE(HsvInRange(cv::Vec3b(1, 200, 180), pick->h, pick->s, pick->v));
}

TEST(HsvPickerTest, GreyPatchOrClickOutsideGivesNoRange) {
  const cv::Mat bgr = ToBgr(HsvPatchImage(0, 2, 5));
  std::string why;
  EXPECT_FALSE(PickHsvRange(bgr, {5, 5}, HsvPickOptions{}, &why));  // Background: grey.
  EXPECT_NE(why.find("not a coloured marker"), std::string::npos) << why;
  EXPECT_FALSE(PickHsvRange(bgr, {-50, 10}, HsvPickOptions{}, &why));
  EXPECT_NE(why.find("outside the image"), std::string::npos) << why;
  EXPECT_FALSE(PickHsvFromSamples({}, HsvPickOptions{}, &why));
}

// Brightness follows the light: the value range reaches down to 0.4 of the sampled values and up
// to 255, so the marker, picked at value ~180, is still in range when its light falls to 45 % or
// rises; hue and saturation keep their margins. darkest_light 1 keeps the additive margin only.
TEST(HsvPickerTest, TheValueRangeFollowsTheLight) {
  const cv::Mat hsv = HsvPatchImage(60, 3, 1);
  const auto pick = PickHsvRange(ToBgr(hsv), {30, 30}, HsvPickOptions{});
  ASSERT_TRUE(pick);
  // 5th percentile of value ~170 (180 - noise): 0.4 of it is ~68.
  EXPECT_GE(pick->v.lo, 60);
  EXPECT_LE(pick->v.lo, 72);
  EXPECT_EQ(pick->v.hi, 255);
  for (const double gain : {0.45, 1.35}) {
    cv::Mat relit = hsv.clone();
    for (auto it = relit.begin<cv::Vec3b>(); it != relit.end<cv::Vec3b>(); ++it) {
      (*it)[2] = cv::saturate_cast<uchar>((*it)[2] * gain);
    }
    EXPECT_DOUBLE_EQ(AcceptedFraction(ToBgr(relit), *pick, {30, 30}, 11, true), 1.0) << gain;
    EXPECT_DOUBLE_EQ(AcceptedFraction(ToBgr(relit), *pick, {30, 30}, 13, false), 0.0) << gain;
  }
  HsvPickOptions margin_only;
  margin_only.darkest_light = 1.0;
  const auto tight = PickHsvRange(ToBgr(hsv), {30, 30}, margin_only);
  ASSERT_TRUE(tight);
  EXPECT_GE(tight->v.lo, 110);  // ~170 - 50.
  EXPECT_LE(tight->v.lo, 125);
}

TEST(HsvPickerTest, OptionsCheckNamesTheField) {
  std::string error;
  EXPECT_TRUE(HsvPickOptions{}.Check(&error));
  HsvPickOptions o;
  o.low_percentile = 60;
  o.high_percentile = 40;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("low_percentile"), std::string::npos);
  o = {};
  o.hue_margin = 95;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("hue_margin"), std::string::npos);
  o = {};
  o.darkest_light = 0.0;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("darkest_light"), std::string::npos);
  o = {};
  o.radius_px = -1;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("radius_px"), std::string::npos);
}

TEST(HsvPickerTest, RenderedSceneMarkersArePickedAndSeparated) {
  SceneOptions scene;
  scene.size = cv::Size(320, 240);
  scene.length_px = 160;
  scene.width_px = 24;
  scene.marker_radius_px = 8;
  scene.frame_count = 2;
  SyntheticScene renderer(scene, NoiseOptions{.sigma = 3.0});
  cv::Mat image;
  const SceneTruth truth = renderer.render(1, image);
  ASSERT_EQ(truth.markers.size(), 3u);
  for (const MarkerTruth& marker : truth.markers) {
    ASSERT_TRUE(marker.centroid_px) << marker.name;
    const auto pick = PickHsvRange(image, *marker.centroid_px, HsvPickOptions{});
    ASSERT_TRUE(pick) << marker.name;
    if (marker.name == "red") {
      EXPECT_GT(pick->h.lo, pick->h.hi) << "red wraps through 0";
    }
    // The marker's interior is accepted, everything away from it (background, body, the other
    // markers) is not.
    EXPECT_GE(AcceptedFraction(image, *pick, *marker.centroid_px, 6, true), 0.97) << marker.name;
    EXPECT_LE(AcceptedFraction(image, *pick, *marker.centroid_px, 11, false), 0.002) << marker.name;
  }
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

// A disc of `level` (radius 8) on a gray background of 110 with a little noise.
cv::Mat GrayDotImage(int level) {
  cv::Mat image(80, 80, CV_8UC3, cv::Scalar::all(110));
  cv::Mat noise(image.size(), CV_8UC3);
  cv::randu(noise, 0, 6);
  image += noise;
  cv::circle(image, {40, 40}, 8, cv::Scalar::all(level), cv::FILLED, cv::LINE_AA);
  return image;
}

TEST(HsvPickerTest, AWhiteOrBlackDotGivesAGrayLevelRangeBetweenItAndItsSurroundings) {
  std::string why;
  const auto white = PickHsvRange(GrayDotImage(235), {40, 40}, HsvPickOptions{}, &why);
  ASSERT_TRUE(white) << why;
  ASSERT_TRUE(white->gray);
  EXPECT_EQ(white->gray->hi, 255);
  EXPECT_GT(white->gray->lo, 120);  // Above the background ...
  EXPECT_LT(white->gray->lo, 230);  // ... and below the dot.
  EXPECT_EQ(PickName(*white), "white");
  const auto black = PickHsvRange(GrayDotImage(20), {40, 40}, HsvPickOptions{}, &why);
  ASSERT_TRUE(black) << why;
  ASSERT_TRUE(black->gray);
  EXPECT_EQ(black->gray->lo, 0);
  EXPECT_GT(black->gray->hi, 25);
  EXPECT_LT(black->gray->hi, 105);
  EXPECT_EQ(PickName(*black), "black");
  // The colour tracker built from the pick finds the dot.
  MarkerColourPick pick;
  pick.ranges = *white;
  pick.roi = cv::Rect(24, 24, 32, 32);
  ColourParams colour;
  ApplyColourPick(pick, &colour);
  EXPECT_TRUE(colour.gray);
  // Plain background (no dot) stays refused, saying why.
  cv::Mat plain(80, 80, CV_8UC3, cv::Scalar::all(110));
  EXPECT_FALSE(PickHsvRange(plain, {40, 40}, HsvPickOptions{}, &why));
  EXPECT_NE(why.find("not a coloured marker"), std::string::npos) << why;
  EXPECT_NE(why.find("nor a white or black dot"), std::string::npos) << why;
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

// An 81x81 white bench (value 240, a warm tint of saturation 0..8) with a green disc of radius
// 10 at (40, 40): saturation 75 +- 8, its top third (y < 37) whitened by the light to
// `top_saturation` +- 3 (a pale dome under a front lamp). `surround_saturation` > 0 paints the
// bench in the disc's own hue at that saturation instead.
cv::Mat PaleDomeImage(int top_saturation, int surround_saturation) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> tint(0, 8), small(-3, 3), noise(-8, 8);
  cv::Mat hsv(81, 81, CV_8UC3);
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      const bool inside = (x - 40) * (x - 40) + (y - 40) * (y - 40) <= 10 * 10;
      cv::Vec3b& p = hsv.at<cv::Vec3b>(y, x);
      if (inside && y < 37) {
        p = cv::Vec3b(60, cv::saturate_cast<uchar>(top_saturation + small(rng)), 245);
      } else if (inside) {
        p = cv::Vec3b(60, cv::saturate_cast<uchar>(75 + noise(rng)), 225);
      } else if (surround_saturation > 0) {
        p = cv::Vec3b(60, cv::saturate_cast<uchar>(surround_saturation + small(rng)), 240);
      } else {
        p = cv::Vec3b(20, cv::saturate_cast<uchar>(tint(rng)), 240);
      }
    }
  }
  return ToBgr(hsv);
}

// The centroid of the pixels the pick accepts within 14 px of (40, 40).
cv::Point2d AcceptedCentroid(const cv::Mat& bgr, const HsvPick& pick) {
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  double n = 0, sx = 0, sy = 0;
  for (int y = 26; y <= 54; ++y) {
    for (int x = 26; x <= 54; ++x) {
      if (HsvInRange(hsv.at<cv::Vec3b>(y, x), pick.h, pick.s, pick.v)) ++n, sx += x, sy += y;
    }
  }
  return n > 0 ? cv::Point2d(sx / n, sy / n) : cv::Point2d(-1, -1);
}

TEST(HsvPickerTest, APaleMarkersFloorDropsTowardsItsPalerSurroundings) {
  // Clicked on its saturated lower part, a pale dome's range reaches down to its whitened top
  // (saturation 32), which the floor of min_saturation cut off: the accepted pixels' centre is
  // the disc's, not 2 px below it; the white bench stays out.
  const cv::Mat image = PaleDomeImage(32, 0);
  const auto pick = PickHsvRange(image, {40, 44}, HsvPickOptions{});
  ASSERT_TRUE(pick);
  EXPECT_LT(pick->s.lo, 32 - 3);
  EXPECT_GT(pick->s.lo, 8);
  EXPECT_LT(cv::norm(AcceptedCentroid(image, *pick) - cv::Point2d(40, 40)), 0.3);
  EXPECT_DOUBLE_EQ(AcceptedFraction(image, *pick, {40, 40}, 12, false), 0.0);
  // The floor of min_saturation would have cut the top off.
  HsvPick cut = *pick;
  cut.s.lo = HsvPickOptions{}.min_saturation;
  EXPECT_GT(AcceptedCentroid(image, cut).y - 40, 1.5);
}

TEST(HsvPickerTest, TheFloorStaysWhereTheSurroundingsShareTheMarkersHueOrNothingWasCut) {
  // A bench of the marker's own hue at saturation 34: a lower floor would let it in.
  const auto on_green = PickHsvRange(PaleDomeImage(32, 34), {40, 44}, HsvPickOptions{});
  ASSERT_TRUE(on_green);
  EXPECT_EQ(on_green->s.lo, HsvPickOptions{}.min_saturation);
  // A saturated disc whose rim the lens blurred all round: a lower floor widens the blob evenly
  // and leaves its centre where it was, so the floor stays.
  cv::Mat blurred;
  cv::GaussianBlur(PaleDomeImage(75, 0), blurred, cv::Size(0, 0), 1.5);
  const auto rim = PickHsvRange(blurred, {40, 40}, HsvPickOptions{});
  ASSERT_TRUE(rim);
  EXPECT_EQ(rim->s.lo, HsvPickOptions{}.min_saturation);
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

// A square image `side` px wide: a dot of radius 9 at its centre, of BGR levels `dot`, on `ground`,
// each pixel's three channels moved by the same noise, uniform in -spread..spread (seed `seed`).
cv::Mat TintedDotImage(int side, cv::Vec3i dot, cv::Vec3i ground, int spread, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> noise(-spread, spread);
  cv::Mat image(side, side, CV_8UC3);
  const int c = side / 2;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3i level = (x - c) * (x - c) + (y - c) * (y - c) <= 9 * 9 ? dot : ground;
      const int n = noise(rng);
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(level[0] + n),
                                            cv::saturate_cast<uchar>(level[1] + n),
                                            cv::saturate_cast<uchar>(level[2] + n));
    }
  }
  return image;
}

TEST(HsvPickerTest, AnInkDotUnderWarmLightIsBlackNotRed) {
  // A black ink dot lit by a warm lamp: levels 5-20, red a few above blue, so its saturation is
  // 100-200 (noise and tint over a tiny value) and its hue the lamp's. It is a black dot.
  const cv::Mat image = TintedDotImage(80, {6, 10, 16}, {70, 100, 130}, 3, 11);
  std::string why;
  const auto pick = PickHsvRange(image, {40, 40}, HsvPickOptions{}, &why);
  ASSERT_TRUE(pick) << why;
  ASSERT_TRUE(pick->gray) << "picked as " << PickName(*pick);
  EXPECT_EQ(PickName(*pick), "black");
  EXPECT_GT(pick->gray->hi, 20);   // Above the dot ...
  EXPECT_LT(pick->gray->hi, 100);  // ... and below the body's gray level (about 107).
}

TEST(HsvPickerTest, AWhiteDotUnderTintedLightOnASurfaceOfItsTintIsWhite) {
  // A white dot under a warm lamp (a camera without white balance): (170, 215, 250), saturation
  // 82, on a darker surface of the same tint (60, 85, 110), saturation 116. Half the dot's pixels
  // and more are "coloured", and the range they give passes the surface too: a blob as large as
  // the surface, no marker. By its gray level (217 against 89) the dot stands out alone.
  const cv::Mat image = TintedDotImage(100, {170, 215, 250}, {60, 85, 110}, 4, 7);
  std::string why;
  const auto coloured = PickHsvFromSamples(
      [&] {
        cv::Mat hsv;
        cv::cvtColor(image(cv::Rect(46, 46, 9, 9)), hsv, cv::COLOR_BGR2HSV);
        return std::vector<cv::Vec3b>(hsv.begin<cv::Vec3b>(), hsv.end<cv::Vec3b>());
      }(),
      HsvPickOptions{}, &why);
  ASSERT_TRUE(coloured) << "the dot's pixels alone read as a colour: " << why;
  const auto pick = PickHsvRange(image, {50, 50}, HsvPickOptions{}, &why);
  ASSERT_TRUE(pick) << why;
  ASSERT_TRUE(pick->gray) << "picked as " << PickName(*pick);
  EXPECT_EQ(PickName(*pick), "white");
  EXPECT_GT(pick->gray->lo, 100);  // Above the surface ...
  EXPECT_LT(pick->gray->lo, 200);  // ... and below the dot.

  // A red dome on white silicone is darker than the silicone too, but its colour range passes
  // nothing around it: it stays a colour.
  cv::Mat red(100, 100, CV_8UC3, cv::Scalar(225, 230, 235));
  cv::circle(red, {50, 50}, 9, cv::Scalar(40, 40, 200), cv::FILLED);
  const auto dome = PickHsvRange(red, {50, 50}, HsvPickOptions{}, &why);
  ASSERT_TRUE(dome) << why;
  EXPECT_FALSE(dome->gray);
  EXPECT_EQ(PickName(*dome), "red");
}

// Paints `colour` over the pixels of `image` in columns [x_from, x_to) that lie between `inner`
// and `outer` px from its centre (a shadow or a lit band beside a TintedDotImage's dot).
void PaintBand(cv::Mat& image, double inner, double outer, int x_from, int x_to,
               const cv::Vec3b& colour) {
  const double c = image.cols / 2;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = x_from; x < x_to; ++x) {
      const double d = std::hypot(x - c, y - c);
      if (d > inner && d < outer) image.at<cv::Vec3b>(y, x) = colour;
    }
  }
}

// A blue dome under a warm lamp without white balance: dim, its channels about 11 levels apart
// (40, 30, 29), too little for a hue by the usual spread, and dark as a black dot; its shadow on
// the wood beside it is as dark. The gray range of a black dot takes the shadow in (the centre
// 1.8 px off on a physically based render); the dome's colour, read with half the spread, does
// not, so the pick is blue.
TEST(HsvPickerTest, ADimBlueDomeBesideItsShadowIsBlueNotBlack) {
  cv::Mat image = TintedDotImage(100, {40, 30, 29}, {40, 90, 150}, 2, 5);
  PaintBand(image, 9.5, 16, 0, 47, {20, 28, 36});  // The shadow, on the left.
  std::string why;
  const auto pick = PickHsvRange(image, {50, 50}, HsvPickOptions{}, &why);
  ASSERT_TRUE(pick) << why;
  EXPECT_FALSE(pick->gray) << "picked as " << PickName(*pick);
  EXPECT_EQ(PickName(*pick), "blue");
}

// An orange dome on a dark actuator under a warm lamp from the right: the lamp lights a band of
// the actuator on the dome's right a dark orange, which its colour range passes (a quarter of its
// near surroundings), while "anything lit", a white dot's gray range, passes none of them. The
// dome's saturation (about 247) is a pigment's, beyond any white's tint: it stays orange. (It was
// taken for a white dot on a physically based render of such a scene, 2-2.8 px off.)
TEST(HsvPickerTest, AnOrangeDomeOnADarkSurfaceLitInItsHueIsOrangeNotWhite) {
  cv::Mat image = TintedDotImage(100, {3, 43, 108}, {4, 6, 10}, 2, 3);
  PaintBand(image, 12, 20, 56, image.cols, {5, 20, 50});  // The lit band, on the right.
  std::string why;
  const auto pick = PickHsvRange(image, {50, 50}, HsvPickOptions{}, &why);
  ASSERT_TRUE(pick) << why;
  EXPECT_FALSE(pick->gray) << "picked as " << PickName(*pick);
  EXPECT_EQ(PickName(*pick), "orange");
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

TEST(HsvPickerTest, AClickOffTheMarkersCentreIsSampledAgainAtItsCentre) {
  // A blue disc of radius 10 at (40, 40) on orange wood, clicked 5 px left of its centre, as a
  // hurried click lands: the first disc of samples holds wood too. The ranges are taken again
  // at the centre of the blob they give, so they hold no wood, and the search box is centred
  // on the marker.
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> noise(-6, 6);
  cv::Mat hsv(81, 81, CV_8UC3);
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      const bool inside = (x - 40) * (x - 40) + (y - 40) * (y - 40) <= 10 * 10;
      hsv.at<cv::Vec3b>(y, x) =
          inside ? cv::Vec3b(110 + noise(rng) / 3, cv::saturate_cast<uchar>(200 + noise(rng)), 150)
                 : cv::Vec3b(14 + noise(rng) / 3, cv::saturate_cast<uchar>(150 + noise(rng)), 170);
    }
  }
  const cv::Mat image = ToBgr(hsv);
  std::string why;
  const auto pick = PickMarkerColourAt(image, {35, 40}, HsvPickOptions{}, 24, &why);
  ASSERT_TRUE(pick) << why;
  EXPECT_LT(cv::norm(pick->ranges.sampled_at_px - cv::Point2d(40, 40)), 0.5);
  EXPECT_FALSE(pick->ranges.h.contains_hue(14)) << pick->ranges.h.lo << ".." << pick->ranges.h.hi;
  EXPECT_TRUE(pick->ranges.h.contains_hue(110));
  EXPECT_EQ(pick->roi, cv::Rect(28, 28, 24, 24));
  // A click within 2 px of the centre samples where it landed.
  const auto near = PickHsvRange(image, {41, 39}, HsvPickOptions{});
  ASSERT_TRUE(near);
  EXPECT_EQ(near->sampled_at_px, cv::Point2d(41, 39));
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

TEST(HsvPickerTest, AClickNearADotsRimFindsTheDot) {
  // 5 px off the centre of a white dot of radius 8: the disc of samples is half bench, so the
  // dot does not stand out from it; the half disc at the click does, and the ranges are taken
  // at the dot's centre.
  std::string why;
  const auto white = PickHsvRange(GrayDotImage(235), {45, 40}, HsvPickOptions{}, &why);
  ASSERT_TRUE(white) << why;
  ASSERT_TRUE(white->gray);
  EXPECT_EQ(PickName(*white), "white");
  EXPECT_LT(cv::norm(white->sampled_at_px - cv::Point2d(40, 40)), 0.5);
}

}  // namespace
}  // namespace softsight
