#include "geometry/geometry_test_util.h"
#include "softsight/geometry/measurement.h"

#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "softsight/core/error.h"

namespace softsight {
namespace {

using ::testing::DoubleNear;
using ::testing::HasSubstr;
using ::testing::Optional;

using testing::kTol;

MarkerObservation Seen(const std::string& name, double x, double y) {
  return {name, Observation{cv::Point2d(x, y), 1.0}};
}
MarkerObservation Lost(const std::string& name) { return {name, Observation{}}; }

MeasureOptions Triple() {
  MeasureOptions options;
  options.base = "red";
  options.middle = "blue";
  options.tip = "green";
  return options;
}

using testing::OnCircle;

MarkerObservation SeenAt(const std::string& name, cv::Point2d p) { return Seen(name, p.x, p.y); }

TEST(MeasureOptionsTest, AlongBodyTakesTheEndsAndTheMiddleAndChainsMoreThanThree) {
  EXPECT_FALSE(MeasureOptions::AlongBody({"a", "b"}).has_triple());
  EXPECT_TRUE(MeasureOptions::AlongBody({"a", "b"}).chain.empty());
  const MeasureOptions three = MeasureOptions::AlongBody({"base", "mid", "tip"});
  EXPECT_EQ(three.base, "base");
  EXPECT_EQ(three.middle, "mid");
  EXPECT_EQ(three.tip, "tip");
  EXPECT_TRUE(three.chain.empty());
  const MeasureOptions five = MeasureOptions::AlongBody({"m0", "m1", "m2", "m3", "m4"});
  EXPECT_EQ(five.base, "m0");
  EXPECT_EQ(five.middle, "m2");
  EXPECT_EQ(five.tip, "m4");
  EXPECT_EQ(five.chain, (std::vector<std::string>{"m0", "m1", "m2", "m3", "m4"}));
  std::string error;
  EXPECT_TRUE(five.Check(&error)) << error;
  // Four: the middle is the third (n / 2), as init and the scenes always chose.
  EXPECT_EQ(MeasureOptions::AlongBody({"m0", "m1", "m2", "m3"}).middle, "m2");
}

TEST(MeasurerTest, HalfCircleTripleInAnyOrderWithoutMetric) {
  Measurer measurer(Triple());
  const Measurement m = measurer.measure(
      {Seen("green", 140, 100), Seen("red", 60, 100), Seen("blue", 100, 140)});
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(90.0, kTol)));
  EXPECT_THAT(m.chord_px, Optional(DoubleNear(80.0, kTol)));
  EXPECT_THAT(m.sagitta_px, Optional(DoubleNear(40.0, kTol)));
  EXPECT_THAT(m.radius_px, Optional(DoubleNear(40.0, kTol)));
  EXPECT_THAT(m.arc_length_px, Optional(DoubleNear(40.0 * std::numbers::pi, 1e-7)));
  EXPECT_THAT(m.circumradius_px, Optional(DoubleNear(40.0, kTol)));
  EXPECT_THAT(m.tip_disp_px, Optional(DoubleNear(0.0, kTol)));  // First frame: the reference.
  EXPECT_EQ(m.chord_mm, std::nullopt);
  EXPECT_EQ(m.radius_mm, std::nullopt);
  EXPECT_EQ(m.tip_disp_mm, std::nullopt);
}

TEST(MeasurerTest, StraightHasNoRadiusAndArcEqualsChord) {
  Measurer measurer(Triple());
  const Measurement m =
      measurer.measure({Seen("red", 10, 10), Seen("blue", 10, 60), Seen("green", 10, 110)});
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(180.0, kTol)));
  EXPECT_EQ(m.radius_px, std::nullopt);
  EXPECT_EQ(m.circumradius_px, std::nullopt);
  EXPECT_THAT(m.arc_length_px, Optional(DoubleNear(100.0, kTol)));
}

TEST(MeasurerTest, MissingMiddleLeavesOnlyChordAndTipDisplacement) {
  Measurer measurer(Triple());
  const Measurement m = measurer.measure({Seen("red", 0, 0), Lost("blue"), Seen("green", 3, 4)});
  EXPECT_THAT(m.chord_px, Optional(DoubleNear(5.0, kTol)));
  EXPECT_TRUE(m.tip_disp_px.has_value());
  EXPECT_EQ(m.angle_deg, std::nullopt);
  EXPECT_EQ(m.sagitta_px, std::nullopt);
  EXPECT_EQ(m.radius_px, std::nullopt);
  EXPECT_EQ(m.arc_length_px, std::nullopt);
  EXPECT_EQ(m.circumradius_px, std::nullopt);
}

