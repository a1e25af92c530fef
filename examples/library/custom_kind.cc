// A kind of marker of your own, added from outside the library: a bright spot (a LED, a
// retro-reflective dot under a ring light), found as the centroid of the pixels at or above a
// gray level. It is registered with softsight's tracker registry (softsight/track/tracker_kind.h),
// named by a config's `method: bright`, and run by a TrackingSession through RunPipeline over a
// video this program writes, exactly as the built-in colour and template kinds are; nothing in
// softsight knows it. Prints one line; exit 0 when the spot was found in every frame at its
// drawn centre (within 0.01 px) and the config's range check names the bad key.
//   custom_kind [WORK_DIR] [FRAMES]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include <softsight/softsight.h>  // Tracker, TrackerKind, option tables, config, session, run.

namespace {

// ---- 1. The parameters, and their option rows (key, range, unit, doc) ---------------------------

struct BrightSpotParams {
  int min_gray = 200;         // A pixel with every channel at or above this level is the spot's.
  double min_area_px = 12;    // Fewer such pixels: not found (a glint, noise).
  int window_px = 64;         // Side of the square searched around the last position; 0: always
                              // the whole frame.

  bool Check(std::string* problem) const;
};

const softsight::OptionTable<BrightSpotParams>& BrightSpotOptions() {
  using softsight::DoubleOption;
  using softsight::IntOption;
  static const softsight::OptionTable<BrightSpotParams> table = {
      IntOption<BrightSpotParams>("bright.min_gray", &BrightSpotParams::min_gray)
          .Range(1, 255)
          .Doc("a pixel with every channel at or above this level belongs to the spot"),
      DoubleOption<BrightSpotParams>("bright.min_area", &BrightSpotParams::min_area_px)
          .AtLeast(1)
          .Unit("px")
          .Doc("fewer bright pixels: the spot is not found"),
      IntOption<BrightSpotParams>("bright.window", &BrightSpotParams::window_px)
          .Range(8, 4096)
          .Or(0, "search the whole frame")
          .Unit("px")
          .Doc("side of the square searched around the last position"),
  };
  return table;
}

bool BrightSpotParams::Check(std::string* problem) const {
  if (const auto bad = softsight::CheckOptions(BrightSpotOptions(), *this)) {
    return softsight::Fail(problem, *bad);
  }
  return true;
}

// ---- 2. The tracker -----------------------------------------------------------------------------

class BrightSpotTracker final : public softsight::Tracker {
 public:
  explicit BrightSpotTracker(const BrightSpotParams& params) : params_(params) {}

  // Nothing to learn from a person's box: the spot is whatever is bright.
  void init(const cv::Mat& /*frame_bgr*/, const cv::Rect& /*hint*/) override {}
  bool start(const softsight::Frame& /*frame*/) override { return true; }

  softsight::Observation update(const cv::Mat& frame_bgr) override {
    const cv::Rect frame_rect(0, 0, frame_bgr.cols, frame_bgr.rows);
    // Near the last position while the spot is followed; the whole frame when it is lost.
    cv::Rect search = frame_rect;
    if (last_px_ && params_.window_px > 0) {
      const int half = params_.window_px / 2;
      search = cv::Rect(cvRound(last_px_->x) - half, cvRound(last_px_->y) - half,
                        params_.window_px, params_.window_px) & frame_rect;
    }
    // One pass over the searched pixels, nothing allocated: the centroid of the bright ones.
    double area = 0, sum_x = 0, sum_y = 0;
    for (int y = search.y; y < search.y + search.height; ++y) {
      const cv::Vec3b* row = frame_bgr.ptr<cv::Vec3b>(y);
      for (int x = search.x; x < search.x + search.width; ++x) {
        if (IsBright(row[x])) {
          area += 1;
          sum_x += x;
          sum_y += y;
        }
      }
    }
    if (area < params_.min_area_px) {
      last_px_.reset();  // Lost: never a stale position.
      return softsight::Observation::NotFound(softsight::MarkerStatus::kLost);
    }
    softsight::Observation seen;
    seen.position_px = cv::Point2d(sum_x / area, sum_y / area);  // Pixel centres at x = j, y = i.
    seen.score = area;  // px.
    last_px_ = seen.position_px;
    return seen;
  }

  void reset() override { last_px_.reset(); }

 private:
  // White light: every channel at or above the level (a coloured surface is not the spot).
  bool IsBright(const cv::Vec3b& bgr) const {
    return std::min({bgr[0], bgr[1], bgr[2]}) >= params_.min_gray;
  }

