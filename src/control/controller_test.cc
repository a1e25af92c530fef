#include "softsight/control/controller.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "softsight/control/actuator_model.h"
#include "softsight/control/profile.h"
#include "core/test_util.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

ControllerOptions POnly(double kp) {
  ControllerOptions o;
  o.kp_kpa_per_deg = kp;
  o.ki_kpa_per_deg_s = 0.0;
  o.bias_kpa = 0.0;
  o.max_rate_kpa_per_s = 0.0;
  return o;
}

TEST(AngleController, ProportionalLawWithThePapersSign) {
  AngleController c(POnly(0.5));
  // Target 120, measured 150: must bend 30 degrees more -> 15 kPa.
  ControllerOutput out = c.update(0.0, 120.0, 150.0);
  EXPECT_EQ(out.action, ControllerOutput::Action::kTrack);
  EXPECT_DOUBLE_EQ(*out.error_deg, 30.0);
  EXPECT_DOUBLE_EQ(out.setpoint_kpa, 15.0);
  // Bent too far: the setpoint drops, clamped at min_kpa.
  EXPECT_DOUBLE_EQ(c.update(0.1, 120.0, 100.0).setpoint_kpa, 0.0);
}

TEST(AngleController, OutputAndRateLimits) {
  ControllerOptions o = POnly(10.0);
  o.max_kpa = 40.0;
  o.max_rate_kpa_per_s = 50.0;
  AngleController c(o);
  EXPECT_DOUBLE_EQ(c.update(0.0, 120.0, 180.0).setpoint_kpa, 0.0);  // First frame: no dt yet.
  EXPECT_NEAR(c.update(0.1, 120.0, 180.0).setpoint_kpa, 5.0, 1e-9);  // 50 kPa/s * 0.1 s.
  double sp = 0.0;
  for (int k = 2; k < 20; ++k) sp = c.update(0.1 * k, 120.0, 180.0).setpoint_kpa;
  EXPECT_DOUBLE_EQ(sp, 40.0);
}

TEST(AngleController, IntegralDoesNotWindUpAgainstTheOutputLimit) {
  ControllerOptions o = POnly(0.1);
  o.ki_kpa_per_deg_s = 2.0;
  o.max_kpa = 20.0;
  AngleController c(o);
  // The actuator cannot reach the target (stuck at 170): the output saturates at 20 kPa.
  for (int k = 0; k < 300; ++k) c.update(0.033 * k, 100.0, 170.0);
  EXPECT_LE(c.integral_kpa(), 20.0);
  // Once the target is reached and passed, the setpoint leaves the limit within a few frames
  // (a wound-up integral would keep it there for seconds).
  double sp = 20.0;
  int frames = 0;
  for (int k = 300; k < 400 && sp >= 20.0 - 1e-9; ++k, ++frames) {
    sp = c.update(0.033 * k, 100.0, 95.0).setpoint_kpa;
  }
  EXPECT_LT(frames, 5);
}

TEST(AngleController, RemovesSteadyStateErrorWithIntegral) {
  ControllerOptions o = POnly(0.2);
  o.ki_kpa_per_deg_s = 1.0;
  AngleController c(o);
  // Static plant: angle = 180 - 2.4 * (p - 3).
  double p = 0.0;
  double angle = 180.0;
  for (int k = 0; k < 600; ++k) {
    p = c.update(k / 30.0, 120.0, angle).setpoint_kpa;
    angle = 180.0 - 2.4 * std::max(0.0, p - 3.0);
  }
  EXPECT_NEAR(angle, 120.0, 0.05);
}

