// The tracker registry and how a tracker starts itself: CreateTracker builds each method by its
// name, and every tracker decides from its own parameters when it can start (Tracker::start), so
// no caller looks at method names or template fields to start one.
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"
#include "softsight/track/tracker.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "softsight/core/error.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

constexpr int kFrames = 6;  // The first frames of the 30-frame bend the tracker tests follow.
constexpr int kTemplatePx = 25;  // The default scene's discs are 18 px across.

// The default bending scene, rendered once per test program.
struct Sequence {
  std::vector<Frame> frames;
  std::vector<SceneTruth> truth;
};

const Sequence& Rendered() {
  static const Sequence sequence = [] {
    SceneOptions options;
    options.frame_count = 30;
    SyntheticScene renderer(options, NoiseOptions{}, {}, {});
    Sequence s;
    for (int i = 0; i < kFrames; ++i) {
      Frame frame;
      frame.index = i;
      frame.time_s = i / 30.0;
      s.truth.push_back(renderer.render(i, frame.image));
      s.frames.push_back(frame);
    }
    return s;
  }();
  return sequence;
}

cv::Rect RectAround(const cv::Point2d& centre, int side) {
  return {static_cast<int>(std::lround(centre.x - (side - 1) / 2.0)),
          static_cast<int>(std::lround(centre.y - (side - 1) / 2.0)), side, side};
}

// (The name from a std::string: GCC 12 misreports assigning a short literal as an overlap.)
MarkerSpec SpecFor(const std::string& method, const std::string& name = "m") {
  MarkerSpec spec;
  spec.name = name;
  spec.params = ParamsForMethod(method, {});
  return spec;
}

double ErrorPx(const Observation& o, const MarkerTruth& truth) {
  return o.found() ? cv::norm(*o.position_px - *truth.centroid_px) : INFINITY;
}

TEST(TrackerRegistry, EveryMethodIsBuiltByItsNameAndTheDefaultsAreRegistered) {
  const std::vector<std::string> methods = TrackerMethods();
  ASSERT_FALSE(methods.empty());
  for (bool has_template : {false, true}) {
    const std::string method = DefaultTrackerMethod(has_template);
    EXPECT_NE(std::find(methods.begin(), methods.end(), method), methods.end()) << method;
    EXPECT_EQ(IsTemplateMethod(method), has_template) << method;
  }
  for (const std::string& method : methods) {
    EXPECT_NE(CreateTracker(SpecFor(method)), nullptr) << method;
  }
  try {
    ParamsForMethod("optical_flow", {});
    FAIL() << "an unknown method must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("optical_flow"), std::string::npos) << e.what();
    for (const std::string& method : methods) {
      EXPECT_NE(std::string(e.what()).find(method), std::string::npos) << e.what();
    }
  }
  EXPECT_FALSE(IsTemplateMethod("optical_flow"));
}

// A marker is one method's parameters: the registry turns a method name into them (keeping the
// given parameters of that kind) and names the method they select, and nothing else spells it.
TEST(TrackerRegistry, MethodNamesAndParametersMapOneToOne) {
  ColourParams colour;
  colour.window_px = 40;
  TemplateParams templ;
  templ.colour = true;
  templ.min_zncc = 0.7;
  for (const std::string& method : TrackerMethods()) {
    const MarkerParams params = ParamsForMethod(method, {colour, templ});
    EXPECT_EQ(TrackerMethodName(params), method);
    EXPECT_EQ(params.holds<TemplateParams>(), IsTemplateMethod(method)) << method;
    if (const auto* t = params.get_if<TemplateParams>()) {
      EXPECT_TRUE(t->colour) << method;
      EXPECT_DOUBLE_EQ(t->min_zncc, 0.7) << method;
    } else {
      EXPECT_EQ(params.get<ColourParams>().window_px, 40);
    }
  }
  EXPECT_EQ(TrackerMethodName(MarkerSpec{}.params), "colour");
}

