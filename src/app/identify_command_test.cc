// `softsight identify` and `control --auto-tune` end to end on the simulated rig: rendered frames
// through the tracker, the board over a real pseudo-terminal, simulated time.
#include "app/identify_command.h"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/program_test_util.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/config/config.h"
#include "softsight/control/rig.h"
#include "softsight/core/format.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::ReadLines;
using testing::ReadTextFile;
using testing::SplitCsv;
using testing::TempDir;
using testing::WriteTextFile;



TEST(IdentifyCommand, SimulatedRigThroughTheTrackerWritesATunedConfigAndLeavesTheInput) {
  TempDir dir;
  const std::string input = dir.file("rig.yaml");
  WriteTextFile(input, ReadTextFile(testing::RigExample()));
  IdentifyCommandOptions o;
  o.config_file = input;
  o.output_file = dir.file("tuned.yaml");
  o.simulate = true;
  o.sim_supersample = 1;
  o.csv_file = dir.file("ident.csv");
  o.model_csv_file = dir.file("model.csv");
  o.quiet = true;
  const std::optional<IdentifyOutcome> ran = RunIdentify(o);
  ASSERT_TRUE(ran);
  const IdentifyOutcome& found = *ran;
  EXPECT_EQ(ReadTextFile(input), ReadTextFile(testing::RigExample()));  // Never touched.

  // The example's plant: 6 deg of bend per kPa, 0.4 deg of angle per degree of bend; lag 0.15 s.
  EXPECT_NEAR(found.model.slope_deg_per_kpa, 2.4, 0.24);
  EXPECT_NEAR(found.model.lag_s, 0.15, 0.045);
  EXPECT_NEAR(found.model.bend_start_kpa, 3.0, 1.0);
  // The renderer's end stop (240 deg of bend, angle 84 deg) is a saturation the camera sees.
  EXPECT_NEAR(found.model.saturation_kpa, 3.0 + (240 + 1.5) / 6.0, 1.5);

  const TrackingConfig tuned = LoadTrackingConfig(o.output_file);
  ASSERT_TRUE(tuned.control);
  EXPECT_DOUBLE_EQ(tuned.control->model.slope_deg_per_kpa, found.model.slope_deg_per_kpa);
  EXPECT_DOUBLE_EQ(tuned.control->controller.kp_kpa_per_deg, found.tuned.kp_kpa_per_deg);
  EXPECT_NEAR(tuned.control->controller.ff_kpa_per_deg, 1.0 / found.model.slope_deg_per_kpa,
              1e-12);
  EXPECT_EQ(tuned.markers.size(), 3u);
  EXPECT_EQ(tuned.control->rig.plant.chamber_volume_ml, 20.0);  // The rest is the input's.

  // The run's CSV and the model's, which `softsight plot` draws.
  const std::vector<std::string> rows = ReadLines(o.csv_file);
  EXPECT_EQ(rows.size(), found.samples.size() + 1);
  EXPECT_THAT(rows[0], HasSubstr("identify_phase"));
  const std::vector<std::string> model = ReadLines(o.model_csv_file);
  ASSERT_EQ(model.size(), found.samples.size() + 1);
  EXPECT_EQ(model[0], "time_s,identify_phase,setpoint_kpa,board_pressure_kpa,model_pressure_kpa,"
                      "angle_deg,model_angle_deg");
  const std::string plot = std::string("\"") + testing::SoftsightBinary() + "\" plot " +
                           o.model_csv_file + " -o " + dir.file("model.png") + " > /dev/null";
  EXPECT_EQ(std::system(plot.c_str()), 0);
}

TEST(IdentifyCommand, RefusesToOverwriteTheInputConfig) {
  TempDir dir;
  const std::string input = dir.file("rig.yaml");
  WriteTextFile(input, ReadTextFile(testing::RigExample()));
  IdentifyCommandOptions o;
  o.config_file = input;
  o.simulate = true;
  const std::string up = (dir.path() / ".." / dir.path().filename() / "rig.yaml").string();
  for (const std::string& same : {input, dir.file("./rig.yaml"), up}) {
    o.output_file = same;
    try {
      RunIdentify(o);
      ADD_FAILURE() << same;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("is the config " + input));
    }
  }
  EXPECT_EQ(ReadTextFile(input), ReadTextFile(testing::RigExample()));
  // Through the program: one line, exit code 2.
  const std::string command = std::string("\"") + testing::SoftsightBinary() +
                              "\" identify --config " + input + " --simulate -o " + input +
                              " 2> " + dir.file("err.txt");
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_EQ(ReadLines(dir.file("err.txt")).size(), 1u) << ReadTextFile(dir.file("err.txt"));
}

