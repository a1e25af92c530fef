// End-to-end tests of `softsight track`: rendered video in, CSV out, checked against the truth.
#include "app/track_command.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "app/program_test_util.h"
#include "app/scene_markers_test_util.h"
#include "app/truth_sink.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::ProgramRun;
using testing::RunProgram;
using testing::TempDir;

// The scene's markers with a scale, so the millimetre columns are written too.
const std::string kConfig = testing::kScaledSceneMarkersYaml;

struct RenderedClip {
  std::string video;
  std::vector<SceneTruth> truth;
};

// Renders a short bending sequence into a lossless video (FFV1, or another FourCC).
RenderedClip RenderClip(const TempDir& dir, int frames, bool gray = false,
                        int fourcc = cv::VideoWriter::fourcc('F', 'F', 'V', '1'),
                        const std::string& name = "clip.avi") {
  SceneOptions scene;
  scene.frame_count = frames;
  scene.max_bend_deg = 200;
  SyntheticScene renderer(scene);
  RenderedClip clip;
  clip.video = dir.file(name);
  cv::VideoWriter writer(clip.video, cv::CAP_FFMPEG, fourcc, scene.fps, scene.size,
                         /*isColor=*/!gray);
  EXPECT_TRUE(writer.isOpened());
  cv::Mat image, gray_image;
  for (int i = 0; i < frames; ++i) {
    clip.truth.push_back(renderer.render(i, image));
    if (gray) {
      cv::cvtColor(image, gray_image, cv::COLOR_BGR2GRAY);
      writer << gray_image;
    } else {
      writer << image;
    }
  }
  return clip;
}


// `track` runs in the commands plugin, which must not load the live window's libraries (highgui
// and its Qt: ~12 libraries and ~10 ms of every start-up; X11 comes with FFmpeg's hardware
// decoders anyway): what the dynamic loader loaded
// for `track --help` and for `live --help`, the GUI's plugin, which does.
TEST(TrackCommand, LoadsVideoLibrariesButNoneOfTheLiveWindows) {
  TempDir dir;
  auto loaded = [&](const std::string& command) {
    const std::string log = dir.file("loader.txt");
    const int status = std::system(("LD_DEBUG=libs LD_DEBUG_OUTPUT=" + log + " " +
                                    testing::SoftsightBinary() + " " + command + " > /dev/null")
                                       .c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;
    // The loader writes its log to LD_DEBUG_OUTPUT.<pid>: the one file there is.
    std::string text;
    for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
      if (entry.path().filename().string().rfind("loader.txt.", 0) == 0) {
        text += testing::ReadTextFile(entry.path().string());
        std::filesystem::remove(entry.path());
      }
    }
    return text;
  };
  const std::string track = loaded("track --help");
  EXPECT_THAT(track, ::testing::HasSubstr("libopencv_videoio"));
  EXPECT_THAT(track, ::testing::Not(::testing::HasSubstr("libopencv_highgui")));
  EXPECT_THAT(track, ::testing::Not(::testing::HasSubstr("libQt5Widgets")));
  EXPECT_THAT(loaded("live --help"), ::testing::HasSubstr("libopencv_highgui"));
  // track-stereo likewise; with --window it runs in the live plugin, which has its window.
  EXPECT_THAT(loaded("track-stereo --help"),
              ::testing::Not(::testing::HasSubstr("libopencv_highgui")));
  EXPECT_THAT(loaded("track-stereo --window --help"), ::testing::HasSubstr("libopencv_highgui"));
}

// Camera settings with frames from a file: a --camera-* option cannot be carried out and is
// refused before anything is written; a config's capture: section (a live recording saves one)
// is said to be unused, and the run goes on.
TEST(TrackCommand, CameraSettingsWithAFileAreRefusedOnTheCommandLineAndNotedFromTheConfig) {
  TempDir dir;
  const RenderedClip clip = RenderClip(dir, 3);
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  const ProgramRun refused =
      RunProgram("track --config " + dir.file("markers.yaml") + " --input " + clip.video +
                    " --csv " + dir.file("a.csv") + " --camera-exposure 120",
                dir);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.stderr_text,
              HasSubstr("--camera-exposure 120: camera settings apply to a camera (--camera N), "
                        "and the frames come from the file " + clip.video));
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.csv")));

  testing::WriteTextFile(dir.file("recorded.yaml"),
                         std::string(kConfig) + "capture:\n  exposure: 120\n");
  const ProgramRun noted = RunProgram("track --config " + dir.file("recorded.yaml") + " --input " +
                                         clip.video + " --csv " + dir.file("b.csv"),
                                     dir);
  EXPECT_EQ(noted.exit_code, 0) << noted.stderr_text;
  EXPECT_THAT(noted.stderr_text, HasSubstr("note: " + dir.file("recorded.yaml") +
                                           ": its capture: settings are for a camera and are not "
                                           "used with the file " + clip.video));
  EXPECT_EQ(testing::ReadLines(dir.file("b.csv")).size(), 4u);
}