TEST(MeasurerTest, MissingOrUnlistedTipLeavesNothingThatNeedsIt) {
  Measurer measurer(Triple());
  for (const std::vector<MarkerObservation>& markers :
       {std::vector<MarkerObservation>{Seen("red", 0, 0), Seen("blue", 5, 5), Lost("green")},
        std::vector<MarkerObservation>{Seen("red", 0, 0), Seen("blue", 5, 5)}}) {
    const Measurement m = measurer.measure(markers);
    EXPECT_EQ(m.chord_px, std::nullopt);
    EXPECT_EQ(m.angle_deg, std::nullopt);
    EXPECT_EQ(m.arc_length_px, std::nullopt);
    EXPECT_EQ(m.tip_disp_px, std::nullopt);
  }
}

TEST(MeasurerTest, CoincidentMarkersGiveAbsentValues) {
  Measurer measurer(Triple());
  const Measurement m =
      measurer.measure({Seen("red", 20, 20), Seen("blue", 20, 20), Seen("green", 50, 60)});
  EXPECT_EQ(m.angle_deg, std::nullopt);
  EXPECT_EQ(m.sagitta_px, std::nullopt);
  EXPECT_EQ(m.radius_px, std::nullopt);
  EXPECT_EQ(m.arc_length_px, std::nullopt);
  EXPECT_EQ(m.circumradius_px, std::nullopt);
  EXPECT_THAT(m.chord_px, Optional(DoubleNear(50.0, kTol)));
}

TEST(MeasurerTest, TipReferenceIsTheFirstFrameWhereTheTipIsFound) {
  Measurer measurer(Triple());
  EXPECT_EQ(measurer.measure({Seen("red", 0, 0), Lost("green")}).tip_disp_px, std::nullopt);
  EXPECT_THAT(measurer.measure({Seen("green", 100, 100)}).tip_disp_px,
              Optional(DoubleNear(0.0, kTol)));
  EXPECT_THAT(measurer.measure({Seen("green", 103, 104)}).tip_disp_px,
              Optional(DoubleNear(5.0, kTol)));
  EXPECT_EQ(measurer.measure({Lost("green")}).tip_disp_px, std::nullopt);
  EXPECT_THAT(measurer.measure({Seen("green", 94, 92)}).tip_disp_px,
              Optional(DoubleNear(10.0, kTol)));
  // After a reset the next frame where the tip is found becomes the reference.
  measurer.reset_tip_reference();
  EXPECT_EQ(measurer.measure({Lost("green")}).tip_disp_px, std::nullopt);
  EXPECT_THAT(measurer.measure({Seen("green", 50, 50)}).tip_disp_px,
              Optional(DoubleNear(0.0, kTol)));
  EXPECT_THAT(measurer.measure({Seen("green", 50, 57)}).tip_disp_px,
              Optional(DoubleNear(7.0, kTol)));
}

TEST(MeasurerTest, ConfiguredTipReferenceSurvivesAReset) {
  MeasureOptions options = Triple();
  options.tip_reference_px = cv::Point2d(10, 10);
  Measurer measurer(options);
  EXPECT_THAT(measurer.measure({Seen("green", 13, 14)}).tip_disp_px,
              Optional(DoubleNear(5.0, kTol)));
  measurer.reset_tip_reference();
  EXPECT_THAT(measurer.measure({Seen("green", 16, 18)}).tip_disp_px,
              Optional(DoubleNear(10.0, kTol)));
}

TEST(MeasurerTest, ScaleMetricMultipliesEveryLength) {
  MeasureOptions options = Triple();
  options.metric.scale_mm_per_px = 0.2;
  Measurer measurer(options);
  measurer.measure({Seen("green", 140, 110)});  // Sets the tip reference.
  const Measurement m = measurer.measure(
      {Seen("red", 60, 100), Seen("blue", 100, 140), Seen("green", 140, 100)});
  EXPECT_THAT(m.chord_mm, Optional(DoubleNear(16.0, kTol)));
  EXPECT_THAT(m.sagitta_mm, Optional(DoubleNear(8.0, kTol)));
  EXPECT_THAT(m.radius_mm, Optional(DoubleNear(8.0, kTol)));
  EXPECT_THAT(m.arc_length_mm, Optional(DoubleNear(8.0 * std::numbers::pi, 1e-7)));
  EXPECT_THAT(m.tip_disp_mm, Optional(DoubleNear(2.0, kTol)));
}

