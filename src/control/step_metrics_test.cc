// The step-response figures on signals whose figures are known in closed form.
#include "control/step_metrics.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace softsight {
namespace {

constexpr double kDt = 0.001;  // Fine sampling: interpolation errors far below the tolerances.

// A step from 180 to 120 deg at t = 0 followed by `response(t)` (the angle).
template <typename F>
std::vector<TrackingPoint> StepRun(double seconds, F response) {
  std::vector<TrackingPoint> points;
  for (int k = 0; k * kDt <= seconds + 1e-12; ++k) {
    const double t = k * kDt;
    points.push_back({t, 120.0, response(t)});
  }
  return points;
}

TEST(StepMetrics, FirstOrderResponse) {
  const double tau = 0.3;
  const auto run = StepRun(4.0, [&](double t) { return 120.0 + 60.0 * std::exp(-t / tau); });
  const StepMetrics m = ComputeStepMetrics(run);
  ASSERT_TRUE(m.rise_time_s && m.settling_1deg_s && m.settling_2deg_s && m.overshoot_percent);
  EXPECT_NEAR(*m.rise_time_s, tau * std::log(9.0), 1e-3);     // 10 % -> 90 %.
  EXPECT_NEAR(*m.settling_1deg_s, tau * std::log(60.0), 2e-3);  // 60 e^-t/tau = 1.
  EXPECT_NEAR(*m.settling_2deg_s, tau * std::log(30.0), 2e-3);
  EXPECT_DOUBLE_EQ(*m.overshoot_percent, 0.0);
  ASSERT_TRUE(m.steady_state_error_deg);
  EXPECT_NEAR(*m.steady_state_error_deg, 0.0, 1e-3);  // 60 e^(-t/tau) over the last 0.5 s.
  EXPECT_DOUBLE_EQ(*m.step_from_deg, 180.0);
  EXPECT_DOUBLE_EQ(*m.step_to_deg, 120.0);
}

TEST(StepMetrics, UnderdampedSecondOrderOvershoot) {
  // y = 1 - e^(-zeta wn t) (cos(wd t) + zeta/sqrt(1-zeta^2) sin(wd t)): peak overshoot
  // exp(-zeta pi / sqrt(1 - zeta^2)).
  const double zeta = 0.5, wn = 8.0, wd = wn * std::sqrt(1 - zeta * zeta);
  const auto run = StepRun(5.0, [&](double t) {
    const double y = 1.0 - std::exp(-zeta * wn * t) *
                               (std::cos(wd * t) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(wd * t));
    return 180.0 - 60.0 * y;
  });
  const StepMetrics m = ComputeStepMetrics(run);
  ASSERT_TRUE(m.overshoot_percent);
  EXPECT_NEAR(*m.overshoot_percent, 100.0 * std::exp(-zeta * std::numbers::pi / std::sqrt(1 - zeta * zeta)), 0.01);
  ASSERT_TRUE(m.settling_1deg_s);
  // The envelope 60 e^(-zeta wn t) / sqrt(1 - zeta^2) bounds the error: settled before it is 1.
  EXPECT_LT(*m.settling_1deg_s, std::log(60.0 / std::sqrt(1 - zeta * zeta)) / (zeta * wn));
  EXPECT_GT(*m.settling_1deg_s, 0.5);
}

TEST(StepMetrics, SteadyStateErrorAndNotSettled) {
  // Converges to 121.5: settled within 2 deg, never within 1; steady-state error +1.5.
  const auto run = StepRun(3.0, [](double t) { return 121.5 + 58.5 * std::exp(-t / 0.2); });
  const StepMetrics m = ComputeStepMetrics(run);
  EXPECT_FALSE(m.settling_1deg_s);
  ASSERT_TRUE(m.settling_2deg_s);
  EXPECT_NEAR(*m.settling_2deg_s, 0.2 * std::log(58.5 / 0.5), 2e-3);
  ASSERT_TRUE(m.steady_state_error_deg);
  EXPECT_NEAR(*m.steady_state_error_deg, 1.5, 1e-4);
  EXPECT_NE(FormatStepMetrics(m).find("settling +-1 deg not settled"), std::string::npos)
      << FormatStepMetrics(m);
}

TEST(StepMetrics, TheLastStepOfAProfileCountsAndRmsCoversTheWholeRun) {
  // Hold 150 for 1 s (measured exactly), then a step to 130 answered by a pure 0.1 s delay.
  std::vector<TrackingPoint> points;
  for (int k = 0; k <= 3000; ++k) {
    const double t = k * kDt;
    const double target = t < 1.0 ? 150.0 : 130.0;
    const double measured = t < 1.1 ? 150.0 : 130.0;
    points.push_back({t, target, measured});
  }
  const StepMetrics m = ComputeStepMetrics(points);
  ASSERT_TRUE(m.step_time_s && m.settling_1deg_s && m.rise_time_s && m.rms_error_deg);
  EXPECT_NEAR(*m.step_time_s, 1.0, 1e-9);
  EXPECT_NEAR(*m.settling_1deg_s, 0.1, 1.5e-3);
  EXPECT_NEAR(*m.rise_time_s, 0.0, 1.5e-3);  // A jump: 10 % and 90 % in the same frame.
  // 20 deg of error for 0.1 s out of 3 s.
  EXPECT_NEAR(*m.rms_error_deg, std::sqrt(400.0 * 0.1 / 3.0), 0.05);
}

TEST(StepMetrics, ASineHasAnRmsErrorButNoStepFigures) {
  // Following a sine with a constant lag: RMS of the difference of two sines.
  const double a = 20.0, f = 0.25, lag = 0.1;
  std::vector<TrackingPoint> points;
  for (int k = 0; k <= 8000; ++k) {
    const double t = k * kDt;
    points.push_back({t, 140.0 + a * std::sin(2 * std::numbers::pi * f * t),
                      140.0 + a * std::sin(2 * std::numbers::pi * f * (t - lag))});
  }
  const StepMetrics m = ComputeStepMetrics(points);
  ASSERT_TRUE(m.rms_error_deg);
  // |a e^{iwt} - a e^{iw(t - lag)}| = 2 a sin(w lag / 2); RMS is that over sqrt(2).
  EXPECT_NEAR(*m.rms_error_deg, 2 * a * std::sin(std::numbers::pi * f * lag) / std::sqrt(2.0), 0.01);
  EXPECT_FALSE(m.rise_time_s);
  EXPECT_FALSE(m.settling_1deg_s);
  EXPECT_FALSE(m.overshoot_percent);
}

TEST(StepMetrics, MissingMeasurementsAreSkippedAndNoneGivesNothing) {
  auto run = StepRun(2.0, [](double t) { return 120.0 + 60.0 * std::exp(-t / 0.1); });
  for (size_t k = 100; k < 200; ++k) run[k].measured_deg.reset();
  const StepMetrics m = ComputeStepMetrics(run);
  ASSERT_TRUE(m.settling_1deg_s);
  EXPECT_NEAR(*m.settling_1deg_s, 0.1 * std::log(60.0), 2e-3);
  for (auto& p : run) p.measured_deg.reset();
  const StepMetrics none = ComputeStepMetrics(run);
  EXPECT_FALSE(none.rms_error_deg);
  EXPECT_FALSE(none.settling_1deg_s);
  const std::string csv = StepMetricsCsv({none});
  EXPECT_EQ(csv.substr(csv.find('\n') + 1), ",,,,,,,,\n");
}


// A staircase 180 -> 150 -> 130 -> 160, two seconds a step, each followed by a first-order
// response (tau 0.2 s) from where the last one ended: each step gets its own closed-form figures.
TEST(StepMetrics, EveryStepOfAStaircaseGetsItsOwnFigures) {
  const double tau = 0.2;
  const double targets[] = {150.0, 130.0, 160.0};
  std::vector<TrackingPoint> points;
  double from = 180.0;
  for (int step = 0; step < 3; ++step) {
    for (int k = 0; k < 2000; ++k) {
      const double u = k * kDt;
      points.push_back({step * 2.0 + u, targets[step],
                        targets[step] + (from - targets[step]) * std::exp(-u / tau)});
    }
    from = points.back().measured_deg.value();
  }
  const std::vector<StepMetrics> steps = ComputeEveryStepMetrics(points);
  ASSERT_EQ(steps.size(), 3u);
  for (int step = 0; step < 3; ++step) {
    SCOPED_TRACE(step);
    const StepMetrics& m = steps[step];
    EXPECT_DOUBLE_EQ(*m.step_to_deg, targets[step]);
    EXPECT_NEAR(*m.step_time_s, step * 2.0, kDt);
    const double size = std::abs(*m.step_from_deg - targets[step]);
    EXPECT_NEAR(size, step == 0 ? 30.0 : step == 1 ? 20.0 : 30.0, 0.01);
    ASSERT_TRUE(m.settling_1deg_s);
    EXPECT_NEAR(*m.settling_1deg_s, tau * std::log(size), 3e-3);
    EXPECT_NEAR(*m.rise_time_s, tau * std::log(9.0), 3e-3);
    EXPECT_DOUBLE_EQ(*m.overshoot_percent, 0.0);
  }
  // A ramp between holds is no step, a jump held shorter than 0.5 s neither, nor a start at the
  // target.
  std::vector<TrackingPoint> ramp;
  for (int k = 0; k < 3000; ++k) {
    const double t = k * kDt;
    const double target = t < 1.0 ? 150.0 : t < 2.0 ? 150.0 - 20.0 * (t - 1.0) : 130.0;
    ramp.push_back({t, target, target});
  }
  ramp[2500].target_deg = 120.0;  // One frame's jump.
  EXPECT_TRUE(ComputeEveryStepMetrics(ramp).empty());
  EXPECT_TRUE(ComputeEveryStepMetrics({}).empty());  // A run without an angle target.
  EXPECT_FALSE(ComputeTrackingMetrics({}).rms_error_deg);
}

// The response is the target 0.2 s late: the lag is found to the frame and, taken out, leaves no
// error; the RMS error with the lag is the sine's own difference over 0.2 s.
TEST(TrackingMetrics, ADelayedSineGivesItsLagAndNoErrorWithoutIt) {
  const double dt = 1.0 / 30.0, lag = 6 * dt, amplitude = 20.0, hz = 0.5;
  std::vector<TrackingPoint> points;
  for (int k = 0; k < 300; ++k) {
    const double t = k * dt;
    points.push_back({t, 140.0 + amplitude * std::sin(2 * std::numbers::pi * hz * t),
                      140.0 + amplitude * std::sin(2 * std::numbers::pi * hz * (t - lag))});
  }
  const TrackingMetrics m = ComputeTrackingMetrics(points);
  ASSERT_TRUE(m.lag_s && m.rms_error_deg && m.rms_error_without_lag_deg);
  EXPECT_NEAR(*m.lag_s, lag, 1e-9);
  EXPECT_LT(*m.rms_error_without_lag_deg, 1e-6);
  // sin(a) - sin(a - d) has amplitude 2 sin(d / 2): its RMS is that over sqrt(2).
  EXPECT_NEAR(*m.rms_error_deg, amplitude * 2.0 * std::sin(std::numbers::pi * hz * lag) / std::sqrt(2.0), 0.05);
  EXPECT_EQ(FormatTrackingMetrics(m).substr(0, 24), "tracking: RMS error 8.74");
}


// A step held 1.5 s, then a sine followed exactly: the step's frames (its first one too, 30 deg
// off) are the step's business; the tracking error is the sine's, zero.
TEST(TrackingMetrics, TheStepBeforeTheMotionIsNotCounted) {
  const double dt = 1.0 / 30.0;
  std::vector<TrackingPoint> points;
  for (int k = 0; k < 45; ++k) points.push_back({k * dt, 150.0, 150.0 + 30.0 * std::exp(-k * dt / 0.1)});
  for (int k = 45; k < 240; ++k) {
    const double target = 150.0 + 20.0 * std::sin(2 * std::numbers::pi * 0.5 * (k - 45) * dt);
    points.push_back({k * dt, target, target});
  }
  const TrackingMetrics m = ComputeTrackingMetrics(points);
  ASSERT_TRUE(m.rms_error_deg);
  EXPECT_LT(*m.rms_error_deg, 1e-9);
  EXPECT_DOUBLE_EQ(*m.lag_s, 0.0);
}

}  // namespace
}  // namespace softsight