TEST(IdentifyCommand, MarkersThatAreNeverSeenStopItVentedWithOneErrorAndNoConfig) {
  TempDir dir;
  // Markers of colours the scene does not have: nothing is found.
  WriteTextFile(dir.file("rig.yaml"), R"(markers:
  - name: a
    hsv: {h: [140, 150], s: [250, 255], v: [250, 255]}
  - name: b
    hsv: {h: [150, 160], s: [250, 255], v: [250, 255]}
  - name: c
    hsv: {h: [160, 165], s: [250, 255], v: [250, 255]}
triple: [a, b, c]
)");
  const std::string command = std::string("\"") + testing::SoftsightBinary() +
                              "\" identify --config " + dir.file("rig.yaml") + " --simulate -o " +
                              dir.file("tuned.yaml") + " --csv " + dir.file("ident.csv") +
                              " 2> " + dir.file("err.txt");
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  const std::vector<std::string> err = ReadLines(dir.file("err.txt"));
  int errors = 0;
  for (const std::string& line : err) errors += line.find("error") != std::string::npos;
  EXPECT_EQ(errors, 1) << ReadTextFile(dir.file("err.txt"));
  EXPECT_THAT(ReadTextFile(dir.file("err.txt")), HasSubstr("identify: markers lost for 0.30 s at 0.30 s"));
  EXPECT_FALSE(std::ifstream(dir.file("tuned.yaml")).good());
}

TEST(ControlCommand, AutoTuneIdentifiesThenRunsTheLoopWithTheGainsFound) {
  TempDir dir;
  ControlOptions o;
  o.config_file = testing::RigExample();
  o.simulate = true;
  o.sim_supersample = 1;
  o.target_deg = 120.0;
  o.duration_s = 4.0;
  o.csv_file = dir.file("run.csv");
  o.metrics_csv_file = dir.file("metrics.csv");
  o.quiet = true;
  // What `control --auto-tune` does: the identification (its CSV beside the run's), then the loop.
  ControlOptions identify = o;
  identify.identify = true;
  identify.target_deg.reset();
  identify.duration_s.reset();
  identify.metrics_csv_file.clear();
  identify.csv_file = IdentifyCsvBeside(o.csv_file);
  EXPECT_EQ(identify.csv_file, dir.file("run_identify.csv"));
  const ControlSummary found = RunControl(identify);
  ASSERT_TRUE(found.identified);
  o.controller = found.identified->tuned;
  const ControlSummary run = RunControl(o);
  // The tracked angle: 180 -> 120 deg settles within +-1 deg in under 2 s, overshoot under 5 %.
  ASSERT_TRUE(run.metrics.settling_1deg_s) << FormatStepMetrics(run.metrics);
  EXPECT_LT(*run.metrics.settling_1deg_s, 2.0) << FormatStepMetrics(run.metrics);
  EXPECT_LT(*run.metrics.overshoot_percent, 5.0) << FormatStepMetrics(run.metrics);
  EXPECT_THAT(FormatControlSummary(run), HasSubstr("settling +-1 deg"));
  const std::vector<std::string> metrics = ReadLines(o.metrics_csv_file);
  ASSERT_EQ(metrics.size(), 2u);
  EXPECT_EQ(metrics[0], "step_time_s,step_from_deg,step_to_deg,rise_time_s,settling_1deg_s,"
                        "settling_2deg_s,overshoot_percent,steady_state_error_deg,rms_error_deg");
  EXPECT_EQ(SplitCsv(metrics[1]).size(), 9u);
  EXPECT_GT(ReadLines(identify.csv_file).size(), 300u);
}