TEST(TrackCommand, RenderedVideoGivesTruthWithinTolerances) {
  TempDir dir;
  const RenderedClip clip = RenderClip(dir, 40);
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.source.input = clip.video;
  options.csv_file = dir.file("out.csv");
  options.quiet = true;
  TruthScoreSink truth(clip.truth, 3);  // The one scorer against the renderer's truth.
  const RunSummary summary = RunTrack(options, nullptr, {&truth});
  EXPECT_EQ(summary.frames, 40);
  EXPECT_EQ(summary.stop_reason, StopReason::kEndOfInput);
  EXPECT_EQ(summary.dropped, 0);
  ASSERT_EQ(summary.markers.size(), 3u);
  for (const MarkerRunSummary& marker : summary.markers) EXPECT_EQ(marker.found, 40);
  const TruthScore score = truth.score();
  EXPECT_EQ(score.visible, 120);
  EXPECT_EQ(score.misses, 0);
  EXPECT_EQ(score.false_reports, 0);
  ASSERT_TRUE(score.centroid_rms_px && score.angle_rms_deg);
  EXPECT_LT(*score.centroid_rms_px, 0.1) << "centroid RMS error, px";
  EXPECT_LT(*score.angle_rms_deg, 0.2) << "angle RMS error, deg";

  // The CSV says the same: one row per source frame, millimetres = scale x pixels.
  const std::vector<std::string> lines = testing::ReadLines(options.csv_file);
  ASSERT_EQ(lines.size(), 41u);
  const std::vector<std::string> header = testing::SplitCsv(lines[0]);
  auto column = [&](const std::string& name) {
    return static_cast<size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  for (int i = 0; i < 40; ++i) {
    const std::vector<std::string> row = testing::SplitCsv(lines[i + 1]);
    ASSERT_EQ(row.size(), header.size());
    EXPECT_EQ(row[column("frame")], std::to_string(i));
    const cv::Point2d red = *clip.truth[i].markers[0].centroid_px;
    EXPECT_NEAR(std::stod(row[column("red_x")]), red.x, 0.3);
    EXPECT_NEAR(std::stod(row[column("red_y")]), red.y, 0.3);
    EXPECT_NEAR(std::stod(row[column("chord_mm")]), 0.2 * std::stod(row[column("chord_px")]),
                1e-3);
  }
}

TEST(TrackCommand, AnnotatedVideoHasEveryFrameWithTheOverlayOnTheMarkers) {
  TempDir dir;
  const RenderedClip clip = RenderClip(dir, 5);
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.source.input = clip.video;
  options.csv_file = dir.file("out.csv");
  options.annotated_file = dir.file("annotated.avi");
  options.quiet = true;
  RunTrack(options);
  cv::VideoCapture annotated(*options.annotated_file);
  ASSERT_TRUE(annotated.isOpened());
  EXPECT_EQ(annotated.get(cv::CAP_PROP_FRAME_COUNT), 5);
  cv::VideoCapture original(clip.video);
  cv::Mat drawn, plain;
  ASSERT_TRUE(annotated.read(drawn));
  ASSERT_TRUE(original.read(plain));
  // The overlay changes pixels around each marker, and leaves a far corner alone.
  for (const MarkerTruth& marker : clip.truth[0].markers) {
    const cv::Rect around(cv::Point(static_cast<int>(marker.centroid_px->x) - 16,
                                    static_cast<int>(marker.centroid_px->y) - 16),
                          cv::Size(33, 33));
    EXPECT_GT(cv::norm(drawn(around), plain(around), cv::NORM_L1) / around.area(), 10.0)
        << marker.name << ": nothing drawn around the marker";
  }
  const cv::Rect corner(drawn.cols - 40, drawn.rows - 40, 30, 30);
  EXPECT_LT(cv::norm(drawn(corner), plain(corner), cv::NORM_L1) / corner.area(), 12.0)
      << "only JPEG noise expected far from the overlay";
}

// Every column but the timings (latency_result_ms, latency_row_ms, proc_ms) of a CSV, row by row.
TEST(TrackCommand, OneMarkerConfigWritesItsPositionsAndStatusWithoutMeasurements) {
  TempDir dir;
  const RenderedClip clip = RenderClip(dir, 6);
  testing::WriteTextFile(dir.file("one.yaml"), R"(markers:
  - name: blue
    hsv: {h: [100, 130], s: [80, 255], v: [40, 255]}
)");
  TrackOptions options;
  options.config_file = dir.file("one.yaml");
  options.source.input = clip.video;
  options.csv_file = dir.file("out.csv");
  options.quiet = true;
  EXPECT_EQ(RunTrack(options).frames, 6);
  const std::vector<std::string> lines = testing::ReadLines(options.csv_file);
  ASSERT_EQ(lines.size(), 7u);
  const std::vector<std::string> header = testing::SplitCsv(lines[0]);
  auto column = [&](const std::string& name) {
    const auto at = std::find(header.begin(), header.end(), name);
    EXPECT_NE(at, header.end()) << name;
    return static_cast<size_t>(at - header.begin());
  };
  for (int i = 0; i < 6; ++i) {
    const std::vector<std::string> row = testing::SplitCsv(lines[i + 1] + ",");
    const cv::Point2d truth = *clip.truth[i].markers[1].centroid_px;
    EXPECT_NEAR(std::stod(row[column("blue_x")]), truth.x, 0.2);
    EXPECT_NEAR(std::stod(row[column("blue_y")]), truth.y, 0.2);
    EXPECT_EQ(row[column("blue_status")], "found");
    EXPECT_EQ(row[column("angle_deg")], "") << "no triple, no angle";
  }
}

std::vector<std::vector<std::string>> TrackingRows(const std::string& csv) {
  std::vector<std::vector<std::string>> rows;
  for (const std::string& line : testing::ReadLines(csv)) {
    std::vector<std::string> fields = testing::SplitCsv(line);
    fields.resize(fields.size() - 3);  // The timings end the row: latency_*_ms, proc_ms.
    rows.push_back(fields);
  }
  return rows;
}

TEST(TrackCommand, RawRecordingTrackedAgainGivesTheSameRows) {
  TempDir dir;
  const RenderedClip clip = RenderClip(dir, 8);
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.source.input = clip.video;
  options.csv_file = dir.file("first.csv");
  options.record_file = dir.file("raw.avi");
  options.quiet = true;
  RunTrack(options);
  TrackOptions again = options;
  again.source.input = *options.record_file;
  again.csv_file = dir.file("again.csv");
  again.record_file.reset();
  RunTrack(again);
  const auto first = TrackingRows(options.csv_file);
  ASSERT_EQ(first.size(), 9u);
  EXPECT_EQ(first.front().back(), "tip_disp_mm") << "header, without the timings";
  EXPECT_EQ(TrackingRows(again.csv_file), first);
}

TEST(TrackCommand, CorruptVideoExitsWithCodeTwoAndKeepsEveryRowWritten) {
  TempDir dir;
  const RenderedClip clip = RenderClip(dir, 30);
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  {  // Cut the file short: the rows of the frames before the cut must survive.
    std::ifstream in(clip.video, std::ios::binary);
    std::string data((std::istreambuf_iterator<char>(in)), {});
    in.close();
    data.resize(data.size() * 2 / 3);
    std::ofstream(clip.video, std::ios::binary).write(data.data(), data.size());
  }
  const ProgramRun run = RunProgram("track -q -c " + dir.file("markers.yaml") + " -i " + clip.video +
                                " -o " + dir.file("out.csv"),
                            dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.stderr_text, HasSubstr(clip.video));
  EXPECT_EQ(std::count(run.stderr_text.begin(), run.stderr_text.end(), '\n'), 1)
      << "one error line, got: " << run.stderr_text;
  const std::vector<std::string> lines = testing::ReadLines(dir.file("out.csv"));
  ASSERT_GT(lines.size(), 10u);
  ASSERT_LT(lines.size(), 31u);
  const size_t columns = testing::SplitCsv(lines[0]).size();
  for (size_t i = 1; i < lines.size(); ++i) {
    EXPECT_EQ(testing::SplitCsv(lines[i]).size(), columns) << "row " << i << " is damaged";
  }
}

// 20 bits flipped in the middle of a lossless recording (the hostile trial's reproduction).
// FFV1 as OpenCV writes it has no slice checksums: the decoder reports nothing, decodes garbage
// down to some row until its next key frame and leaves the rest of the frame stale (seed 1: the
// red base marker 3.4 px behind the truth). HuffYUV has no check either, and a flip shifts the
// colours (or the pixels) of the rest of the frame (the red base marker turned blue, and the
// blue tracker re-acquired it); the video source leaves most such frames out
// (io/damaged_band.h). Either way no marker may be reported found more
// than 3 px from the truth: damaged frames lose markers, they must not move them.
// `clean` with 20 bits flipped at places drawn (by `seed`) between fractions `from` and `to` of
// its length, written to `video`; then tracked (the run's InputError, if any, is returned).
std::string TrackWithBitFlips(const TempDir& dir, const std::string& clean, unsigned seed,
                              double from, double to, const std::string& video,
                              TruthScoreSink& truth) {
  std::string data = clean;
  std::mt19937 random(seed);
  std::uniform_int_distribution<size_t> where(static_cast<size_t>(data.size() * from),
                                              static_cast<size_t>(data.size() * to));
  std::uniform_int_distribution<int> bit(0, 7);
  for (int flip = 0; flip < 20; ++flip) data[where(random)] ^= static_cast<char>(1 << bit(random));
  std::ofstream(video, std::ios::binary).write(data.data(), static_cast<std::streamsize>(data.size()));
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.source.input = video;
  options.csv_file = dir.file("out.csv");
  options.quiet = true;
  try {
    RunTrack(options, nullptr, {&truth});
  } catch (const InputError& e) {
    return e.what();  // The decoder's own report of damaged frames ends the run with an error.
  }
  return "";
}

TEST(TrackCommand, BitFlipsInALosslessVideoNeverGiveAConfidentlyWrongPosition) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  for (const int fourcc : {cv::VideoWriter::fourcc('F', 'F', 'V', '1'),
                           cv::VideoWriter::fourcc('H', 'F', 'Y', 'U')}) {
    const RenderedClip clip = RenderClip(dir, 40, false, fourcc);
    std::ifstream in(clip.video, std::ios::binary);
    const std::string clean((std::istreambuf_iterator<char>(in)), {});
    in.close();
    for (const unsigned seed : {1u, 2u, 3u}) {
      TruthScoreSink truth(clip.truth, 3);
      TrackWithBitFlips(dir, clean, seed, 0.4, 0.6, dir.file("flipped.avi"), truth);
      const TruthScore score = truth.score();
      const std::string what = std::string(fourcc == cv::VideoWriter::fourcc('H', 'F', 'Y', 'U')
                                               ? "HuffYUV"
                                               : "FFV1") +
                               ", flip seed " + std::to_string(seed);
      EXPECT_EQ(score.false_reports, 0) << what;
      ASSERT_TRUE(score.centroid_max_px) << what << ": nothing found at all";
      EXPECT_LT(*score.centroid_max_px, 3.0) << what << ": a marker reported found that far off";
      EXPECT_GT(score.found_visible, score.visible / 2) << what << ": the clean frames are tracked";
    }
  }
}