  BrightSpotParams params_;
  std::optional<cv::Point2d> last_px_;
};

// ---- 3. The kind: what the config, the session and the live window ask of it --------------------

class BrightSpotKind final : public softsight::TrackerKind {
 public:
  std::string name() const override { return "bright spot"; }
  std::vector<std::string> methods() const override { return {"bright"}; }
  softsight::MarkerParams defaults() const override { return BrightSpotParams{}; }
  const softsight::OptionTable<softsight::MarkerParams>& options() const override {
    static const auto rows = softsight::KindOptions(BrightSpotOptions());
    return rows;
  }
  bool check(const softsight::MarkerParams& params, std::string* problem) const override {
    return params.get<BrightSpotParams>().Check(problem);
  }
  std::unique_ptr<softsight::Tracker> create(const softsight::MarkerParams& params) const override {
    return std::make_unique<BrightSpotTracker>(params.get<BrightSpotParams>());
  }
  bool needs_colour(const softsight::MarkerParams& /*params*/) const override { return false; }
  double size_hint_px(const softsight::MarkerParams& params) const override {
    return std::sqrt(params.get<BrightSpotParams>().min_area_px);
  }
  // Selected by a box in the live window; the spot needs no start position, so a selection, a
  // recording's start and a late edit leave its parameters as they are.
  softsight::MarkerSelection selection() const override {
    return softsight::MarkerSelection::kDragBox;
  }
  void remember_selection(softsight::MarkerParams& /*params*/, const softsight::Frame& /*frame*/,
                          const cv::Rect& /*rect*/) const override {}
  void start_in(softsight::MarkerParams& /*params*/, const cv::Rect& /*box*/) const override {}
  void start_by(softsight::MarkerParams& /*params*/, int64_t /*last_frame*/) const override {}
};

// ---- The test scene: a white disc on a gray bench, beside a dimmer patch ------------------------

// Where the spot is drawn in frame `i`: whole pixels, so the centroid of the drawn disc (it is
// symmetric) is exactly its centre. A steady motion, as a marker's: the session's motion model
// refuses jumps no motion explains. It passes over the lit patch near the end.
cv::Point SpotCentre(int i) { return {60 + 4 * i, 60 + 2 * i}; }

// Drawn pixel by pixel: the program needs OpenCV's core only, as softsight's track module does.
cv::Mat DrawFrame(int i) {
  constexpr int kRadius = 5;
  // Neutral grays only: the video's chroma subsampling then changes no pixel.
  cv::Mat image(180, 320, CV_8UC3, cv::Scalar::all(80));
  image(cv::Rect(200, 120, 40, 30)).setTo(cv::Scalar::all(150));  // A lit patch, not bright enough.
  const cv::Point c = SpotCentre(i);
  for (int y = c.y - kRadius; y <= c.y + kRadius; ++y) {
    for (int x = c.x - kRadius; x <= c.x + kRadius; ++x) {
      if ((x - c.x) * (x - c.x) + (y - c.y) * (y - c.y) <= kRadius * kRadius) {
        image.at<cv::Vec3b>(y, x) = cv::Vec3b(250, 250, 250);
      }
    }
  }
  return image;
}

// Checks every frame's result against where the spot was drawn.
class TruthSink final : public softsight::FrameSink {
 public:
  void consume(const softsight::Frame& frame, const softsight::FrameResult& result) override {
    const softsight::Observation& seen = result.markers.at(0).observation;
    if (!seen.position_px) return;
    ++found;
    const cv::Point2d d = *seen.position_px - cv::Point2d(SpotCentre(static_cast<int>(frame.index)));
    worst_px = std::max(worst_px, std::hypot(d.x, d.y));
  }
  int found = 0;
  double worst_px = 0.0;
};

std::string ErrorOf(const std::string& config_file) {
  try {
    softsight::LoadTrackingConfig(config_file);
  } catch (const softsight::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::filesystem::path work =
        argc > 1 ? std::filesystem::path(argv[1]) : std::filesystem::temp_directory_path();
    const int frames = argc > 2 ? std::atoi(argv[2]) : 40;
    std::filesystem::create_directories(work);

    // Registered before the first config that names it is read.
    softsight::RegisterTrackerKind<BrightSpotParams>(std::make_unique<BrightSpotKind>());

    // A config names it like any method; its keys are read and range-checked from its rows.
    const std::string config_file = (work / "bright.yaml").string();
    std::ofstream(config_file) << "markers:\n  - name: lamp\n    method: bright\n"
                                  "    bright: {min_gray: 200, window: 48}\n";
    const softsight::TrackingConfig config = softsight::LoadTrackingConfig(config_file);
    const std::string bad_file = (work / "bad.yaml").string();
    std::ofstream(bad_file) << "markers:\n  - name: lamp\n    method: bright\n"
                               "    bright: {min_gray: 300}\n";
    const std::string bad = ErrorOf(bad_file);
    const bool names_bad_key = bad.find("bright.min_gray: 300 must lie within 1..255") !=
                               std::string::npos;

    // A lossless video of the scene, read back as any input is.
    const std::string video = (work / "bright_spot.avi").string();
    {
      softsight::FrameWriter writer({.path = video});
      writer.open(DrawFrame(0).size());
      for (int i = 0; i < frames; ++i) writer.write(DrawFrame(i), i);
      writer.close();
    }
    std::unique_ptr<softsight::FrameSource> source = softsight::OpenFrameSource({.input = video});
    softsight::TrackingSession session(config);
    TruthSink truth;
    const softsight::RunSummary summary = softsight::RunPipeline(*source, session, {&truth});

    std::printf("softsight %s custom kind '%s': %s; worst %.4f px from the drawn centre; "
                "bad key %s\n",
                softsight::kVersion,
                softsight::TrackerMethodName(config.markers.at(0).params).c_str(),
                summary.BriefReport().c_str(), truth.worst_px,
                names_bad_key ? "named" : ("NOT named: " + bad).c_str());
    return summary.ok() && truth.found == frames && truth.worst_px < 0.01 && names_bad_key ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