// Both metric models on the same observations; returns {scale result, homography result}.
std::pair<Measurement, Measurement> MeasureBoth(const MeasureOptions& base_options,
                                                const cv::Matx33d& homography, double scale,
                                                const std::vector<MarkerObservation>& first,
                                                const std::vector<MarkerObservation>& second) {
  MeasureOptions by_scale = base_options;
  by_scale.metric.scale_mm_per_px = scale;
  MeasureOptions by_plane = base_options;
  by_plane.metric.plane_mm_from_image = homography;
  Measurer a(by_scale), b(by_plane);
  a.measure(first);
  b.measure(first);
  return {a.measure(second), b.measure(second)};
}

void ExpectSameMm(const Measurement& a, const Measurement& b) {
  for (const auto& [x, y] : {std::pair{a.chord_mm, b.chord_mm}, {a.sagitta_mm, b.sagitta_mm},
                             {a.radius_mm, b.radius_mm}, {a.arc_length_mm, b.arc_length_mm},
                             {a.tip_disp_mm, b.tip_disp_mm}}) {
    ASSERT_TRUE(x.has_value());
    EXPECT_THAT(y, Optional(DoubleNear(*x, 1e-9 * std::max(1.0, *x))));
  }
}

TEST(MeasurerTest, PureScaleHomographyAgreesWithTheScaleModel) {
  // A rotation by 30 degrees, a scale of 0.25 mm/px and a translation change no length beyond
  // the scale.
  const double s = 0.25, c = std::cos(std::numbers::pi / 6), n = std::sin(std::numbers::pi / 6);
  const cv::Matx33d similarity(s * c, -s * n, 12.0, s * n, s * c, -40.0, 0, 0, 1);
  const cv::Matx33d pure_scale(s, 0, 0, 0, s, 0, 0, 0, 1);
  const std::vector<MarkerObservation> first = {Seen("green", 300, 200)};
  const std::vector<MarkerObservation> second = {
      SeenAt("red", OnCircle({200, 200}, 90, 200)), SeenAt("blue", OnCircle({200, 200}, 90, 90)),
      SeenAt("green", OnCircle({200, 200}, 90, -20))};  // 220 degrees: the major arc.
  for (const cv::Matx33d& h : {pure_scale, similarity, pure_scale * 3.0}) {
    const auto [by_scale, by_plane] = MeasureBoth(Triple(), h, s, first, second);
    ExpectSameMm(by_scale, by_plane);
    EXPECT_THAT(by_plane.radius_mm, Optional(DoubleNear(90.0 * s, 1e-9)));
    EXPECT_THAT(by_plane.arc_length_mm, Optional(DoubleNear(90.0 * s * 220.0 * std::numbers::pi / 180, 1e-9)));
    EXPECT_EQ(by_scale.angle_deg, by_plane.angle_deg);
  }
}

TEST(MeasurerTest, PerspectiveHomographyMeasuresInThePlane) {
  // H maps (x, y) to (x, y) / (1 + x / 1000): base (0, 0) -> (0, 0), tip (500, 0) ->
  // (333.33, 0), so the plane chord is 1000 / 3 mm while the image chord is 500 px.
  const cv::Matx33d h(1, 0, 0, 0, 1, 0, 1e-3, 0, 1);
  MeasureOptions options = Triple();
  options.metric.plane_mm_from_image = h;
  Measurer measurer(options);
  const Measurement m =
      measurer.measure({Seen("red", 0, 0), Seen("blue", 250, 0), Seen("green", 500, 0)});
  EXPECT_THAT(m.chord_px, Optional(DoubleNear(500.0, kTol)));
  EXPECT_THAT(m.chord_mm, Optional(DoubleNear(1000.0 / 3.0, 1e-9)));
  EXPECT_THAT(m.arc_length_mm, Optional(DoubleNear(1000.0 / 3.0, 1e-9)));
  EXPECT_EQ(m.radius_mm, std::nullopt);  // A homography keeps straight lines straight.
}