// Issue 44, D9 and D10: the hostile trial's single flipped bits in intra-only recordings of
// `synth -n 120 --oscillate`, each of which the decoder takes without a word. In Motion JPEG
// (frame 53, byte 14683 of its JPEG, bit 1) the Huffman codes get out of step and back: from
// one MCU row on the picture is shifted 16 px and brightened, and the green marker was reported
// found 16 px off, exit 0. In HuffYUV (frame 11, byte 105131, bit 0) a residual goes wrong and
// the colours of every pixel decoded after it move: the green marker 3-4 px off, exit 0. Now
// the frame is left out as damaged (no row, the run ends with the error), and no marker is
// reported more than 2 px from the truth.
//
// The `frame`-th video chunk of an AVI ('00dc'), from the chunk list.
size_t AviChunkData(const std::string& avi, int frame) {
  size_t at = avi.find("movi") + 4;
  for (int k = 0; at + 8 <= avi.size();) {
    const std::string tag = avi.substr(at, 4);
    uint32_t size = 0;
    std::memcpy(&size, avi.data() + at + 4, 4);  // Little-endian, as the machines it runs on.
    if (tag == "00dc" && k++ == frame) return at + 8;
    at += 8 + size + (size & 1);
  }
  ADD_FAILURE() << "no chunk for frame " << frame;
  return 0;
}