// The stiff plant (3 deg of bend per kPa): at the 45 kPa output limit it bends to ~130 deg. Its
// identified model says so, and `control` refuses 120 deg before the board is opened, naming
// the reach and the pressure 120 deg would need; --allow-saturation runs it limited to the reach.
// Without a model the run says the output stayed at its limit.
TEST(ControlCommand, ATargetBeyondTheIdentifiedReachIsRefusedBeforeAnythingIsSent) {
  TempDir dir;
  std::string stiff = ReadTextFile(testing::RigExample());
  const size_t at = stiff.find("bend_deg_per_kpa: 6.0");
  ASSERT_NE(at, std::string::npos);
  stiff.replace(at, std::string("bend_deg_per_kpa: 6.0").size(), "bend_deg_per_kpa: 3.0");
  WriteTextFile(dir.file("stiff.yaml"), stiff);
  IdentifyCommandOptions identify;
  identify.config_file = dir.file("stiff.yaml");
  identify.output_file = dir.file("tuned.yaml");
  identify.simulate = true;
  identify.sim_supersample = 1;
  identify.quiet = true;
  const std::optional<IdentifyOutcome> found = RunIdentify(identify);
  ASSERT_TRUE(found);
  EXPECT_NEAR(found->model.valid_min_deg, 130.0, 2.0);

  ControlOptions o;
  o.config_file = dir.file("tuned.yaml");
  o.simulate = true;
  o.sim_supersample = 1;
  o.target_deg = 120.0;
  o.duration_s = 3.0;
  o.csv_file = dir.file("run.csv");
  o.quiet = true;
  try {
    RunControl(o);
    ADD_FAILURE() << "an unreachable target ran";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--target-deg 120: 120.0 deg is beyond the actuator's reach: "
                                    "it bends to 1"));
    EXPECT_THAT(e.what(), HasSubstr("deg would need about 5"));
    EXPECT_THAT(e.what(), HasSubstr("nothing sent"));
  }
  EXPECT_FALSE(std::filesystem::exists(o.csv_file)) << "the run started";
  // A profile that leaves the reach: the same refusal.
  WriteTextFile(dir.file("p.txt"), "step 150\nhold 1\nsine 140 25 0.5 2\n");
  ControlOptions profiled = o;
  profiled.target_deg.reset();
  profiled.profile_file = dir.file("p.txt");
  EXPECT_THROW(RunControl(profiled), InputError);
  EXPECT_FALSE(std::filesystem::exists(o.csv_file));

  // Run on purpose: the target limited to the reach, said in the summary.
  o.allow_saturation = true;
  const ControlSummary saturated = RunControl(o);
  ASSERT_FALSE(saturated.notes.empty());
  EXPECT_THAT(saturated.notes.front(), HasSubstr("the target was limited to 1"));
  const std::vector<std::string> rows = ReadLines(o.csv_file);
  ASSERT_GT(rows.size(), 10u);
  const std::vector<std::string> header = SplitCsv(rows[0]);
  const size_t target_column =
      std::find(header.begin(), header.end(), "target_deg") - header.begin();
  ASSERT_LT(target_column, header.size());
  EXPECT_NEAR(std::stod(SplitCsv(rows.back())[target_column]), found->model.valid_min_deg, 1e-3);

  // Without a model (the plain stiff config): the run says its output sat at the limit.
  ControlOptions unmodelled = o;
  unmodelled.config_file = dir.file("stiff.yaml");
  unmodelled.allow_saturation = false;
  unmodelled.csv_file = dir.file("plain.csv");
  const ControlSummary plain = RunControl(unmodelled);
  EXPECT_THAT(FormatControlSummary(plain),
              HasSubstr("note: the outer loop's output stayed at its limit (45 kPa) for "));
}

