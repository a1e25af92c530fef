// The `template:` section of a marker: every key read, written back and read again to the same
// values; template images relative to the config file; errors naming the key.
#include <sys/stat.h>

#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "config/config_test_util.h"
#include "core/test_util.h"
#include "softsight/config/config.h"
#include "softsight/core/error.h"
#include "softsight/track/template_tracker.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

TEST(TemplateConfig, ReadsEveryKeyAndWritesThemBack) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), R"(markers:
  - name: blue
    method: ssd
    template:
      frame: 3
      rect: [205, 186, 25, 27]
      colour: true
      round: false
      report: rect_centre
      ambiguity_margin: 0.05
      scale_search: false
      min_zncc: 0.7
      max_sad: 12.5
      max_ssd: 18
      search_margin_px: 12
      acquire_radius_px: 0
      pyramid_levels: 2
      update_rate: 0.05
      drift_min_zncc: 0.85
      contrast_gray: false
)");
  const TrackingConfig config = LoadTrackingConfig(dir.file("markers.yaml"));
  ASSERT_EQ(config.markers.size(), 1u);
  for (const TrackingConfig& c : {config, [&] {
                                    SaveTrackingConfig(config, dir.file("saved.yaml"));
                                    return LoadTrackingConfig(dir.file("saved.yaml"));
                                  }()}) {
    const TemplateParams& t = c.markers[0].params.get<TemplateParams>();
    EXPECT_EQ(TrackerMethodName(c.markers[0].params), "ssd");
    EXPECT_EQ(t.measure, MatchMeasure::kSsd);
    EXPECT_EQ(t.template_frame, 3);
    ASSERT_TRUE(t.rect.has_value());
    EXPECT_EQ(*t.rect, cv::Rect(205, 186, 25, 27));
    EXPECT_TRUE(t.colour);
    EXPECT_FALSE(t.round_mask);
    EXPECT_EQ(t.report, TemplateReport::kRectCentre);
    EXPECT_DOUBLE_EQ(t.ambiguity_margin, 0.05);
    EXPECT_FALSE(t.scale_search);
    EXPECT_DOUBLE_EQ(t.min_zncc, 0.7);
    EXPECT_DOUBLE_EQ(t.max_sad, 12.5);
    EXPECT_DOUBLE_EQ(t.max_ssd, 18);
    EXPECT_EQ(t.search_margin_px, 12);
    EXPECT_EQ(t.acquire_radius_px, 0);
    EXPECT_EQ(t.pyramid_levels, 2);
    EXPECT_DOUBLE_EQ(t.update_rate, 0.05);
    EXPECT_DOUBLE_EQ(t.drift_min_zncc, 0.85);
    EXPECT_FALSE(t.contrast_gray);
  }
}

TEST(TemplateConfig, TemplateWithoutMethodMeansZnccAndDefaultsStay) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"),
                         "markers:\n  - name: red\n    template: {rect: [10, 20, 21, 21]}\n");
  const TrackingConfig config = LoadTrackingConfig(dir.file("markers.yaml"));
  EXPECT_EQ(TrackerMethodName(config.markers[0].params), "zncc");
  const TemplateParams& t = config.markers[0].params.get<TemplateParams>();
  const TemplateParams defaults;
  EXPECT_FALSE(t.colour);
  EXPECT_EQ(t.template_frame, 0);
  EXPECT_DOUBLE_EQ(t.min_zncc, defaults.min_zncc);
  EXPECT_EQ(t.search_margin_px, defaults.search_margin_px);
}

TEST(TemplateConfig, ImageFileIsRelativeToTheConfig) {
  TempDir dir;
  cv::Mat image(21, 23, CV_8UC3, cv::Scalar(30, 60, 90));
  image(cv::Rect(5, 5, 10, 10)).setTo(cv::Scalar(200, 10, 10));
  ASSERT_TRUE(cv::imwrite(dir.file("marker.png"), image));
  testing::WriteTextFile(dir.file("markers.yaml"),
                         "markers:\n  - name: red\n    method: sad\n"
                         "    template: {file: marker.png}\n");
  const TrackingConfig config = LoadTrackingConfig(dir.file("markers.yaml"));
  const TemplateParams& t = config.markers[0].params.get<TemplateParams>();
  ASSERT_EQ(t.image.size(), image.size());
  EXPECT_EQ(t.image.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(t.image, image, cv::NORM_INF), 0.0);
  // The file is the config's, not the tracker's: saved again under the same name.
  EXPECT_EQ(config.template_files.at("red"), "marker.png");
  EXPECT_EQ(config.files_read.back(), dir.file("marker.png"));
  SaveTrackingConfig(config, dir.file("saved.yaml"));
  const TrackingConfig saved = LoadTrackingConfig(dir.file("saved.yaml"));
  EXPECT_EQ(saved.template_files.at("red"), "marker.png");
  EXPECT_EQ(cv::norm(saved.markers[0].params.get<TemplateParams>().image, image,
                     cv::NORM_INF), 0.0);
  EXPECT_FALSE(t.rect.has_value());
}