TEST(TrackCommand, OneFlippedBitInAnIntraOnlyRecordingLeavesItsFrameOutAndMovesNoMarker) {
  TempDir dir;
  const std::string markers = testing::SourceDir() + "/examples/markers.yaml";
  struct Flip {
    const char* codec;
    int frame;
    size_t offset;
    int bit;
  };
  for (const Flip& flip : {Flip{"mjpg", 53, 14683, 1}, Flip{"hfyu", 11, 105131, 0}}) {
    const std::string codec = flip.codec;
    const std::string clean = dir.file(codec + ".avi"), damaged = dir.file(codec + "_flip.avi");
    ASSERT_EQ(RunProgram("synth -n 120 --oscillate --codec " + codec + " -q -o " + clean +
                             " --truth " + dir.file("truth.csv"),
                         dir)
                  .exit_code,
              0);
    std::string data = testing::ReadTextFile(clean);
    const size_t at = AviChunkData(data, flip.frame) + flip.offset;
    data[at] = static_cast<char>(data[at] ^ (1 << flip.bit));
    testing::WriteTextFile(damaged, data);
    {  // The flip still damages that frame (else the rendering changed: find another flip).
      cv::VideoCapture a(clean, cv::CAP_FFMPEG), b(damaged, cv::CAP_FFMPEG);
      cv::Mat x, y, difference;
      for (int i = 0; i <= flip.frame; ++i) ASSERT_TRUE(a.read(x) && b.read(y));
      cv::absdiff(x, y, difference);
      ASSERT_GT(cv::countNonZero(difference.reshape(1) > 8), static_cast<int>(x.total() / 20))
          << codec << ": the flip no longer damages frame " << flip.frame;
    }
    const ProgramRun run =
        RunProgram("track -q -c " + markers + " -i " + damaged + " -o " + dir.file("out.csv"), dir);
    EXPECT_EQ(run.exit_code, 2) << codec << ": " << run.stderr_text;
    EXPECT_THAT(run.stderr_text, HasSubstr("1 frame the decoder found damaged is left out "
                                           "(first: frame " + std::to_string(flip.frame)))
        << codec;
    // Every marker found within 2 px of where the renderer put it.
    const std::vector<std::string> truth = testing::ReadLines(dir.file("truth.csv"));
    const std::vector<std::string> rows = testing::ReadLines(dir.file("out.csv"));
    ASSERT_GT(rows.size(), 100u) << codec;
    const std::vector<std::string> truth_header = testing::SplitCsv(truth[0]);
    const std::vector<std::string> header = testing::SplitCsv(rows[0]);
    auto column = [](const std::vector<std::string>& names, const std::string& name) {
      return static_cast<size_t>(std::find(names.begin(), names.end(), name) - names.begin());
    };
    for (size_t r = 1; r < rows.size(); ++r) {
      const std::vector<std::string> row = testing::SplitCsv(rows[r]);
      const int64_t frame = std::stoll(row[0]);
      EXPECT_NE(frame, flip.frame) << codec << ": the damaged frame has a row";
      const std::vector<std::string> expected =
          testing::SplitCsv(truth[static_cast<size_t>(frame) + 1]);
      for (const char* marker : {"red", "blue", "green"}) {
        const std::string m = marker;
        if (row[column(header, m + "_found")] != "1") continue;
        const double dx = std::stod(row[column(header, m + "_x")]) -
                          std::stod(expected[column(truth_header, m + "_x")]);
        const double dy = std::stod(row[column(header, m + "_y")]) -
                          std::stod(expected[column(truth_header, m + "_y")]);
        EXPECT_LE(std::hypot(dx, dy), 2.0) << codec << ": " << m << " in frame " << frame;
      }
    }
  }
}