TEST(AngleController, HoldsThenVentsOnVisionLoss) {
  ControllerOptions o = POnly(0.5);
  o.ki_kpa_per_deg_s = 1.0;
  o.hold_s = 0.5;
  AngleController c(o);
  ControllerOutput out;
  for (int k = 0; k < 30; ++k) out = c.update(k / 30.0, 120.0, 140.0);
  const double held = out.setpoint_kpa;
  const double integral = c.integral_kpa();
  for (int k = 30; k <= 45; ++k) {  // 0.5 s without a measurement.
    out = c.update(k / 30.0, 100.0, std::nullopt);
    EXPECT_EQ(out.action, ControllerOutput::Action::kHold);
    EXPECT_DOUBLE_EQ(out.setpoint_kpa, held);
  }
  EXPECT_DOUBLE_EQ(c.integral_kpa(), integral);  // Frozen.
  out = c.update(46 / 30.0, 100.0, std::nullopt);
  EXPECT_EQ(out.action, ControllerOutput::Action::kVent);
  EXPECT_DOUBLE_EQ(out.setpoint_kpa, 0.0);
  EXPECT_DOUBLE_EQ(c.integral_kpa(), 0.0);
  // Never measured at all: no inflation.
  AngleController fresh(o);
  EXPECT_EQ(fresh.update(0.0, 120.0, std::nullopt).action, ControllerOutput::Action::kVent);
}

// The model-based loop runs only with model_inverse and an identified model; otherwise the
// controller is the PI, frame for frame.
TEST(AngleController, TheModelBasedLoopNeedsTheOptionAndAModel) {
  ActuatorModel model;
  model.straight_deg = 180.0;
  model.bend_start_kpa = 3.0;
  model.slope_deg_per_kpa = 2.4;
  model.lag_s = 0.15;
  model.inflate_kpa_per_s = 80.0;
  model.vent_kpa_per_s = 150.0;
  model.vent_at_kpa = 10.0;
  model.pressure_duty_per_kpa = 0.25;
  ControllerOptions pi;
  ControllerOptions flagged = pi;
  flagged.model_inverse = true;
  AngleController plain(pi), unmodelled(flagged), off(pi), on(flagged);
  off.set_model(model);
  unmodelled.set_model(ActuatorModel{});  // Not identified.
  on.set_model(model);
  EXPECT_FALSE(off.model_based());
  EXPECT_FALSE(unmodelled.model_based());
  EXPECT_TRUE(on.model_based());
  for (int k = 0; k < 30; ++k) {
    const double t = k / 30.0, measured = 180.0 - k;
    const double expected = plain.update(t, 150.0, measured).setpoint_kpa;
    EXPECT_DOUBLE_EQ(off.update(t, 150.0, measured).setpoint_kpa, expected) << k;
    EXPECT_DOUBLE_EQ(unmodelled.update(t, 150.0, measured).setpoint_kpa, expected) << k;
  }
  // A step from straight: the model-based loop asks for full duty at once, a setpoint at least
  // 1/g (the error at which the board's duty saturates) above the vented chamber, but no more
  // than 1/g above what the pump gives in that frame (so it can come back in one), where the
  // PI's slew limit holds its first setpoint at 0.
  const ControllerOutput first = on.update(0.0, 150.0, 180.0);
  EXPECT_EQ(AngleController(pi).update(0.0, 150.0, 180.0).setpoint_kpa, 0.0);
  EXPECT_GE(first.setpoint_kpa, 1.0 / model.pressure_duty_per_kpa);
  EXPECT_LE(first.setpoint_kpa, model.inflate_kpa_per_s / 30.0 + 1.0 / model.pressure_duty_per_kpa);
}

TEST(AngleController, CheckNamesTheBadField) {
  ControllerOptions o;
  std::string error;
  EXPECT_TRUE(o.Check(&error));
  o.max_kpa = -1.0;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("max_kpa"), std::string::npos);
  o = ControllerOptions{};
  o.kp_kpa_per_deg = -0.1;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("kp_kpa_per_deg"), std::string::npos);
}