TEST(MeasurerTest, PointOnTheVanishingLineHasNoPlaneValue) {
  const cv::Matx33d h(1, 0, 0, 0, 1, 0, 1e-3, 0, 1);
  EXPECT_EQ(MapToPlane(h, {-1000, 5}), std::nullopt);
  EXPECT_THAT(MapToPlane(h, {1000, 5}), Optional(cv::Point2d(500, 2.5)));
  MeasureOptions options = Triple();
  options.metric.plane_mm_from_image = h;
  Measurer measurer(options);
  const Measurement m =
      measurer.measure({Seen("red", -1000, 0), Seen("blue", 0, 10), Seen("green", 100, 0)});
  EXPECT_TRUE(m.chord_px.has_value());
  EXPECT_EQ(m.chord_mm, std::nullopt);
  EXPECT_EQ(m.arc_length_mm, std::nullopt);
}

MeasureOptions Chain() {
  MeasureOptions options = Triple();
  options.chain = {"red", "c1", "blue", "c2", "green"};
  return options;
}

std::vector<MarkerObservation> ChainOnCircle(cv::Point2d centre, double radius, double from_deg,
                                             double to_deg) {
  const std::vector<std::string> names = {"red", "c1", "blue", "c2", "green"};
  std::vector<MarkerObservation> markers;
  for (size_t i = 0; i < names.size(); ++i) {
    markers.push_back(SeenAt(names[i], OnCircle(centre, radius, from_deg + (to_deg - from_deg) *
                                                                               i / 4.0)));
  }
  return markers;
}

TEST(MeasurerTest, ChainRadiusAndArcComeFromTheCircleFit) {
  Measurer measurer(Chain());
  // 240 degrees of an 80 px circle: the major arc, 80 * 4 pi / 3.
  const Measurement m = measurer.measure(ChainOnCircle({300, 200}, 80.0, 150.0, -90.0));
  EXPECT_THAT(m.radius_px, Optional(DoubleNear(80.0, 1e-8)));
  EXPECT_THAT(m.arc_length_px, Optional(DoubleNear(80.0 * 4.0 * std::numbers::pi / 3.0, 1e-8)));
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(60.0, 1e-8)));  // From the triple.
}

TEST(MeasurerTest, ChainUsesTheFoundMarkersAndNeedsThree) {
  Measurer measurer(Chain());
  std::vector<MarkerObservation> markers = ChainOnCircle({0, 0}, 50.0, 0.0, 120.0);
  markers[1] = Lost("c1");
  Measurement m = measurer.measure(markers);
  EXPECT_THAT(m.radius_px, Optional(DoubleNear(50.0, 1e-8)));
  EXPECT_THAT(m.arc_length_px, Optional(DoubleNear(50.0 * 2.0 * std::numbers::pi / 3.0, 1e-8)));
  markers[3] = Lost("c2");
  markers[2] = Lost("blue");
  m = measurer.measure(markers);
  EXPECT_EQ(m.radius_px, std::nullopt);
  EXPECT_EQ(m.arc_length_px, std::nullopt);
  EXPECT_THAT(m.chord_px, Optional(DoubleNear(50.0 * std::sqrt(3.0), 1e-8)));
}

TEST(MeasurerTest, StraightChainHasNoRadiusAndArcEqualsFirstToLast) {
  MeasureOptions options = Chain();
  options.metric.scale_mm_per_px = 0.5;
  Measurer measurer(options);
  const Measurement m =
      measurer.measure({Seen("red", 0, 0), Seen("c1", 10, 5), Seen("blue", 20, 10),
                        Seen("c2", 30, 15), Seen("green", 40, 20)});
  EXPECT_EQ(m.radius_px, std::nullopt);
  EXPECT_EQ(m.radius_mm, std::nullopt);
  EXPECT_THAT(m.arc_length_px, Optional(DoubleNear(std::hypot(40.0, 20.0), kTol)));
  EXPECT_THAT(m.arc_length_mm, Optional(DoubleNear(0.5 * std::hypot(40.0, 20.0), kTol)));
}

TEST(MeasurerTest, ChainInThePlaneAgreesWithTheScaleModel) {
  const cv::Matx33d h(0.1, 0, 5, 0, 0.1, 7, 0, 0, 1);
  const std::vector<MarkerObservation> markers = ChainOnCircle({320, 240}, 120.0, 0.0, 200.0);
  const auto [by_scale, by_plane] = MeasureBoth(Chain(), h, 0.1, markers, markers);
  ExpectSameMm(by_scale, by_plane);
  EXPECT_THAT(by_plane.radius_mm, Optional(DoubleNear(12.0, 1e-8)));
}

