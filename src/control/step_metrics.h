// Figures of merit of a closed-loop run, from the target and the measured angle at each frame:
// rise time, settling time (+-1 and +-2 deg), overshoot and steady-state error of the last step to a
// constant target, and the RMS error over the whole profile. Shared by `softsight control`'s
// summary and CSV, `softsight identify --verify` style checks and the tests.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace softsight {

struct TrackingPoint {
  double time_s = 0.0;
  double target_deg = 0.0;
  std::optional<double> measured_deg;  // Absent: the angle was not measured in that frame.
};

struct StepMetricsOptions {
  // A change of the target larger than this between two frames starts a step. 0.5 deg: smaller
  // changes are a profile moving (a ramp, a sine), not a step.
  double step_threshold_deg = 0.5;
  // Steps smaller than this get no step figures (rise, settling, overshoot). Default 2 deg.
  double min_step_deg = 2.0;
  // The steady-state error is the mean error over this last part of the run. Default 0.5 s.
  double steady_window_s = 0.5;
};

struct StepMetrics {
  // Over every frame with a measurement: sqrt(mean((measured - target)^2)).
  std::optional<double> rms_error_deg;
  // The step the figures below describe: the last jump of the target (or the start of the run
  // when the target never jumps: the actuator starts where it is), to a target that then stays
  // constant to the end of the run.
  std::optional<double> step_time_s;
  std::optional<double> step_from_deg;  // Measured when the step began.
  std::optional<double> step_to_deg;    // The target after the step.
  // From 10 % to 90 % of the step (linear interpolation between frames).
  std::optional<double> rise_time_s;
  // From the step until the measured angle stays within +-1 (+-2) deg of the target to the end
  // of the run: the time of the first frame of that last stretch. Absent when the last frame is
  // outside (not settled).
  std::optional<double> settling_1deg_s;
  std::optional<double> settling_2deg_s;
  // How far the angle went beyond the target, in % of the step (0 when it never did).
  std::optional<double> overshoot_percent;
  // Mean of measured - target over the last steady_window_s of the step.
  std::optional<double> steady_state_error_deg;
};

StepMetrics ComputeStepMetrics(const std::vector<TrackingPoint>& points,
                               const StepMetricsOptions& options = {});

// The figures of every step of a staircase: the run cut at each jump of the target (the run's
// start counts as one when the response starts away from the first target), each piece scored
// as ComputeStepMetrics scores a run, its RMS error over the piece. Pieces whose target is not
// constant (a ramp, a sine) or that move less than min_step_deg are left out.
std::vector<StepMetrics> ComputeEveryStepMetrics(const std::vector<TrackingPoint>& points,
                                                 const StepMetricsOptions& options = {});

// How a moving target (a ramp, a slow sine) is followed: the RMS error, the delay of the response
// behind the target (the shift, in whole frames up to max_lag_s, that makes the RMS error
// smallest) and the RMS error once that delay is taken out (what is left is amplitude and shape).
struct TrackingMetrics {
  std::optional<double> rms_error_deg;
  std::optional<double> lag_s;
  std::optional<double> rms_error_without_lag_deg;
};
TrackingMetrics ComputeTrackingMetrics(const std::vector<TrackingPoint>& points,
                                       double max_lag_s = 2.0);
// "tracking: RMS error 1.85 deg, lag 0.20 s (RMS 0.41 deg with the lag taken out)".
std::string FormatTrackingMetrics(const TrackingMetrics& metrics);

// "rise 0.42 s, settling +-1 deg 1.10 s, +-2 deg 0.80 s, overshoot 2.1 %, steady-state error
// +0.05 deg, RMS error 6.31 deg" (figures that are absent are said so: "not settled").
// `rms_span` names what the RMS error covers ("the run"; "the step" for one of a staircase).
std::string FormatStepMetrics(const StepMetrics& metrics, const char* rms_span = "the run");

// The CSV of the figures: a header line and one line of values per step (empty where absent).
std::string StepMetricsCsv(const std::vector<StepMetrics>& steps);

}  // namespace softsight