// MPEG-4 predicts each frame from the one before: a flipped bit the decoder complains about once
// goes on, silently, in every frame decoded from it until the next key frame (every 12th frame as
// OpenCV writes it), where a marker would be measured in the damaged picture. Those frames are
// left out with the damaged one: after a gap, rows resume only at a key frame. And no marker is
// reported found away from where it is (the issue's "confident wrong rows").
TEST(TrackCommand, BitFlipsInAPredictedVideoLeaveOutEveryFrameUpToTheNextKeyFrame) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  const RenderedClip clip =
      RenderClip(dir, 120, false, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), "clip.mp4");
  constexpr int64_t kKeyFrameInterval = 12;  // OpenCV's MPEG-4 writer (FFmpeg's gop_size).
  std::ifstream in(clip.video, std::ios::binary);
  const std::string clean((std::istreambuf_iterator<char>(in)), {});
  in.close();
  int carried = 0;
  for (const unsigned seed : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u}) {
    TruthScoreSink truth(clip.truth, 3);
    const std::string error =
        TrackWithBitFlips(dir, clean, seed, 0.05, 0.95, dir.file("flipped.mp4"), truth);
    carried += error.find("decoded from them up to the next key frame") != std::string::npos;
    const std::string what = "MPEG-4, flip seed " + std::to_string(seed);
    std::vector<int64_t> rows;
    const std::vector<std::string> lines = testing::ReadLines(dir.file("out.csv"));
    for (size_t i = 1; i < lines.size(); ++i) rows.push_back(std::stoll(lines[i]));
    for (size_t i = 0; i < rows.size(); ++i) {
      const int64_t previous = i == 0 ? -1 : rows[i - 1];
      if (rows[i] != previous + 1) {
        EXPECT_EQ(rows[i] % kKeyFrameInterval, 0)
            << what << ": rows resume at frame " << rows[i] << " after frame " << previous
            << ", a frame decoded from a damaged one";
      }
    }
    const TruthScore score = truth.score();
    EXPECT_EQ(score.false_reports, 0) << what;
    EXPECT_EQ(score.wrong_finds, 0) << what << ": markers found more than 3 px off";
    std::printf("%s: %lld rows, worst marker %.1f px off, %lld found > 3 px off\n", what.c_str(),
                static_cast<long long>(rows.size()), score.centroid_max_px.value_or(0.0),
                static_cast<long long>(score.wrong_finds));
  }
  EXPECT_GT(carried, 0) << "no run had damage carried into later frames: the test tests nothing";
}