TEST(TargetProfile, StepsRampsAndSines) {
  const TargetProfile p = TargetProfile::Parse(
      "# a test\nstart 170\nhold 1   # stay\nstep 120\nhold 1\nramp 150 2\nsine 150 10 0.5 2\n",
      "p.txt");
  EXPECT_DOUBLE_EQ(p.at(0.0), 170.0);
  EXPECT_DOUBLE_EQ(p.at(0.99), 170.0);
  EXPECT_DOUBLE_EQ(p.at(1.0), 120.0);
  EXPECT_DOUBLE_EQ(p.at(1.5), 120.0);
  EXPECT_DOUBLE_EQ(p.at(3.0), 135.0);  // Half-way up the ramp.
  EXPECT_DOUBLE_EQ(p.at(4.0), 150.0);
  EXPECT_NEAR(p.at(4.5), 160.0, 1e-9);  // Quarter period of 0.5 Hz.
  EXPECT_NEAR(p.at(5.5), 140.0, 1e-9);
  EXPECT_DOUBLE_EQ(p.duration_s(), 6.0);
  EXPECT_NEAR(p.at(100.0), 150.0, 1e-9);  // Holds the final value.
  EXPECT_DOUBLE_EQ(TargetProfile::Constant(120.0).at(5.0), 120.0);
  EXPECT_DOUBLE_EQ(TargetProfile::Parse("step 100\n", "x").at(3.0), 100.0);
}

// The message of the InputError that parsing `text` as prof.txt throws, or "no error".
std::string ProfileError(const std::string& text) {
  try {
    TargetProfile::Parse(text, "prof.txt");
  } catch (const InputError& e) {
    return std::string(e.what());
  }
  return std::string("no error");
}

TEST(TargetProfile, ErrorsNameFileLineAndProblem) {
  const auto error_of = ProfileError;
  EXPECT_EQ(error_of("hold 1\nstep 200\n"),
            "prof.txt:2: step: angle 200.000000 deg is outside 0..180 (the angle at the middle "
            "marker)");
  EXPECT_NE(error_of("ramp 120\n").find("prof.txt:1: ramp: expected 'ramp ANGLE_DEG SECONDS'"),
            std::string::npos);
  EXPECT_NE(error_of("hold x\n").find("prof.txt:1: hold: 'x' is not a number"), std::string::npos);
  EXPECT_NE(error_of("jump 3\n").find("unknown segment 'jump'"), std::string::npos);
  EXPECT_NE(error_of("sine 170 20 1 1\n").find("outside 0..180"), std::string::npos);
  EXPECT_NE(error_of("# nothing\n").find("no segments"), std::string::npos);
  EXPECT_NE(error_of("hold -1\n").find("must be > 0"), std::string::npos);
}


// Every loop and allocation driven by the profile's values is bounded: a profile is a short text.
TEST(TargetProfile, BoundsOnLengthSegmentsFrequencyAndSize) {
  const auto error_of = ProfileError;
  EXPECT_THAT(error_of("hold 1e18\n"), ::testing::HasSubstr("prof.txt:1: hold: the profile would "
                                                            "last 1e+18 s, longer than a week"));
  // A week in total, however it is split.
  EXPECT_THAT(error_of("hold 400000\nramp 100 400000\n"),
              ::testing::HasSubstr("prof.txt:2: ramp: the profile would last"));
  EXPECT_EQ(error_of("hold 600000\n"), "no error");
  EXPECT_THAT(error_of("sine 90 20 1000 1\n"),
              ::testing::HasSubstr("prof.txt:1: sine: frequency 1000 Hz must be in (0, 100]"));
  EXPECT_THAT(error_of("sine 90 20 0 1\n"), ::testing::HasSubstr("frequency 0 Hz"));
  std::string many;
  for (size_t i = 0; i <= TargetProfile::kMaxSegments; ++i) many += "hold 1\n";
  EXPECT_THAT(error_of(many), ::testing::HasSubstr("more than 10000 segments"));

  testing::TempDir dir;
  std::string big(TargetProfile::kMaxBytes + 10, '#');
  testing::WriteTextFile(dir.file("big.txt"), big);
  EXPECT_THROW(
      {
        try {
          TargetProfile::Load(dir.file("big.txt"));
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), ::testing::HasSubstr("big.txt: larger than 1 MiB"));
          throw;
        }
      },
      InputError);
  try {
    TargetProfile::Load("/dev/zero");  // Endless: read only up to the bound.
    ADD_FAILURE() << "/dev/zero accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("/dev/zero: larger than 1 MiB"));
  }
  testing::WriteTextFile(dir.file("nul.txt"), std::string("step 120\n\0step 90\n", 18));
  try {
    TargetProfile::Load(dir.file("nul.txt"));
    ADD_FAILURE() << "a NUL byte accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("not a text file"));
  }
}