TEST(MeasurerTest, ChainGivesTheAngleAtEveryInnerMarker) {
  Measurer measurer(Chain());
  EXPECT_EQ(measurer.options().inner_markers(),
            (std::vector<std::string>{"c1", "blue", "c2"}));
  // A zig-zag: right angles at c1 and c2 (computed by hand), 180 at the straight middle.
  std::vector<MarkerObservation> markers = {Seen("red", 0, 0), Seen("c1", 10, 0),
                                            Seen("blue", 10, 10), Seen("c2", 10, 20),
                                            Seen("green", 0, 20)};
  Measurement m = measurer.measure(markers);
  ASSERT_EQ(m.inner_angle_deg.size(), 3u);
  EXPECT_THAT(m.inner_angle_deg[0], Optional(DoubleNear(90.0, kTol)));
  EXPECT_THAT(m.inner_angle_deg[1], Optional(DoubleNear(180.0, kTol)));
  EXPECT_THAT(m.inner_angle_deg[2], Optional(DoubleNear(90.0, kTol)));
  // A lost marker takes the angles it is part of with it: its own and its neighbours'.
  markers[1] = Lost("c1");
  measurer.measure(markers, m);
  ASSERT_EQ(m.inner_angle_deg.size(), 3u);
  EXPECT_EQ(m.inner_angle_deg[0], std::nullopt);
  EXPECT_EQ(m.inner_angle_deg[1], std::nullopt);
  EXPECT_THAT(m.inner_angle_deg[2], Optional(DoubleNear(90.0, kTol)));
  EXPECT_TRUE(Measurer(Triple()).measure(markers).inner_angle_deg.empty());
}

TEST(MeasurerTest, WithoutATripleOnlyTheChainIsMeasured) {
  MeasureOptions none;
  std::string error;
  EXPECT_TRUE(none.Check(&error)) << error;
  Measurer positions_only(none);
  const Measurement m = positions_only.measure({Seen("ball", 3, 4)});
  EXPECT_EQ(m.angle_deg, std::nullopt);
  EXPECT_EQ(m.chord_px, std::nullopt);
  EXPECT_EQ(m.tip_disp_px, std::nullopt);
  EXPECT_TRUE(m.inner_angle_deg.empty());

  MeasureOptions chain_only = Chain();
  chain_only.base.clear();
  chain_only.middle.clear();
  chain_only.tip.clear();
  EXPECT_TRUE(chain_only.Check(&error)) << error;
  Measurer chain(chain_only);
  const Measurement c = chain.measure(ChainOnCircle({300, 200}, 80.0, 150.0, -90.0));
  EXPECT_EQ(c.angle_deg, std::nullopt);
  EXPECT_EQ(c.chord_px, std::nullopt);
  EXPECT_THAT(c.radius_px, Optional(DoubleNear(80.0, 1e-8)));
  ASSERT_EQ(c.inner_angle_deg.size(), 3u);
  // Equally spaced on a circle, 60 degrees of arc apart: each inner angle is 180 - 60.
  for (const auto& angle : c.inner_angle_deg) EXPECT_THAT(angle, Optional(DoubleNear(120.0, 1e-8)));
}

TEST(MeasureOptionsTest, CheckNamesTheBadField) {
  std::string error;
  EXPECT_TRUE(Triple().Check(&error)) << error;
  EXPECT_TRUE(Chain().Check(&error)) << error;

  MeasureOptions o = Triple();
  o.middle.clear();
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("middle"));

  o = Triple();
  o.base.clear();
  o.middle.clear();
  EXPECT_FALSE(o.Check(&error)) << "a triple names all three or none";
  EXPECT_THAT(error, HasSubstr("triple: the base"));

  o = Triple();
  o.tip = "red";
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("three different"));

  o = Triple();
  o.chain = {"red", "green"};
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("chain"));

  o = Chain();
  o.chain[3] = "red";
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("'red'"));

  o = Triple();
  o.metric.scale_mm_per_px = 0.0;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("scale_mm_per_px"));

  o = Triple();
  o.metric.scale_mm_per_px = 0.1;
  o.metric.plane_mm_from_image = cv::Matx33d::eye();
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("not both"));

  o = Triple();
  o.metric.plane_mm_from_image = cv::Matx33d(1, 2, 3, 2, 4, 6, 0, 0, 1);
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("singular"));

  o = Triple();
  o.tip_reference_px = cv::Point2d(std::nan(""), 0);
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("tip_reference"));
}

TEST(MeasureOptionsTest, MeasurerRejectsBadOptionsAsInputError) {
  MeasureOptions o = Triple();
  o.base = "blue";
  EXPECT_THROW(Measurer{o}, InputError);
}

}  // namespace
}  // namespace softsight