// A measurement, not a check (run with --gtest_also_run_disabled_tests; the figures are in
// docs/usage.md, "Damaged video"): 20 bits flipped in the 200-degree MPEG-4 clip, over 40 seeds
// (SOFTSIGHT_FLIP_SEEDS sets how many); per seed and in all, the marker-frames found more than
// 3 px from the truth, and what leaving out damaged frames costs: the rows and marker-frames kept.
TEST(TrackCommand, DISABLED_BitFlipSweep) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  const RenderedClip clip =
      RenderClip(dir, 120, false, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), "clip.mp4");
  std::ifstream in(clip.video, std::ios::binary);
  const std::string clean((std::istreambuf_iterator<char>(in)), {});
  in.close();
  const char* seeds_text = std::getenv("SOFTSIGHT_FLIP_SEEDS");
  const unsigned seeds = seeds_text ? static_cast<unsigned>(std::stoul(seeds_text)) : 40u;
  int64_t rows = 0, found = 0, wrong = 0;
  int seeds_wrong = 0, seeds_far = 0;
  double worst = 0.0;
  for (unsigned seed = 1; seed <= seeds; ++seed) {
    TruthScoreSink truth(clip.truth, 3);
    TrackWithBitFlips(dir, clean, seed, 0.05, 0.95, dir.file("flipped.mp4"), truth);
    const TruthScore score = truth.score();
    const double seed_worst = score.centroid_max_px.value_or(0.0);
    std::printf("seed %u: %lld rows, %lld marker-frames found, %lld > 3 px off, worst %.1f px\n",
                seed, static_cast<long long>(score.frames),
                static_cast<long long>(score.found_visible),
                static_cast<long long>(score.wrong_finds), seed_worst);
    rows += score.frames;
    found += score.found_visible;
    wrong += score.wrong_finds;
    seeds_wrong += score.wrong_finds > 0;
    seeds_far += seed_worst > 10.0;
    worst = std::max(worst, seed_worst);
  }
  std::printf("%u seeds: %lld rows of %u frames, %lld marker-frames found; %lld found > 3 px off, "
              "in %d seeds; %d seeds > 10 px off; worst %.1f px\n",
              seeds, static_cast<long long>(rows), seeds * 120u, static_cast<long long>(found),
              static_cast<long long>(wrong), seeds_wrong, seeds_far, worst);
}

TEST(TrackCommand, GrayVideoWithColourTrackingIsRefusedWithAHint) {
  TempDir dir;
  const RenderedClip clip = RenderClip(dir, 3, /*gray=*/true);
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  const ProgramRun run = RunProgram("track -c " + dir.file("markers.yaml") + " -i " + clip.video +
                                " -o " + dir.file("out.csv"),
                            dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.stderr_text, HasSubstr("grayscale"));
  EXPECT_THAT(run.stderr_text, HasSubstr(clip.video));
}

TEST(TrackCommand, BadConfigAndMissingInputExitWithCodeTwo) {
  TempDir dir;
  testing::WriteTextFile(dir.file("bad.yaml"), "markers:\n  - name: red\n    hsv: {h: [0, 300]}\n");
  testing::WriteTextFile(dir.file("good.yaml"), kConfig);
  ProgramRun run = RunProgram("track -c " + dir.file("bad.yaml") + " -i x.avi -o " + dir.file("o.csv"), dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.stderr_text, HasSubstr("bad.yaml:3"));
  run = RunProgram("track -c " + dir.file("good.yaml") + " -i " + dir.file("none.avi") + " -o " +
                      dir.file("o.csv"),
                  dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.stderr_text, HasSubstr("none.avi"));
  run = RunProgram("track -c " + dir.file("good.yaml"), dir);
  EXPECT_EQ(run.exit_code, 2) << "missing required options";
}

// `track` on the built-in bending scene (300 frames), sent `signal` once `rows` CSV lines are on
// disk; returns the wait status.
int TrackSignalledAfterRows(const TempDir& dir, size_t rows, int signal) {
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  return testing::RunAndSignalOnceRowsAreWritten(
      "track -c " + dir.file("markers.yaml") + " -i synth:bending -o " + dir.file("out.csv"),
      dir.file("out.csv"), rows, signal, dir.file("stderr.txt"));
}

TEST(TrackCommand, CtrlCStopsWithASummaryAndEveryRowComplete) {
  TempDir dir;
  const std::string csv = dir.file("out.csv");
  const int status = TrackSignalledAfterRows(dir, 6, SIGINT);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping cleanly";
  EXPECT_EQ(WEXITSTATUS(status), 130) << "128 + SIGINT: an interrupted run is not a complete one";
  EXPECT_THAT(testing::ReadTextFile(dir.file("stderr.txt")), HasSubstr("stopped by Ctrl-C"));
  const std::vector<std::string> lines = testing::ReadLines(csv);
  ASSERT_GE(lines.size(), 6u);
  ASSERT_LT(lines.size(), 301u) << "the run ended before the interrupt arrived";
  const size_t columns = testing::SplitCsv(lines[0]).size();
  for (size_t i = 1; i < lines.size(); ++i) {
    EXPECT_EQ(testing::SplitCsv(lines[i]).size(), columns) << "row " << i;
  }
}