TEST(TargetProfile, LowestAndHighestIncludeASinesSwingAndClampingLimitsThem) {
  const TargetProfile p = TargetProfile::Parse("step 150\nhold 1\nsine 140 25 0.5 4\nramp 170 1\n",
                                               "x");
  EXPECT_DOUBLE_EQ(p.lowest_deg(), 115.0);
  EXPECT_DOUBLE_EQ(p.highest_deg(), 170.0);
  const TargetProfile clamped = p.ClampedTo(130.0, 160.0);
  EXPECT_DOUBLE_EQ(clamped.lowest_deg(), 130.0);
  EXPECT_DOUBLE_EQ(clamped.highest_deg(), 160.0);
  for (double t = 0.0; t < 7.0; t += 0.01) {
    EXPECT_DOUBLE_EQ(clamped.at(t), std::clamp(p.at(t), 130.0, 160.0)) << t;
  }
  EXPECT_DOUBLE_EQ(TargetProfile::Constant(120.0).lowest_deg(), 120.0);
}

// The stiff plant of issue 23 as `softsight identify` measured it: 1.2 deg/kPa at the middle
// marker from 3 kPa, bent to 130.25 deg at the 45 kPa output limit.
ActuatorModel StiffPlant() {
  ActuatorModel m;
  m.straight_deg = 180.0;
  m.bend_start_kpa = 3.0;
  m.slope_deg_per_kpa = 1.2;
  m.static_rms_deg = 0.06;
  m.valid_max_kpa = 44.95;
  m.valid_min_deg = 130.25;
  m.valid_max_deg = 180.0;
  return m;
}

// Speed is part of reach: the pump raises the pressure at most inflate_kpa_per_s, the vent lowers
// it at most vent_kpa_per_s. With 1.2 deg/kPa, a 10 kPa/s pump and a 0.4 s bending lag, a sine
// at 0.5 Hz swings at most 2 * 1.2 * 10 / (pi * sqrt(1 + (0.4 pi)^2)) = 4.757 deg; ramps bend at
// most 12 deg/s and straighten at most 1.2 * 20 = 24 deg/s. Only 20 % past the bound is refused.
TEST(ActuatorReach, ARampOrSineFasterThanThePumpIsNamedWithWhatTheActuatorCanDo) {
  ActuatorModel m = StiffPlant();
  m.inflate_kpa_per_s = 10.0;
  m.vent_kpa_per_s = 20.0;
  m.lag_s = 0.4;
  const double w = std::numbers::pi;
  const double bound = 2.0 * 1.2 * 10.0 / (w * std::sqrt(1.0 + 0.16 * w * w));
  EXPECT_NEAR(MaxSineAmplitudeDeg(m, 0.5), bound, 1e-12);
  EXPECT_NEAR(bound, 4.757, 0.001);
  const auto profile = [](const std::string& text) { return TargetProfile::Parse(text, "test"); };
  EXPECT_FALSE(OutsideRateReach(m, profile("step 160\nsine 160 5.7 0.5 4\n")));  // 1.19x.
  EXPECT_EQ(OutsideRateReach(m, profile("step 160\nhold 1\nsine 160 20 0.5 4\n")),
            std::optional<std::string>(
                "the sine at 1.0 s (20.0 deg at 0.5 Hz) is faster than the actuator: the pump "
                "raises the pressure at most 10.0 kPa/s, so at 0.5 Hz it swings at most 4.8 deg, "
                "and 20.0 deg only up to 0.17 Hz (control.model)"));
  // At the frequency named, the swing is what the bound allows (w^2 (1 + 0.16 w^2) = 1.44).
  EXPECT_NEAR(MaxSineAmplitudeDeg(m, 0.17485), 20.0, 0.01);
  // Ramps: bending at 15 deg/s (over 1.2 x 12) is refused, straightening at 28 deg/s is not.
  EXPECT_THAT(OutsideRateReach(m, profile("ramp 165 1\n")).value_or(""),
              ::testing::HasSubstr("the ramp at 0.0 s (180.0 to 165.0 deg at 15.0 deg/s) is faster "
                                   "than the actuator: the pump raises the pressure at most 10.0 "
                                   "kPa/s, 12.0 deg/s"));
  EXPECT_FALSE(OutsideRateReach(m, profile("step 140\nramp 168 1\n")));
  EXPECT_TRUE(OutsideRateReach(m, profile("step 140\nramp 170 1\n")));
  // Steps take the time they take; a model without the rates reaches everything.
  EXPECT_FALSE(OutsideRateReach(m, profile("step 135\nstep 178\n")));
  ActuatorModel no_rates = m;
  no_rates.inflate_kpa_per_s = 0.0;
  EXPECT_FALSE(OutsideRateReach(no_rates, profile("sine 160 20 5 4\n")));
}