TEST(TemplateConfig, ImageWithRectIsWhereItWasSelectedAndMustBeItsSize) {
  // What the live window saves for a template selected live: the image, and where and on which
  // frame it was cut.
  TempDir dir;
  const cv::Mat image(21, 23, CV_8UC3, cv::Scalar(30, 60, 90));
  ASSERT_TRUE(cv::imwrite(dir.file("marker.png"), image));
  testing::WriteTextFile(dir.file("markers.yaml"),
                         "markers:\n  - name: red\n    method: zncc\n"
                         "    template: {file: marker.png, frame: 12, rect: [40, 50, 23, 21]}\n");
  const TrackingConfig config = LoadTrackingConfig(dir.file("markers.yaml"));
  const TemplateParams& t = config.markers[0].params.get<TemplateParams>();
  EXPECT_EQ(t.image.size(), image.size());
  EXPECT_EQ(t.rect, cv::Rect(40, 50, 23, 21));
  EXPECT_EQ(t.template_frame, 12);
  EXPECT_NO_THROW(CreateTracker(config.markers[0]));

  testing::WriteTextFile(dir.file("wrong.yaml"),
                         "markers:\n  - name: red\n    method: zncc\n"
                         "    template: {file: marker.png, rect: [40, 50, 25, 25]}\n");
  try {
    LoadTrackingConfig(dir.file("wrong.yaml"));
    ADD_FAILURE() << "a rect of another size than the image was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("template.rect: [40, 50, 25, 25] is not the size of the image "
                                    "'marker.png' (23x21 px)"));
  }
}

TEST(TemplateConfig, ErrorsNameTheKey) {
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {file: nothere.png}\n"),
              HasSubstr("markers[0].template.file: cannot read image"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {rect: [1, 2, 3]}\n"),
              HasSubstr("markers[0].template.rect"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {rect: [1, 2, 30, 30], "
                      "min_zncc: 2}\n"),
              HasSubstr("markers[0].template.min_zncc"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {rect: [1, 2, 30, 30], "
                      "colur: true}\n"),
              HasSubstr("colur"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {rect: [1, 2, 2, 30]}\n"),
              HasSubstr("template.rect: [1, 2, 2, 30]"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {rect: [1, 2, 30, 30], "
                      "report: middle}\n"),
              HasSubstr("markers[0].template.report"));
}

// imread on a FIFO or /dev/stdin would wait for ever for a writer: refused before it is opened.
TEST(TemplateConfig, ATemplateFileThatIsNoRegularFileIsRefusedWithoutReadingIt) {
  TempDir dir;
  ASSERT_EQ(mkfifo(dir.file("fifo.png").c_str(), 0600), 0);
  std::filesystem::create_directory(dir.file("folder.png"));
  for (const std::string& file :
       {dir.file("folder.png"), std::string("/dev/null"), dir.file("fifo.png")}) {
    const std::string message = testing::ConfigErrorOf(
        "markers:\n  - name: red\n    template: {file: " + file + "}\n");
    EXPECT_THAT(message, HasSubstr("markers[0].template.file: '" + file +
                                   "' is not a regular file"));
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(TemplateConfig, IntegersPastAnyImageSizeAreRefused) {
  // 2147483647 once overflowed a signed int in the tracker's search window (UBSan).
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {rect: [205, 186, 25, "
                                     "25], acquire_radius_px: 2147483647}\n"),
              HasSubstr("template.acquire_radius_px"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {rect: [2147483600, "
                                     "186, 25, 25]}\n"),
              HasSubstr("template.rect"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {frame: 2147483647, "
                                     "rect: [205, 186, 25, 25]}\n"),
              HasSubstr("template.frame"));
}

}  // namespace
}  // namespace softsight