// The profiles people run on soft actuators, after `identify`: a staircase gets each step's
// figures (summary and metrics CSV, a row per step) and a slow sine its tracking error and lag.
TEST(ControlCommand, AStaircaseGetsEveryStepsFiguresAndASineItsTrackingError) {
  TempDir dir;
  IdentifyCommandOptions identify;
  identify.config_file = testing::RigExample();
  identify.output_file = dir.file("tuned.yaml");
  identify.simulate = true;
  identify.sim_supersample = 1;
  identify.quiet = true;
  ASSERT_TRUE(RunIdentify(identify));

  WriteTextFile(dir.file("stairs.txt"), "step 150\nhold 2\nstep 130\nhold 2\nstep 160\nhold 2\n");
  ControlOptions o;
  o.config_file = dir.file("tuned.yaml");
  o.simulate = true;
  o.sim_supersample = 1;
  o.profile_file = dir.file("stairs.txt");
  o.csv_file = dir.file("stairs.csv");
  o.metrics_csv_file = dir.file("stairs_metrics.csv");
  o.quiet = true;
  const ControlSummary stairs = RunControl(o);
  ASSERT_EQ(stairs.steps.size(), 3u) << FormatControlSummary(stairs);
  const double to[] = {150.0, 130.0, 160.0};
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(*stairs.steps[i].step_to_deg, to[i]);
    ASSERT_TRUE(stairs.steps[i].settling_1deg_s) << FormatStepMetrics(stairs.steps[i]);
    EXPECT_LT(*stairs.steps[i].settling_1deg_s, 2.0);
  }
  EXPECT_FALSE(stairs.tracking) << "a staircase has no moving target";
  EXPECT_THAT(FormatControlSummary(stairs), HasSubstr("step 3 of 3: step 13"));
  EXPECT_EQ(ReadLines(o.metrics_csv_file).size(), 4u);

  WriteTextFile(dir.file("sine.txt"), "step 140\nhold 1.5\nsine 140 20 0.5 6\n");
  o.profile_file = dir.file("sine.txt");
  o.csv_file = dir.file("sine.csv");
  o.metrics_csv_file.clear();
  const ControlSummary sine = RunControl(o);
  ASSERT_TRUE(sine.tracking) << FormatControlSummary(sine);
  ASSERT_TRUE(sine.tracking->rms_error_deg && sine.tracking->lag_s);
  // Issue 23's figure: a 0.5 Hz sine of 20 deg followed within 2 deg RMS.
  EXPECT_LE(*sine.tracking->rms_error_deg, 2.0) << FormatControlSummary(sine);
  EXPECT_GE(*sine.tracking->lag_s, 0.0);
  EXPECT_LT(*sine.tracking->lag_s, 0.5);
  EXPECT_LE(*sine.tracking->rms_error_without_lag_deg, *sine.tracking->rms_error_deg);
  EXPECT_THAT(FormatControlSummary(sine), HasSubstr("tracking: RMS error "));
}

// The range of plants a lab meets (issue 23): total bending 3-10 deg/kPa, chamber 10-60 ml,
// bending lag 0.05-0.4 s, hysteresis 1-6 deg, and two behind a 50 ms tube between the valves and
// the chamber. After `identify` (its config runs the model-based loop), a step from straight to
// 140 deg settles within +-1 deg in under 2 s with under 5 % overshoot, and a 0.5 Hz sine of
// 20 deg around 155 deg is followed within 2 deg RMS: issue 23's figures, on every plant but
// one sine, which no controller can follow (PumpLimitedSineRms below). Each case prints its
// row of docs/control.md's table ("PlantSweep row:"; scripts/plant_sweep_table.sh collects them).
struct Plant {
  const char* name;
  double bend_deg_per_kpa, chamber_ml, lag_s, hysteresis_deg;
  double tube_s;
};

// The plant's name is all a test name needs (gtest would print the bytes of the struct,
// pointer included: ctest's list of tests would change with every link).
void PrintTo(const Plant& plant, std::ostream* os) { *os << plant.name; }

// The sine's 20 deg at 0.5 Hz around 155 deg.
constexpr double kSineAmplitudeDeg = 20.0;
constexpr double kSineHz = 0.5;

// The least RMS error with which any controller can follow the sine on `plant`, from the pump
// alone (0 when the pump does not forbid 2 deg). The pressure rises at most at the pump's free
// rate p_atm Q / V (less towards its stall pressure; venting is taken as instant), so over a
// period its first harmonic is at most 2 Q p_atm / (V w) (a sawtooth rising at that rate); the
// play and the static map's flat part never make the bend move faster than the pressure, and
// the bending lag divides the harmonic by |1 + i w lag|. The angle's harmonic at the sine's
// frequency is then at most A = 0.5 * span * bend/kPa * that, and the error's own harmonic at
// that frequency alone is (20 - A) / sqrt(2) RMS when A < 20.
double PumpLimitedSineRms(const Plant& plant) {
  const PlantOptions pump;  // The example rig's pump and vent (not changed by the sweep).
  const double w = 2.0 * std::numbers::pi * kSineHz;
  const double rise_kpa_per_s =
      101.325 * pump.pump_flow_l_per_min / 60.0 / (plant.chamber_ml * 1e-3);
  const double angle_per_kpa = 0.5 * RigOptions{}.end_marker_span * plant.bend_deg_per_kpa;
  const double harmonic_deg = 2.0 * angle_per_kpa * rise_kpa_per_s /
                              (w * std::sqrt(1.0 + (w * plant.lag_s) * (w * plant.lag_s)));
  return std::max(0.0, (kSineAmplitudeDeg - harmonic_deg) / std::sqrt(2.0));
}