// A rectangle on frame 3 names where the marker is on frame 3: the tracker waits for that frame,
// cuts its template there and finds the marker from then on.
TEST(TrackerRegistry, TemplateTrackerStartsItselfOnItsTemplateFrame) {
  const Sequence& s = Rendered();
  constexpr int kTemplateFrame = 3;
  for (const std::string& method : TrackerMethods()) {
    if (!IsTemplateMethod(method)) continue;
    for (size_t m = 0; m < s.truth[0].markers.size(); ++m) {
      MarkerSpec spec = SpecFor(method, s.truth[0].markers[m].name);
      TemplateParams& templ = spec.params.get<TemplateParams>();
      templ.template_frame = kTemplateFrame;
      templ.rect = RectAround(*s.truth[kTemplateFrame].markers[m].centroid_px, kTemplatePx);
      const auto tracker = CreateTracker(spec);
      for (int i = 0; i < kTemplateFrame; ++i) {
        EXPECT_FALSE(tracker->start(s.frames[i])) << method << " frame " << i;
      }
      ASSERT_TRUE(tracker->start(s.frames[kTemplateFrame])) << method;
      for (int i = kTemplateFrame; i < kFrames; ++i) {
        const Observation o = tracker->update(s.frames[i].image);
        EXPECT_LT(ErrorPx(o, s.truth[i].markers[m]), 0.3)
            << method << " " << spec.name << " frame " << i;
      }
    }
  }
}

TEST(TrackerRegistry, TemplateTrackerWithoutATemplateNeverStarts) {
  const Sequence& s = Rendered();
  MarkerSpec spec = SpecFor(DefaultTrackerMethod(true));
  const auto tracker = CreateTracker(spec);
  for (const Frame& frame : s.frames) EXPECT_FALSE(tracker->start(frame)) << frame.index;
}

// A template given as an image starts on the first frame and is searched for on the whole frame
// (in colour: in gray the three discs look alike, and a whole-frame search is ambiguous).
TEST(TrackerRegistry, TemplateTrackerFromAnImageStartsOnTheFirstFrame) {
  const Sequence& s = Rendered();
  const size_t m = 1;
  MarkerSpec spec = SpecFor(DefaultTrackerMethod(true));
  TemplateParams& templ = spec.params.get<TemplateParams>();
  templ.colour = true;
  templ.image =
      s.frames[0].image(RectAround(*s.truth[0].markers[m].centroid_px, kTemplatePx)).clone();
  templ.template_frame = kFrames;  // Where a rect would be cut; an image needs no frame.
  const auto tracker = CreateTracker(spec);
  ASSERT_TRUE(tracker->start(s.frames[0]));
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_LT(ErrorPx(tracker->update(s.frames[i].image), s.truth[i].markers[m]), 0.3) << i;
  }
}

// A colour tracker starts on its first frame; with a roi it acquires only there.
TEST(TrackerRegistry, ColourTrackerStartsOnItsFirstFrameWithinItsRoi) {
  const Sequence& s = Rendered();
  MarkerSpec spec = SpecFor(DefaultTrackerMethod(false));
  // Every colour is a marker: what is found depends only on where the tracker may look.
  ColourParams& colour = spec.params.get<ColourParams>();
  colour.h = {0, 179};
  colour.s = {80, 255};
  colour.v = {40, 255};
  for (size_t m = 0; m < s.truth[0].markers.size(); ++m) {
    colour.roi = RectAround(*s.truth[0].markers[m].centroid_px, 2 * kTemplatePx);
    const auto tracker = CreateTracker(spec);
    ASSERT_TRUE(tracker->start(s.frames[0]));
    EXPECT_LT(ErrorPx(tracker->update(s.frames[0].image), s.truth[0].markers[m]), 0.3)
        << s.truth[0].markers[m].name;
  }
}

}  // namespace
}  // namespace softsight
