// Footage of the kinds that real lab videos hold and that per-marker rules got wrong, drawn by an
// independent renderer (sim/dot_scene_test_util.h): identical markers on two carts, one
// accelerating to 60 px a frame; a marker at a steady 30 px a frame; identical dots coming into
// view beside a tracked one; a hand-held plate of white dots over clutter. Each asserts found
// rates and that no report is far from the truth (the session's motion model, global assignment
// and track management: pipeline/marker_tracks.h).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/scene_config_test_util.h"
#include "sim/dot_scene_test_util.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/marker_finder.h"
#include "softsight/track/template_tracker.h"

namespace softsight {
namespace {

using testing::DotPose;
using testing::DotScene;
using testing::DotSceneOptions;
using testing::DotShape;

struct SceneScore {
  int frames = 0;   // Frames in which the marker's shape is visible.
  int found = 0;    // ... and it was found within the tolerance.
  int wrong = 0;    // Reports farther than the tolerance from the truth (or while hidden).
  double max_error_px = 0;
  std::string first_wrong;
};

// Runs `config` over `count` frames of `scene`; marker m is shape `shape_of[m]`.
std::vector<SceneScore> TrackScene(const DotScene& scene, const TrackingConfig& config,
                       const std::vector<size_t>& shape_of, int count, double tolerance_px) {
  TrackingSession session(config);
  std::vector<SceneScore> scores(shape_of.size());
  for (int f = 0; f < count; ++f) {
    Frame frame;
    frame.image = scene.render(f);
    frame.index = f;
    frame.time_s = f / 30.0;
    const FrameResult& result = session.process(frame);
    for (size_t m = 0; m < shape_of.size(); ++m) {
      const std::optional<cv::Point2d> truth = scene.truth(shape_of[m], f);
      const Observation& o = result.markers[m].observation;
      SceneScore& s = scores[m];
      if (truth) ++s.frames;
      if (!o.found()) continue;
      const double error = truth ? cv::norm(*o.position_px - *truth) : 1e9;
      if (error <= tolerance_px) {
        ++s.found;
        s.max_error_px = std::max(s.max_error_px, error);
      } else {
        if (s.wrong == 0) {
          s.first_wrong = "frame " + std::to_string(f) + " at (" +
                          std::to_string(o.position_px->x) + ", " +
                          std::to_string(o.position_px->y) + ")";
        }
        ++s.wrong;
      }
    }
  }
  // The measured figures, for the README's and docs' tables.
  for (size_t m = 0; m < scores.size(); ++m) {
    std::printf("[ measured ] %s: found %d of %d within %.1f px (worst %.2f px), %d wrong\n",
                config.markers[m].name.c_str(), scores[m].found, scores[m].frames, tolerance_px,
                scores[m].max_error_px, scores[m].wrong);
  }
  return scores;
}

MarkerSpec YellowDot(const std::string& name, const cv::Rect& roi) {
  MarkerSpec spec = testing::ColourMarker(name, {20, 40});
  spec.params.get<ColourParams>().roi = roi;
  return spec;
}

MarkerSpec WhiteDot(const std::string& name, const cv::Rect& roi) {
  MarkerSpec spec;
  spec.name = name;
  ColourParams& colour = spec.params.get<ColourParams>();
  colour.gray = HsvRange{185, 255};
  colour.roi = roi;
  return spec;
}

// Two carts on one track, each with the same small yellow dot (radius 5 px): the one behind
// accelerates at 6 px/frame^2 to 60 px a frame, the one ahead moves a steady 30 px a frame.
// `exposure`: the shutter's share of the frame time (0.2: a 1/25 s shutter at 5 fps, the fast
// dot a 12 px streak, the slow one 6 px).
DotScene TwoCarts(double exposure = 0.2) {
  DotSceneOptions options;
  options.size = {960, 320};
  options.blur_samples = 4;
  options.exposure = exposure;
  const auto fast = [](double t) {
    const double x = t <= 10 ? 60 + 3 * t * t : 360 + 60 * (t - 10);
    return DotPose{{x, 150}};
  };
  const auto slow = [](double t) { return DotPose{{300 + 30 * t, 150}}; };
  const auto body = [](std::function<DotPose(double)> path) {
    return [path](double t) {
      DotPose p = path(t);
      p.centre_px.y += 12;
      return p;
    };
  };
  std::vector<DotShape> shapes;
  shapes.push_back({{28, 16}, {90, 70, 60}, {}, 0, {}, body(fast)});   // Cart bodies.
  shapes.push_back({{28, 16}, {90, 70, 60}, {}, 0, {}, body(slow)});
  shapes.push_back({{5, 5}, {0, 220, 230}, {}, 0, {}, fast});          // Their dots.
  shapes.push_back({{5, 5}, {0, 220, 230}, {}, 0, {}, slow});
  return DotScene(options, shapes);
}

constexpr int kCartFrames = 16;

TEST(AssociationScenes, TheFastCartsMarkerIsFollowedAndNeverTakenForTheOtherCarts) {
  const DotScene scene = TwoCarts();
  TrackingConfig config;
  config.markers = {YellowDot("fast", scene.roi(2))};
  const SceneScore s = TrackScene(scene, config, {2}, kCartFrames, 3.0)[0];
  EXPECT_EQ(s.wrong, 0) << s.first_wrong;
  EXPECT_GE(s.found, kCartFrames - 1);
}

// With a 1/20 s shutter the fast dot is a 15 px streak that its colour marker cannot take for
// the round dot it learned: the marker is lost for frames. Its reach grows meanwhile, and the
// other cart's identical dot comes into it; that dot was in view, elsewhere, when the marker was
// lost (another object, followed since), so it is never taken for it (it used to be, once,
// after seven frames lost).
TEST(AssociationScenes, ALostMarkersReachNeverTakesAnIdenticalDotSeenElsewhereWhenItWasLost) {
  const DotScene scene = TwoCarts(0.25);
  TrackingConfig config;
  config.markers = {YellowDot("fast", scene.roi(2))};
  const int count = 20;  // Until both dots near the frame's right edge.
  const SceneScore s = TrackScene(scene, config, {2}, count, 3.0)[0];
  EXPECT_EQ(s.wrong, 0) << s.first_wrong;
  EXPECT_GE(s.found, 9);
}

TEST(AssociationScenes, AMarkerAtASteady30PxAFrameIsFollowed) {
  const DotScene scene = TwoCarts();
  TrackingConfig config;
  config.markers = {YellowDot("slow", scene.roi(3))};
  const SceneScore s = TrackScene(scene, config, {3}, kCartFrames, 1.5)[0];
  EXPECT_EQ(s.wrong, 0) << s.first_wrong;
  EXPECT_GE(s.found, kCartFrames - 1);
}

TEST(AssociationScenes, TwoIdenticalMarkersOnTwoCartsKeepTheirIdentities) {
  const DotScene scene = TwoCarts();
  TrackingConfig config;
  config.markers = {YellowDot("fast", scene.roi(2)), YellowDot("slow", scene.roi(3))};
  const std::vector<SceneScore> s = TrackScene(scene, config, {2, 3}, kCartFrames, 3.0);
  for (size_t m = 0; m < 2; ++m) {
    EXPECT_EQ(s[m].wrong, 0) << config.markers[m].name << ": " << s[m].first_wrong;
    EXPECT_GE(s[m].found, kCartFrames - 1) << config.markers[m].name;
  }
}

// A white dot circling slowly on a gray bench; four identical dots slide in from the right edge
// and come to rest 35-60 px from its path, then drift.
DotScene DotsComingIntoView() {
  DotSceneOptions options;
  options.clutter = 12;
  std::vector<DotShape> shapes;
  shapes.push_back({{6, 6}, {235, 235, 235}, {}, 0, {}, [](double t) {
    return DotPose{{300 + 40 * std::cos(t / 25), 240 + 40 * std::sin(t / 25)}};
  }});
  for (int k = 0; k < 4; ++k) {
    const cv::Point2d rest(300 + (k % 2 ? 1 : -1) * (90 + 10 * k), 240 + (k < 2 ? -1 : 1) * 95);
    shapes.push_back({{6, 6}, {235, 235, 235}, {}, 0, {}, [rest, k](double t) {
      const double arrive = 20 + 10 * k;
      const double u = std::clamp((t - arrive + 30) / 30, 0.0, 1.0);
      cv::Point2d p = rest + cv::Point2d(700 * (1 - u) * (1 - u), 0);
      p += cv::Point2d(3 * std::sin(t / 17 + k), 3 * std::cos(t / 13 + k));
      return DotPose{p, 0, p.x < 660};
    }});
  }
  return DotScene(options, shapes);
}

TEST(AssociationScenes, IdenticalDotsComingIntoViewDoNotTakeTheTrackedOnesPlace) {
  const DotScene scene = DotsComingIntoView();
  TrackingConfig config;
  config.markers = {WhiteDot("dot", scene.roi(0))};
  const int count = 150;
  const SceneScore s = TrackScene(scene, config, {0}, count, 1.5)[0];
  EXPECT_EQ(s.wrong, 0) << s.first_wrong;
  EXPECT_GE(s.found, count - 2);
}

// A hand-held plate with five white dots over a cluttered background: it moves, turns and comes
// closer (the dots grow by half); every dot has its own roi.
DotScene WhiteDotPlate() {
  DotSceneOptions options;
  options.clutter = 30;
  const cv::Point2d layout[5] = {{-60, -40}, {60, -40}, {0, 0}, {-60, 40}, {60, 40}};
  std::vector<DotShape> shapes;
  for (const cv::Point2d& offset : layout) {
    const auto pose = [offset](double t) {
      const double scale = 1.0 + 0.5 * t / 200;
      const double a = 0.6 * std::sin(t / 40);
      const cv::Point2d centre(320 + 80 * std::sin(t / 30), 240 + 50 * std::cos(t / 23));
      const cv::Point2d r(offset.x * std::cos(a) - offset.y * std::sin(a),
                          offset.x * std::sin(a) + offset.y * std::cos(a));
      return DotPose{centre + scale * r, a * 180 / CV_PI, true, scale};
    };
    shapes.push_back({{7, 7}, {240, 240, 240}, {}, 0, {}, [pose](double t) { return pose(t); }});
  }
  return DotScene(options, shapes);
}

TEST(AssociationScenes, FiveWhiteDotsOnAMovingPlateAreEachFollowedInEveryFrame) {
  const DotScene scene = WhiteDotPlate();
  TrackingConfig config;
  std::vector<size_t> shape_of;
  for (size_t k = 0; k < 5; ++k) {
    config.markers.push_back(WhiteDot(std::string(1, static_cast<char>('a' + k)), scene.roi(k)));
    shape_of.push_back(k);
  }
  const int count = 200;
  const std::vector<SceneScore> s = TrackScene(scene, config, shape_of, count, 1.5);
  for (size_t m = 0; m < s.size(); ++m) {
    EXPECT_EQ(s[m].wrong, 0) << config.markers[m].name << ": " << s[m].first_wrong;
    EXPECT_GE(s[m].found, count - 4) << config.markers[m].name;
  }
}


// ---- Markers that are not whole, ideal discs -----------------------------------------------------

// Of a disc of radius r at `centre`, the fraction left of x = edge (a straight-edged cover
// coming from the right).
double VisibleLeftOf(const cv::Point2d& centre, double r, double edge) {
  const double d = std::clamp((edge - centre.x) / r, -1.0, 1.0);
  // Area of the disc left of the chord at signed distance d*r from the centre, over the disc's.
  return (std::acos(-d) + d * std::sqrt(1 - d * d)) / CV_PI;
}

// A red disc (radius 10 px) drifting right; a paddle slides in from the right, covers up to
// 70 % of it, and withdraws. The marker must be found (at its centre) whenever at least half of
// it shows, and never be reported more than 1 px off.
TEST(AssociationScenes, ADiscPartlyCoveredByAPaddleIsFoundAtItsCentreOrNotAtAll) {
  DotSceneOptions options;
  const double r = 10;
  const auto centre = [](double t) { return cv::Point2d(250 + 0.5 * t, 240 + 10 * std::sin(t / 20)); };
  // The paddle's left edge: from beyond the disc to 0.4 r left of its centre (70 % covered) and back.
  const auto edge = [centre, r](double t) {
    const double u = 0.5 - 0.5 * std::cos(2 * CV_PI * t / 80);  // 0 -> 1 -> 0 every 80 frames.
    return centre(t).x + r * (1.5 - 1.9 * u);
  };
  std::vector<DotShape> shapes;
  shapes.push_back({{r, r}, {40, 40, 220}, {}, 0, {}, [centre](double t) { return DotPose{centre(t)}; }});
  std::vector<testing::DotCover> covers;
  covers.push_back({[edge](double t) { return cv::Rect2d(edge(t), 150, 200, 200); }, 0, 1 << 30,
                    {70, 70, 70}});
  const DotScene scene(options, shapes, covers);
  MarkerSpec spec = testing::ColourMarker("red", {170, 10});
  spec.params.get<ColourParams>().roi = scene.roi(0);
  TrackingConfig config;
  config.markers = {spec};
  TrackingSession session(config);
  int half_visible = 0, found_half = 0, off = 0;
  double worst = 0;
  for (int f = 0; f < 160; ++f) {
    Frame frame;
    frame.image = scene.render(f);
    frame.index = f;
    const Observation& o = session.process(frame).markers[0].observation;
    const double visible = VisibleLeftOf(centre(f), r, edge(f));
    if (visible >= 0.5) ++half_visible;
    if (!o.found()) continue;
    const double e = cv::norm(*o.position_px - centre(f));
    worst = std::max(worst, e);
    if (e > 1.0) ++off;
    if (visible >= 0.5) ++found_half;
  }
  std::printf("[ measured ] partly covered disc: found %d of %d frames with >= half visible, "
              "%d reports > 1 px off (worst %.2f px)\n", found_half, half_visible, off, worst);
  EXPECT_EQ(off, 0);
  EXPECT_GE(found_half, half_visible * 98 / 100);
}

// A pale green air puck (radius 12 px) with a white specular highlight inside it, sliding over
// the bench; the range is the puck's green (the highlight is not in it).
TEST(AssociationScenes, APalePuckWithAHighlightIsFound) {
  DotSceneOptions options;
  std::vector<DotShape> shapes;
  shapes.push_back({{12, 12}, {150, 205, 150}, cv::Vec3b(250, 250, 250), 0.35, {0.25, -0.3},
                    [](double t) { return DotPose{{200 + 2.0 * t, 200 + 40 * std::sin(t / 15)}}; }});
  const DotScene scene(options, shapes);
  MarkerSpec spec = testing::ColourMarker("puck", {50, 70});
  ColourParams& colour = spec.params.get<ColourParams>();
  colour.s = {40, 255};
  colour.v = {120, 255};
  colour.roi = scene.roi(0);
  TrackingConfig config;
  config.markers = {spec};
  const int count = 100;
  const SceneScore s = TrackScene(scene, config, {0}, count, 1.5)[0];
  EXPECT_EQ(s.wrong, 0) << s.first_wrong;
  EXPECT_GE(s.found, count - 2);
}

// A bicycle rim (a dark tyre, a gray rim) with an elongated sticker (28 x 8 px) on it, the
// wheel turning 5 degrees a frame: the sticker goes round and turns with it.
DotScene TurningRim() {
  DotSceneOptions options;
  std::vector<DotShape> shapes;
  shapes.push_back({{130, 130}, {40, 40, 40}, {}, 0, {}, [](double) { return DotPose{{320, 240}}; }});
  shapes.push_back({{112, 112}, {120, 120, 120}, {}, 0, {}, [](double) { return DotPose{{320, 240}}; }});
  shapes.push_back({{14, 4}, {40, 200, 240}, {}, 0, {}, [](double t) {
    const double a = 5.0 * t * CV_PI / 180;
    return DotPose{{320 + 121 * std::cos(a), 240 + 121 * std::sin(a)}, 5.0 * t + 90};
  }});
  return DotScene(options, shapes);
}

// An elongated sticker (28 x 8 px) on a bicycle rim turning 5 degrees a frame: it goes round
// and turns with the wheel.
TEST(AssociationScenes, AnElongatedStickerOnATurningRimIsFollowed) {
  const DotScene scene = TurningRim();
  MarkerSpec spec = testing::ColourMarker("sticker", {10, 30});
  spec.params.get<ColourParams>().roi = scene.roi(2);
  spec.params.get<ColourParams>().min_circularity = 0.2;
  TrackingConfig config;
  config.markers = {spec};
  const int count = 144;  // Two turns.
  const SceneScore s = TrackScene(scene, config, {2}, count, 1.5)[0];
  EXPECT_EQ(s.wrong, 0) << s.first_wrong;
  EXPECT_GE(s.found, count - 3);
}

// ---- init's markers on the same footage -----------------------------------------------------

// Which of `shapes` of `scene` lies nearest `p` on frame 0.
size_t NearestShape(const DotScene& scene, const cv::Point2d& p, const std::vector<size_t>& shapes) {
  size_t nearest = shapes.front();
  for (size_t s : shapes) {
    if (cv::norm(p - *scene.truth(s, 0)) < cv::norm(p - *scene.truth(nearest, 0))) nearest = s;
  }
  return nearest;
}

// What `init` writes for frame 0 of `scene` (FindMarkers), as a config.
TrackingConfig InitConfig(const DotScene& scene, MarkerFinding* finding) {
  *finding = FindMarkers(scene.render(0));
  TrackingConfig config;
  for (const FoundMarker& m : finding->markers) config.markers.push_back(m.spec);
  return config;
}

// The two carts' identical dots (the slow one blurred by its motion) are what a person would
// click: init writes both, each with its roi, and each is followed on its own cart.
TEST(AssociationScenes, InitTakesTheCartsIdenticalDotsAsTwoMarkersThatKeepTheirIdentities) {
  const DotScene scene = TwoCarts();
  MarkerFinding finding;
  const TrackingConfig config = InitConfig(scene, &finding);
  ASSERT_TRUE(finding.ok()) << finding.problem;
  ASSERT_EQ(finding.markers.size(), 2u);
  std::vector<size_t> shape_of;
  for (const FoundMarker& m : finding.markers) {
    EXPECT_TRUE(m.needs_roi);
    ASSERT_TRUE(m.spec.params.get<ColourParams>().roi.has_value());
    const size_t dot = NearestShape(scene, m.position_px, {2, 3});
    EXPECT_LT(cv::norm(m.position_px - *scene.truth(dot, 0)), 0.5);
    shape_of.push_back(dot);
  }
  EXPECT_NE(shape_of[0], shape_of[1]);
  for (const SceneScore& s : TrackScene(scene, config, shape_of, kCartFrames, 3.0)) {
    EXPECT_EQ(s.wrong, 0) << s.first_wrong;
    EXPECT_GE(s.found, kCartFrames - 1);
  }
}

// Three identical pale pucks with highlights on a tinted bench: three markers, a roi each, each
// followed (the picked saturation range reached down to the bench's greenish blotches, and a
// puck passing one merged with it: 53 and 48 of 60 found; with the bound half way between puck
// and bench, 60 of 60; the highlight had made the pucks' edges look soft). A set
// of blobs of one colour that differ (a larger one, a smaller one) stays refused: init cannot tell
// which of them is the marker.
TEST(AssociationScenes, InitTakesIdenticalPucksAsMarkersAndRefusesUnlikeLookAlikes) {
  const auto puck = [](double x0, double y0, double r, cv::Vec3b colour) {
    return DotShape{{r, r}, colour, cv::Vec3b(250, 250, 250), 0.35, {0.25, -0.3},
                    [x0, y0](double t) { return DotPose{{x0 + 2.0 * t, y0 + 20 * std::sin(t / 15)}}; }};
  };
  const cv::Vec3b green(140, 205, 140);
  const DotScene pucks(DotSceneOptions(), {puck(150, 200, 12, green), puck(330, 260, 12, green),
                                           puck(480, 150, 12, green)});
  MarkerFinding finding;
  const TrackingConfig config = InitConfig(pucks, &finding);
  ASSERT_TRUE(finding.ok()) << finding.problem;
  ASSERT_EQ(finding.markers.size(), 3u);
  std::vector<size_t> shape_of;
  for (const FoundMarker& m : finding.markers) {
    shape_of.push_back(NearestShape(pucks, m.position_px, {0, 1, 2}));
  }
  EXPECT_NE(shape_of[0], shape_of[1]);
  EXPECT_NE(shape_of[1], shape_of[2]);
  EXPECT_NE(shape_of[0], shape_of[2]);
  for (const SceneScore& s : TrackScene(pucks, config, shape_of, 60, 1.5)) {
    EXPECT_EQ(s.wrong, 0) << s.first_wrong;
    EXPECT_GE(s.found, 59);
  }

  for (const auto& unlike : {DotScene(DotSceneOptions(), {puck(150, 200, 12, green),
                                                         puck(330, 260, 17, green)}),
                             DotScene(DotSceneOptions(), {puck(150, 200, 12, green),
                                                         puck(330, 260, 8, green)})}) {
    InitConfig(unlike, &finding);
    EXPECT_FALSE(finding.ok()) << finding.markers.size() << " markers; " << [&] {
      std::string why;
      for (const auto& r : finding.rejected) why += r.why + "; ";
      return why;
    }();
    EXPECT_NE(finding.problem.find("will not guess"), std::string::npos) << finding.problem;
  }
}

// The rim's elongated sticker: init proposes it (a bar, filling its moment ellipse), with a
// min_circularity of its own, and the marker is followed round two turns of the wheel.
TEST(AssociationScenes, InitTakesTheRimsElongatedStickerAndItIsFollowed) {
  const DotScene scene = TurningRim();
  MarkerFinding finding;
  const TrackingConfig config = InitConfig(scene, &finding);
  ASSERT_TRUE(finding.ok()) << finding.problem << [&] {
    std::string why;
    for (const auto& r : finding.rejected) why += "; " + r.why;
    return why;
  }();
  ASSERT_EQ(finding.markers.size(), 1u);
  EXPECT_LT(cv::norm(finding.markers[0].position_px - *scene.truth(2, 0)), 0.5);
  EXPECT_LT(config.markers[0].params.get<ColourParams>().min_circularity, 0.5);
  const int count = 144;  // Two turns.
  const SceneScore s = TrackScene(scene, config, {2}, count, 1.5)[0];
  EXPECT_EQ(s.wrong, 0) << s.first_wrong;
  EXPECT_GE(s.found, count - 3);
}

// ---- Template markers (SAD, SSD, ZNCC) on the same footage ---------------------------------

constexpr const char* kTemplateMethods[] = {"zncc", "ssd", "sad"};

// A box dragged around shape `s` on frame 0 (6 px of background on every side).
MarkerSpec TemplateDot(const std::string& name, const std::string& method, const cv::Rect& rect) {
  MarkerSpec spec;
  spec.name = name;
  spec.params = ParamsForMethod(method, {});
  spec.params.get<TemplateParams>().rect = rect;
  return spec;
}

// The carts, one box per cart dot or both. Every method follows the slow cart's dot at 30 px a
// frame (it used to be lost after frame 0 and then found on the other cart's dot passing its
// last place: the re-acquisition grew by 8 px a frame and stopped short of a cart corner it had
// taken for a look-alike); ZNCC and SAD follow the accelerating one too. None is ever reported
// on the other cart's dot.
TEST(AssociationScenes, TemplateMarkersOnTheCartsKeepTheirIdentities) {
  const DotScene scene = TwoCarts();
  for (const char* method : kTemplateMethods) {
    SCOPED_TRACE(method);
    const bool follows_fast = std::string(method) != "ssd";  // SSD: 10 of 16 (blur streaks).
    TrackingConfig fast, slow, both;
    fast.markers = {TemplateDot("fast", method, scene.roi(2))};
    slow.markers = {TemplateDot("slow", method, scene.roi(3))};
    both.markers = {fast.markers[0], slow.markers[0]};
    const SceneScore f = TrackScene(scene, fast, {2}, kCartFrames, 3.0)[0];
    const SceneScore s = TrackScene(scene, slow, {3}, kCartFrames, 1.5)[0];
    const std::vector<SceneScore> b = TrackScene(scene, both, {2, 3}, kCartFrames, 3.0);
    for (const SceneScore* score : {&f, &s, &b[0], &b[1]}) {
      EXPECT_EQ(score->wrong, 0) << score->first_wrong;
    }
    EXPECT_GE(s.found, kCartFrames - 1);
    EXPECT_GE(b[1].found, kCartFrames - 1);
    if (follows_fast) {
      EXPECT_GE(f.found, kCartFrames - 1);
      EXPECT_GE(b[0].found, kCartFrames - 1);
    } else {
      EXPECT_GE(f.found, kCartFrames / 2);
    }
  }
}

TEST(AssociationScenes, ATemplateMarkerIsNotTakenForIdenticalDotsComingIntoView) {
  const DotScene scene = DotsComingIntoView();
  for (const char* method : kTemplateMethods) {
    SCOPED_TRACE(method);
    TrackingConfig config;
    config.markers = {TemplateDot("dot", method, scene.roi(0))};
    const int count = 150;
    const SceneScore s = TrackScene(scene, config, {0}, count, 1.5)[0];
    EXPECT_EQ(s.wrong, 0) << s.first_wrong;
    // SAD and SSD compare grey levels, background included: clutter behind a moving dot costs
    // them 13-14 frames.
    EXPECT_GE(s.found, std::string(method) == "zncc" ? count - 2 : count - 20);
  }
}

// The plate of white dots over clutter, a box per dot: ZNCC follows every dot in every frame.
// SAD and SSD lose the dots whose surroundings change most (8-33 of 200 found for two of them:
// a known limit), but never report one elsewhere.
TEST(AssociationScenes, TemplateMarkersOnAMovingPlateAreFollowedOrLostNeverSwapped) {
  const DotScene scene = WhiteDotPlate();
  for (const char* method : kTemplateMethods) {
    SCOPED_TRACE(method);
    TrackingConfig config;
    std::vector<size_t> shape_of;
    for (size_t k = 0; k < 5; ++k) {
      config.markers.push_back(
          TemplateDot(std::string(1, static_cast<char>('a' + k)), method, scene.roi(k)));
      shape_of.push_back(k);
    }
    const int count = 200;
    const std::vector<SceneScore> s = TrackScene(scene, config, shape_of, count, 1.5);
    for (size_t m = 0; m < s.size(); ++m) {
      EXPECT_EQ(s[m].wrong, 0) << config.markers[m].name << ": " << s[m].first_wrong;
      if (std::string(method) == "zncc") {
        EXPECT_GE(s[m].found, count - 4) << config.markers[m].name;
      }
    }
  }
}

// A template box dragged over the rim's sticker, mostly tyre: the tyre looks the same however
// the wheel turns, the sticker does not stay in the box. A match must contain the template's
// own blob (the sticker), and follows it: SAD used to stay on the tyre, 2.6-3.8 px behind the
// sticker, for three frames. The template turns with the sticker (template.turn_search): the
// box was lost after 4-6 of 48 frames, the drift guard refusing the turned sticker.
TEST(AssociationScenes, ATemplateMostlyOfBackgroundFollowsItsMarkerOrLosesIt) {
  const DotScene scene = TurningRim();
  for (const char* method : kTemplateMethods) {
    SCOPED_TRACE(method);
    TrackingConfig config;
    config.markers = {TemplateDot("sticker", method, scene.roi(2, 0, 14))};
    const int count = 48;
    const SceneScore s = TrackScene(scene, config, {2}, count, 1.5)[0];
    EXPECT_EQ(s.wrong, 0) << s.first_wrong;
    EXPECT_GE(s.found, count - 2);
  }
}

// A box close around the sticker, two whole turns of the wheel: the template follows it all the
// way round (it was found in 4-10 of 144 frames), and without the turn search it is lost, never
// reported elsewhere.
TEST(AssociationScenes, ATemplateOnAStickerTurningWithAWheelFollowsItAllTheWayRound) {
  const DotScene scene = TurningRim();
  const int count = 144;
  for (const char* method : kTemplateMethods) {
    SCOPED_TRACE(method);
    TrackingConfig config;
    config.markers = {TemplateDot("sticker", method, scene.roi(2, 0, 6))};
    const SceneScore s = TrackScene(scene, config, {2}, count, 1.5)[0];
    EXPECT_EQ(s.wrong, 0) << s.first_wrong;
    EXPECT_GE(s.found, count - 3);
    // Without it, a third of a turn shows the loss (2-4 of 48 found; 4-10 of 144 before).
    config.markers[0].params.get<TemplateParams>().turn_search = false;
    const int third = count / 3;
    const SceneScore fixed = TrackScene(scene, config, {2}, third, 1.5)[0];
    EXPECT_EQ(fixed.wrong, 0) << fixed.first_wrong;
    EXPECT_LT(fixed.found, third / 2);
  }
}

}  // namespace
}  // namespace softsight