class PlantSweep : public ::testing::TestWithParam<Plant> {};

TEST_P(PlantSweep, AfterIdentifyAStepSettlesQuicklyAndASineIsFollowed) {
  const Plant& plant = GetParam();
  TempDir dir;
  std::string text = ReadTextFile(testing::RigExample());
  const auto set = [&text](const std::string& key, const std::string& from, double value) {
    const size_t at = text.find(key + ": " + from);
    ASSERT_NE(at, std::string::npos) << key;
    text.replace(at, key.size() + 2 + from.size(), key + ": " + ShortNumber(value));
  };
  set("bend_deg_per_kpa", "6.0", plant.bend_deg_per_kpa);
  set("chamber_volume_ml", "20", plant.chamber_ml);
  set("bend_lag_s", "0.15", plant.lag_s);
  set("hysteresis_deg", "3.0", plant.hysteresis_deg);
  set("tube_delay_s", "0.0", plant.tube_s);
  WriteTextFile(dir.file("plant.yaml"), text);
  IdentifyCommandOptions identify;
  identify.config_file = dir.file("plant.yaml");
  identify.output_file = dir.file("tuned.yaml");
  identify.simulate = true;
  identify.quiet = true;
  const std::optional<IdentifyOutcome> found = RunIdentify(identify);
  ASSERT_TRUE(found);
  // Behind a tube the board gets gains for it (written to the config, sent by `control`).
  EXPECT_EQ(found->inner_loop.given(), plant.tube_s > 0.0);
  EXPECT_EQ(LoadTrackingConfig(identify.output_file).control->inner_loop.given(),
            plant.tube_s > 0.0);

  ControlOptions o;
  o.config_file = dir.file("tuned.yaml");
  o.simulate = true;
  o.target_deg = 140.0;
  o.duration_s = 5.0;
  o.csv_file = dir.file("run.csv");
  o.quiet = true;
  const ControlSummary run = RunControl(o);
  ASSERT_TRUE(run.metrics.settling_1deg_s) << FormatStepMetrics(run.metrics);

  WriteTextFile(dir.file("sine.txt"), "step 155\nhold 2\nsine 155 20 0.5 6\n");
  ControlOptions sine = o;
  sine.target_deg.reset();
  sine.duration_s.reset();
  sine.profile_file = dir.file("sine.txt");
  sine.csv_file = dir.file("sine.csv");
  const double impossible_below_deg = PumpLimitedSineRms(plant);
  if (impossible_below_deg > 2.0) {
    // A sine the pump cannot follow is refused before the run, naming what it can do; the
    // identified model knows the pump's rate and the lag.
    try {
      RunControl(sine);
      ADD_FAILURE() << "a sine no controller can follow was run";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr("is faster than the actuator"));
      EXPECT_THAT(e.what(), ::testing::HasSubstr("nothing sent"));
    }
    EXPECT_FALSE(std::filesystem::exists(sine.csv_file)) << "a refused run wrote its CSV";
    sine.allow_saturation = true;  // Run as given, to see how far it falls behind.
  }
  const ControlSummary followed = RunControl(sine);
  ASSERT_TRUE(followed.tracking && followed.tracking->rms_error_deg)
      << FormatControlSummary(followed);

  std::printf("PlantSweep row: | %s (%s, %s, %s, %s%s) | %.2f s | %.1f %% | %.2f deg |\n",
              plant.name, ShortNumber(plant.bend_deg_per_kpa).c_str(),
              ShortNumber(plant.chamber_ml).c_str(), ShortNumber(plant.lag_s).c_str(),
              ShortNumber(plant.hysteresis_deg).c_str(),
              plant.tube_s > 0.0 ? (", tube " + ShortNumber(plant.tube_s) + " s").c_str() : "",
              *run.metrics.settling_1deg_s, *run.metrics.overshoot_percent,
              *followed.tracking->rms_error_deg);
  EXPECT_LT(*run.metrics.settling_1deg_s, 2.0) << FormatStepMetrics(run.metrics);
  EXPECT_LT(*run.metrics.overshoot_percent, 5.0) << FormatStepMetrics(run.metrics);
  if (impossible_below_deg <= 2.0) {
    EXPECT_LE(*followed.tracking->rms_error_deg, 2.0) << FormatControlSummary(followed);
  } else {
    // The pump cannot move this plant 20 deg at 0.5 Hz (the stiff, big, laggy corner: 4.7 deg
    // RMS at least): the figure cannot be met. The loop must not do worse than that bound
    // allows by more than it does now (18.3 deg: it follows the sine late, see
    // docs/control.md "What the plants reach"); held here at 4.2 times the bound.
    EXPECT_GT(*followed.tracking->rms_error_deg, impossible_below_deg);
    EXPECT_LE(*followed.tracking->rms_error_deg, 4.2 * impossible_below_deg)
        << FormatControlSummary(followed);
  }
}