TEST(TrackCommand, TemplateMethodWithoutTemplateIsRefused) {
  TempDir dir;
  const RenderedClip clip = RenderClip(dir, 2);
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.source.input = clip.video;
  options.csv_file = dir.file("out.csv");
  options.method = "zncc";
  options.quiet = true;
  EXPECT_THROW(RunTrack(options), InputError);
}

TEST(TrackCommand, SigtermStopsWithItsOwnReasonAndExitCode) {
  TempDir dir;
  const int status = TrackSignalledAfterRows(dir, 4, SIGTERM);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping cleanly";
  EXPECT_EQ(WEXITSTATUS(status), 143);
  const std::string text = testing::ReadTextFile(dir.file("stderr.txt"));
  EXPECT_THAT(text, HasSubstr("stopped by SIGTERM"));
  EXPECT_THAT(text, ::testing::Not(HasSubstr("Ctrl-C")));
  EXPECT_THAT(text, HasSubstr("frames:")) << "the summary comes before the exit";
}

// Runs `track` with `args` on a two-frame rendered clip and a valid config.
class TrackRefuses : public ::testing::Test {
 protected:
  void SetUp() override {
    clip_ = RenderClip(dir_, 2);
    testing::WriteTextFile(config(), kConfig);
  }
  std::string config() const { return dir_.file("markers.yaml"); }
  ProgramRun Track(const std::string& args) {
    return RunProgram("track -q -c " + config() + " " + args, dir_);
  }
  // One error line naming `what`, exit code 2.
  void ExpectOneError(const ProgramRun& run, const std::string& what) {
    EXPECT_EQ(run.exit_code, 2) << run.stderr_text;
    EXPECT_THAT(run.stderr_text, HasSubstr(what));
    EXPECT_EQ(std::count(run.stderr_text.begin(), run.stderr_text.end(), '\n'), 1)
        << "one error line, got: " << run.stderr_text;
  }
  TempDir dir_;
  RenderedClip clip_;
};

TEST_F(TrackRefuses, PatternThatIsNotOneNumber) {
  std::filesystem::create_directories(dir_.file("frames"));
  for (const std::string pattern : {"frames/%s.png", "frames/%n.png", "frames/%d%d.png"}) {
    ExpectOneError(Track("-i '" + dir_.file(pattern) + "' -o " + dir_.file("o.csv")), pattern);
  }
}

TEST_F(TrackRefuses, NegativeMaxFrames) {
  ExpectOneError(Track("-i " + clip_.video + " -o " + dir_.file("o.csv") + " --max-frames -1"),
                 "--max-frames");
}

TEST_F(TrackRefuses, FpsThatIsNotAPositiveFiniteNumber) {
  std::filesystem::create_directories(dir_.file("frames"));
  cv::imwrite(dir_.file("frames/0.png"), cv::Mat(48, 64, CV_8UC3, cv::Scalar(10, 20, 30)));
  for (const std::string fps : {"inf", "-inf", "nan", "0", "-1", "1e400"}) {
    ExpectOneError(Track("-i " + dir_.file("frames") + " -o " + dir_.file("o.csv") + " --fps " + fps),
                   "--fps");
  }
}