TEST(ActuatorReach, ATargetBeyondTheIdentifiedRangeIsNamedWithThePressureItNeeds) {
  const ActuatorModel m = StiffPlant();
  EXPECT_DOUBLE_EQ(PressureForAngle(m, 180.0), 3.0);
  EXPECT_DOUBLE_EQ(PressureForAngle(m, 120.0), 53.0);
  EXPECT_EQ(OutsideReach(m, 120.0, 180.0, 45.0),
            std::optional<std::string>(
                "120.0 deg is beyond the actuator's reach: it bends to 130.2..180.0 deg up to 45.0 "
                "kPa (control.model, from `softsight identify`); 120.0 deg would need about 53.0 "
                "kPa"));
  // Within the range, and within the tolerance (0.5 deg) at its edges: reachable.
  EXPECT_FALSE(OutsideReach(m, 131.0, 180.0, 45.0));
  EXPECT_FALSE(OutsideReach(m, 129.8, 180.0, 45.0));
  EXPECT_TRUE(OutsideReach(m, 129.7, 180.0, 45.0));
  // A lower output limit than the identification had: less reach (180 - 1.2 * (30 - 3)).
  const ActuatorReach lower = ReachOf(m, 30.0);
  EXPECT_DOUBLE_EQ(lower.most_bent_deg, 180.0 - 1.2 * 27.0);
  EXPECT_DOUBLE_EQ(lower.up_to_kpa, 30.0);
  EXPECT_TRUE(OutsideReach(m, 140.0, 180.0, 30.0));
  // Straighter than vented.
  ActuatorModel bent_at_rest = m;
  bent_at_rest.valid_max_deg = bent_at_rest.straight_deg = 175.0;
  EXPECT_THAT(OutsideReach(bent_at_rest, 150.0, 180.0, 45.0).value_or(""),
              ::testing::HasSubstr("180.0 deg is straighter than the actuator gets when vented "
                                   "(175.0 deg"));
  // Past the end stop no pressure helps.
  ActuatorModel stops = m;
  stops.saturation_kpa = 40.0;
  EXPECT_THAT(OutsideReach(stops, 120.0, 180.0, 45.0).value_or(""),
              ::testing::HasSubstr("it stops bending from 40.0 kPa, so no pressure gives 120.0 deg"));
  // No model: everything is reachable as far as the host knows.
  EXPECT_FALSE(OutsideReach(ActuatorModel{}, 0.0, 180.0, 45.0));
}

}  // namespace
}  // namespace softsight