INSTANTIATE_TEST_SUITE_P(
    TenPlants, PlantSweep,
    ::testing::Values(Plant{"example", 6, 20, 0.15, 3, 0.0}, Plant{"stiff", 3, 20, 0.15, 3, 0.0},
                      Plant{"soft", 10, 20, 0.15, 3, 0.0}, Plant{"quick", 6, 10, 0.05, 1, 0.0},
                      Plant{"big", 6, 60, 0.15, 3, 0.0}, Plant{"laggy", 6, 20, 0.40, 6, 0.0},
                      Plant{"stiff_big_laggy", 3, 60, 0.40, 6, 0.0},
                      Plant{"soft_small_quick", 10, 10, 0.05, 1, 0.0},
                      Plant{"example_tube", 6, 20, 0.15, 3, 0.05},
                      Plant{"laggy_tube", 6, 20, 0.40, 6, 0.05}),
    [](const ::testing::TestParamInfo<Plant>& info) { return std::string(info.param.name); });

TEST(IdentifyCommand, CtrlCDuringTheExperimentVentsWritesNothingAndExits130) {
  TempDir dir;
  WriteTextFile(dir.file("rig.yaml"), ReadTextFile(testing::RigExample()));
  const std::string csv = dir.file("ident.csv");
  const int status = testing::RunAndSignalOnceRowsAreWritten(
      "identify --config " + dir.file("rig.yaml") + " --simulate -o " + dir.file("tuned.yaml") +
          " --csv " + csv,
      csv, 4, SIGINT, dir.file("err.txt"));
  const std::string err = ReadTextFile(dir.file("err.txt"));
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping cleanly: " << err;
  EXPECT_EQ(WEXITSTATUS(status), 130) << "128 + SIGINT, not the error path: " << err;
  EXPECT_THAT(err, HasSubstr("identify: stopped by Ctrl-C (SIGINT) during the experiment at "));
  EXPECT_THAT(err, HasSubstr("; vented, nothing written"));
  EXPECT_THAT(err, Not(HasSubstr("error"))) << "an interrupted experiment is not a failure";
  EXPECT_FALSE(std::ifstream(dir.file("tuned.yaml")).good());
  // Every row written before the signal is whole.
  const std::vector<std::string> rows = ReadLines(csv);
  ASSERT_GE(rows.size(), 4u);
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_EQ(SplitCsv(rows[i]).size(), SplitCsv(rows[0]).size()) << "row " << i;
  }
}

TEST(ControlCommand, AutoTuneStoppedBySigtermDuringTheIdentificationExits143WithoutTheLoop) {
  TempDir dir;
  const std::string identify_csv = dir.file("run_identify.csv");
  const int status = testing::RunAndSignalOnceRowsAreWritten(
      "control --config " + testing::RigExample() + " --simulate --auto-tune --target-deg 120 --csv " +
          dir.file("run.csv"),
      identify_csv, 4, SIGTERM, dir.file("err.txt"));
  const std::string err = ReadTextFile(dir.file("err.txt"));
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping cleanly: " << err;
  EXPECT_EQ(WEXITSTATUS(status), 143) << "128 + SIGTERM, not the error path: " << err;
  EXPECT_THAT(err, HasSubstr("control --auto-tune: stopped by SIGTERM during the identification "
                             "at "));
  EXPECT_THAT(err, HasSubstr("; vented, the loop not started"));
  EXPECT_THAT(err, Not(HasSubstr("error")));
  EXPECT_GE(ReadLines(identify_csv).size(), 4u);
  EXPECT_FALSE(std::ifstream(dir.file("run.csv")).good()) << "the closed loop never started";
}

}  // namespace
}  // namespace softsight
