#include "control/step_metrics.h"

#include <cmath>
#include <cstdio>

namespace softsight {
namespace {

// The first time the response, moving from `from` towards `to`, reaches `level` (a fraction of
// the step), interpolated between the two frames around it; searched from index `begin`.
std::optional<double> CrossingTime(const std::vector<TrackingPoint>& points, size_t begin,
                                   double from, double to, double level) {
  const double direction = to > from ? 1.0 : -1.0;
  const double threshold = from + level * (to - from);
  std::optional<size_t> previous;
  for (size_t k = begin; k < points.size(); ++k) {
    if (!points[k].measured_deg) continue;
    const double y = *points[k].measured_deg;
    if (direction * (y - threshold) >= 0.0) {
      if (!previous) return points[k].time_s;
      const double y0 = *points[*previous].measured_deg;
      const double t0 = points[*previous].time_s;
      const double f = (threshold - y0) / (y - y0);  // y0 had not reached it: y != y0.
      return t0 + f * (points[k].time_s - t0);
    }
    previous = k;
  }
  return std::nullopt;
}

// Time from the step at `begin` until the response stays within `tolerance` of `target`.
std::optional<double> SettlingTime(const std::vector<TrackingPoint>& points, size_t begin,
                                   double target, double tolerance) {
  std::optional<size_t> first_inside;
  for (size_t k = begin; k < points.size(); ++k) {
    if (!points[k].measured_deg) continue;
    if (std::abs(*points[k].measured_deg - target) <= tolerance) {
      if (!first_inside) first_inside = k;
    } else {
      first_inside.reset();
    }
  }
  if (!first_inside) return std::nullopt;
  return points[*first_inside].time_s - points[begin].time_s;
}

void Append(std::string* out, const char* label, const std::optional<double>& v, const char* unit,
            const char* absent, bool sign = false) {
  char text[96];
  if (v) {
    std::snprintf(text, sizeof(text), sign ? "%s %+.2f%s" : "%s %.2f%s", label, *v, unit);
  } else {
    std::snprintf(text, sizeof(text), "%s %s", label, absent);
  }
  if (!out->empty()) *out += ", ";
  *out += text;
}

}  // namespace

StepMetrics ComputeStepMetrics(const std::vector<TrackingPoint>& points,
                               const StepMetricsOptions& options) {
  StepMetrics m;
  double sum_sq = 0.0;
  size_t n = 0;
  for (const TrackingPoint& p : points) {
    if (!p.measured_deg) continue;
    const double e = *p.measured_deg - p.target_deg;
    sum_sq += e * e;
    ++n;
  }
  if (n == 0) return m;
  m.rms_error_deg = std::sqrt(sum_sq / static_cast<double>(n));

  // The last jump of the target; the run's start when it never jumps.
  size_t begin = 0;
  for (size_t k = 1; k < points.size(); ++k) {
    if (std::abs(points[k].target_deg - points[k - 1].target_deg) > options.step_threshold_deg) {
      begin = k;
    }
  }
  const double to = points[begin].target_deg;
  for (size_t k = begin; k < points.size(); ++k) {
    if (points[k].target_deg != to) return m;  // Not a constant target after the step.
  }
  // Where the response started: the last measurement before the step, else the first after.
  std::optional<double> from;
  for (size_t k = begin + 1; k-- > 0 && !from;) from = points[k].measured_deg;
  for (size_t k = begin; k < points.size() && !from; ++k) from = points[k].measured_deg;
  if (!from) return m;
  m.step_time_s = points[begin].time_s;
  m.step_from_deg = *from;
  m.step_to_deg = to;

  const double end_s = points.back().time_s;
  double steady_sum = 0.0;
  size_t steady_n = 0;
  for (size_t k = begin; k < points.size(); ++k) {
    if (!points[k].measured_deg || points[k].time_s < end_s - options.steady_window_s) continue;
    steady_sum += *points[k].measured_deg - to;
    ++steady_n;
  }
  if (steady_n > 0) m.steady_state_error_deg = steady_sum / static_cast<double>(steady_n);

  const double step = to - *from;
  if (std::abs(step) < options.min_step_deg) return m;
  const std::optional<double> t10 = CrossingTime(points, begin, *from, to, 0.1);
  const std::optional<double> t90 = CrossingTime(points, begin, *from, to, 0.9);
  if (t10 && t90) m.rise_time_s = *t90 - *t10;
  m.settling_1deg_s = SettlingTime(points, begin, to, 1.0);
  m.settling_2deg_s = SettlingTime(points, begin, to, 2.0);
  const double direction = step > 0.0 ? 1.0 : -1.0;
  double beyond = 0.0;
  for (size_t k = begin; k < points.size(); ++k) {
    if (points[k].measured_deg) beyond = std::max(beyond, direction * (*points[k].measured_deg - to));
  }
  m.overshoot_percent = 100.0 * beyond / std::abs(step);
  return m;
}

std::string FormatStepMetrics(const StepMetrics& m) {
  std::string out;
  if (m.step_to_deg && m.step_from_deg) {
    char text[96];
    std::snprintf(text, sizeof(text), "step %.1f -> %.1f deg at %.2f s:", *m.step_from_deg,
                  *m.step_to_deg, m.step_time_s.value_or(0.0));
    std::string figures;
    Append(&figures, "rise (10-90 %)", m.rise_time_s, " s", "-");
    Append(&figures, "settling +-1 deg", m.settling_1deg_s, " s", "not settled");
    Append(&figures, "+-2 deg", m.settling_2deg_s, " s", "not settled");
    Append(&figures, "overshoot", m.overshoot_percent, " %", "-");
    Append(&figures, "steady-state error", m.steady_state_error_deg, " deg", "-", true);
    out = std::string(text) + " " + figures + "; ";
  }
  std::string rms;
  Append(&rms, "RMS error over the run", m.rms_error_deg, " deg", "- (no angle measured)");
  return out + rms;
}

std::string StepMetricsCsv(const StepMetrics& m) {
  const std::optional<double>* values[] = {
      &m.step_time_s,     &m.step_from_deg,   &m.step_to_deg,       &m.rise_time_s,
      &m.settling_1deg_s, &m.settling_2deg_s, &m.overshoot_percent, &m.steady_state_error_deg,
      &m.rms_error_deg};
  std::string out =
      "step_time_s,step_from_deg,step_to_deg,rise_time_s,settling_1deg_s,settling_2deg_s,"
      "overshoot_percent,steady_state_error_deg,rms_error_deg\n";
  bool first = true;
  for (const std::optional<double>* v : values) {
    if (!first) out += ",";
    first = false;
    if (*v) {
      char text[32];
      std::snprintf(text, sizeof(text), "%.6g", **v);
      out += text;
    }
  }
  return out + "\n";
}

}  // namespace softsight