TEST_F(TrackRefuses, OutputThatIsAnInputAndLeavesItUntouched) {
  const std::string video_before = testing::ReadTextFile(clip_.video);
  const std::string config_before = testing::ReadTextFile(config());
  ExpectOneError(Track("-i " + clip_.video + " -o " + clip_.video), "refusing to overwrite");
  ExpectOneError(Track("-i " + clip_.video + " -o " + config()), "refusing to overwrite");
  // The same file by another spelling, and by a hard link.
  std::filesystem::create_hard_link(clip_.video, dir_.file("link.avi"));
  ExpectOneError(Track("-i " + clip_.video + " -o " + dir_.path().string() + "/./link.avi"),
                 "refusing to overwrite");
  ExpectOneError(Track("-i " + clip_.video + " -o " + dir_.file("o.csv") + " --annotated " +
                       clip_.video),
                 "refusing to overwrite");
  EXPECT_EQ(testing::ReadTextFile(clip_.video), video_before);
  EXPECT_EQ(testing::ReadTextFile(config()), config_before);

  // A frame of the input sequence.
  std::filesystem::create_directories(dir_.file("frames"));
  for (int i = 0; i < 3; ++i) {
    cv::imwrite(dir_.file("frames/f" + std::to_string(i) + ".png"),
                cv::Mat(48, 64, CV_8UC3, cv::Scalar(10, 20, 30)));
  }
  const std::string frame_before = testing::ReadTextFile(dir_.file("frames/f1.png"));
  ExpectOneError(Track("-i " + dir_.file("frames") + " -o " + dir_.file("frames/f1.png")),
                 "f1.png");
  ExpectOneError(Track("-i '" + dir_.file("frames/f%d.png") + "' -o " +
                       dir_.file("frames/f2.png")),
                 "f2.png");
  // An image-pattern output that would write over frames of the input (a folder or a pattern).
  for (const std::string& input : {dir_.file("frames"), "'" + dir_.file("frames/f%d.png") + "'"}) {
    ExpectOneError(Track("-i " + input + " -o " + dir_.file("o.csv") + " --record '" +
                         dir_.file("frames/f%d.png") + "'"),
                   "would write --input");
    ExpectOneError(Track("-i " + input + " -o " + dir_.file("o.csv") + " --annotated '" +
                         dir_.path().string() + "/./frames/f%d.png'"),
                   "refusing to overwrite");
  }
  EXPECT_EQ(testing::ReadTextFile(dir_.file("frames/f1.png")), frame_before);

  // A file the config names (the camera model).
  testing::WriteTextFile(dir_.file("camera.yaml"),
                         "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
                         "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                         "   data: [500., 0., 320., 0., 500., 240., 0., 0., 1.]\n"
                         "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n"
                         "   dt: d\n   data: [0., 0., 0., 0., 0.]\n");
  testing::WriteTextFile(dir_.file("with_camera.yaml"), kConfig + "camera: camera.yaml\n");
  const std::string camera_before = testing::ReadTextFile(dir_.file("camera.yaml"));
  const ProgramRun run = RunProgram("track -q -c " + dir_.file("with_camera.yaml") + " -i " +
                                       clip_.video + " -o " + dir_.file("camera.yaml"),
                                   dir_);
  ExpectOneError(run, "camera.yaml");
  EXPECT_EQ(testing::ReadTextFile(dir_.file("camera.yaml")), camera_before);
}

TEST_F(TrackRefuses, OutputOnAFullDevice) {
  ExpectOneError(Track("-i " + clip_.video + " -o /dev/full --max-frames 0"), "/dev/full");
}

TEST_F(TrackRefuses, ConfigWithRandomBytesOrAComplexKeyInOneEscapedLine) {
  std::mt19937 random(11);
  for (int trial = 0; trial < 5; ++trial) {
    std::string bytes(200, '\0');
    for (char& c : bytes) c = static_cast<char>(random() & 0xFF);
    testing::WriteTextFile(dir_.file("random.yaml"), bytes);
    const ProgramRun run = RunProgram(
        "track -q -c " + dir_.file("random.yaml") + " -i " + clip_.video + " -o " + dir_.file("o.csv"),
        dir_);
    ExpectOneError(run, "random.yaml");
    for (char c : run.stderr_text.substr(0, run.stderr_text.size() - 1)) {
      ASSERT_FALSE(static_cast<unsigned char>(c) < 0x20 || c == 0x7f) << "raw control character";
    }
  }
  testing::WriteTextFile(dir_.file("key.yaml"), kConfig + "? [a, b]\n: 1\n");
  ExpectOneError(RunProgram("track -q -c " + dir_.file("key.yaml") + " -i " + clip_.video + " -o " +
                               dir_.file("o.csv"),
                           dir_),
                 "key.yaml:10:");
}

TEST(TrackCommand, SequenceWithAGapNumbersRowsByFileAndSaysSoInTheSummary) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  SceneOptions scene;
  scene.frame_count = 6;
  SyntheticScene renderer(scene);
  cv::Mat image;
  std::filesystem::create_directories(dir.file("frames"));
  for (int i : {0, 1, 2, 4, 5}) {  // File 3 is missing.
    renderer.render(i, image);
    char name[32];
    std::snprintf(name, sizeof(name), "frames/%04d.png", i);
    cv::imwrite(dir.file(name), image);
  }
  const ProgramRun run = RunProgram("track -c " + dir.file("markers.yaml") + " -i '" +
                                       dir.file("frames/%04d.png") + "' -o " + dir.file("o.csv"),
                                   dir);
  EXPECT_EQ(run.exit_code, 0) << run.stderr_text;
  EXPECT_THAT(run.stderr_text, HasSubstr("1 file number missing (first: 3)"));
  const std::vector<std::string> lines = testing::ReadLines(dir.file("o.csv"));
  ASSERT_EQ(lines.size(), 6u);
  std::vector<std::string> frames;
  for (size_t i = 1; i < lines.size(); ++i) frames.push_back(testing::SplitCsv(lines[i])[0]);
  EXPECT_THAT(frames, ::testing::ElementsAre("0", "1", "2", "4", "5"));
}

}  // namespace
}  // namespace softsight
