#include "control/step_metrics.h"

#include <algorithm>
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

std::string FormatStepMetrics(const StepMetrics& m, const char* rms_span) {
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
  const std::string label = std::string("RMS error over ") + rms_span;
  Append(&rms, label.c_str(), m.rms_error_deg, " deg", "- (no angle measured)");
  return out + rms;
}

namespace {

// A piece of a run that is a step: from a jump of the target (or the run's start) to the next
// jump, the target constant for at least steady_window_s after it. Indices into the points:
// `begin` is the frame before the jump (where the response starts from), `first` the jump's.
struct StepPiece {
  size_t begin, first, end;
};

std::vector<StepPiece> StepPieces(const std::vector<TrackingPoint>& points,
                                  const StepMetricsOptions& options) {
  std::vector<StepPiece> pieces;
  if (points.empty()) return pieces;
  std::vector<size_t> starts{0};
  for (size_t k = 1; k < points.size(); ++k) {
    if (points[k].target_deg != points[k - 1].target_deg) starts.push_back(k);
  }
  for (size_t i = 0; i < starts.size(); ++i) {
    const size_t first = starts[i];
    const size_t end = i + 1 < starts.size() ? starts[i + 1] : points.size();
    const bool jumped =
        first == 0 ||
        std::abs(points[first].target_deg - points[first - 1].target_deg) >
            options.step_threshold_deg;
    // Held long enough to settle (not a frame of a ramp or a sine that moved by more).
    if (jumped && points[end - 1].time_s - points[first].time_s >= options.steady_window_s) {
      pieces.push_back({first == 0 ? 0 : first - 1, first, end});
    }
  }
  return pieces;
}

}  // namespace

std::vector<StepMetrics> ComputeEveryStepMetrics(const std::vector<TrackingPoint>& points,
                                                 const StepMetricsOptions& options) {
  std::vector<StepMetrics> steps;
  std::vector<TrackingPoint> piece;
  for (const StepPiece& p : StepPieces(points, options)) {
    piece.assign(points.begin() + static_cast<std::ptrdiff_t>(p.begin),
                 points.begin() + static_cast<std::ptrdiff_t>(p.end));
    const StepMetrics m = ComputeStepMetrics(piece, options);
    if (m.step_to_deg && m.overshoot_percent) steps.push_back(m);
  }
  return steps;
}

TrackingMetrics ComputeTrackingMetrics(const std::vector<TrackingPoint>& points,
                                       double max_lag_s) {
  TrackingMetrics out;
  if (points.size() < 3) return out;
  // Scored where the target moves: the steps (and their settling) have their own figures.
  std::vector<bool> scored(points.size(), true);
  for (const StepPiece& p : StepPieces(points, StepMetricsOptions{})) {
    std::fill(scored.begin() + static_cast<std::ptrdiff_t>(p.first),
              scored.begin() + static_cast<std::ptrdiff_t>(p.end), false);
  }
  if (std::find(scored.begin(), scored.end(), true) == scored.end()) return out;
  // The frame period: the median spacing (a dropped frame does not change it).
  std::vector<double> spacing;
  spacing.reserve(points.size() - 1);
  for (size_t k = 1; k < points.size(); ++k) {
    spacing.push_back(points[k].time_s - points[k - 1].time_s);
  }
  std::nth_element(spacing.begin(), spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2),
                   spacing.end());
  const double period_s = spacing[spacing.size() / 2];
  if (!(period_s > 0.0)) return out;
  // The target at any time, linear between frames (held before the first).
  const auto target_at = [&points](double t) {
    if (t <= points.front().time_s) return points.front().target_deg;
    const auto after = std::lower_bound(
        points.begin(), points.end(), t,
        [](const TrackingPoint& p, double time) { return p.time_s < time; });
    if (after == points.end()) return points.back().target_deg;
    const auto before = after - 1;
    const double span = after->time_s - before->time_s;
    const double f = span > 0.0 ? (t - before->time_s) / span : 1.0;
    return before->target_deg + f * (after->target_deg - before->target_deg);
  };
  const auto rms_at_lag = [&](double lag_s) -> std::optional<double> {
    double sum_sq = 0.0;
    size_t n = 0;
    for (size_t k = 0; k < points.size(); ++k) {
      const TrackingPoint& p = points[k];
      if (!scored[k] || !p.measured_deg || p.time_s - lag_s < points.front().time_s) continue;
      const double e = *p.measured_deg - target_at(p.time_s - lag_s);
      sum_sq += e * e;
      ++n;
    }
    if (n == 0) return std::nullopt;
    return std::sqrt(sum_sq / static_cast<double>(n));
  };
  out.rms_error_deg = rms_at_lag(0.0);
  if (!out.rms_error_deg) return out;
  const int most = static_cast<int>(std::min(max_lag_s / period_s, 1000.0));
  double best_lag = 0.0;
  double best = *out.rms_error_deg;
  for (int k = 1; k <= most; ++k) {
    const std::optional<double> rms = rms_at_lag(k * period_s);
    if (rms && *rms < best) {
      best = *rms;
      best_lag = k * period_s;
    }
  }
  out.lag_s = best_lag;
  out.rms_error_without_lag_deg = best;
  return out;
}

std::string FormatTrackingMetrics(const TrackingMetrics& m) {
  if (!m.rms_error_deg) return "tracking: - (no angle measured)";
  char text[160];
  std::snprintf(text, sizeof(text),
                "tracking: RMS error %.2f deg, lag %.2f s (RMS %.2f deg with the lag taken out)",
                *m.rms_error_deg, m.lag_s.value_or(0.0),
                m.rms_error_without_lag_deg.value_or(*m.rms_error_deg));
  return text;
}

std::string StepMetricsCsv(const std::vector<StepMetrics>& steps) {
  std::string out =
      "step_time_s,step_from_deg,step_to_deg,rise_time_s,settling_1deg_s,settling_2deg_s,"
      "overshoot_percent,steady_state_error_deg,rms_error_deg\n";
  for (const StepMetrics& m : steps) {
    const std::optional<double>* values[] = {
        &m.step_time_s,     &m.step_from_deg,   &m.step_to_deg,       &m.rise_time_s,
        &m.settling_1deg_s, &m.settling_2deg_s, &m.overshoot_percent, &m.steady_state_error_deg,
        &m.rms_error_deg};
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
    out += "\n";
  }
  return out;
}

}  // namespace softsight
