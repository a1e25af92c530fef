#include "control/identify.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "softsight/core/format.h"

namespace softsight {
namespace {


std::string Seconds(double v) { return FixedNumber(v, 2) + " s"; }

// The inner-loop probe inflates to this fraction of the ceiling: high enough for a few frames of
// a rising pressure in a small chamber, low enough that what the tube still delivers after the
// valves close stays under the ceiling.
constexpr double kProbeFraction = 0.25;

// Solves the 3x3 system a x = b (Cramer's rule); false when it is (nearly) singular.
bool Solve3(const double a[3][3], const double b[3], double x[3]) {
  auto det = [](const double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const double d = det(a);
  double scale = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) scale = std::max(scale, std::abs(a[i][j]));
  if (!(std::abs(d) > 1e-12 * scale * scale * scale)) return false;
  for (int c = 0; c < 3; ++c) {
    double m[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m[i][j] = j == c ? b[i] : a[i][j];
    x[c] = det(m) / d;
  }
  return true;
}

// Least squares of angle = c - slope * p + branch * half_width over `points` (branch +1 up,
// -1 down; without a down point the width is not fitted). False when underdetermined.
struct LineFit {
  double c = 0.0, slope = 0.0, half_width = 0.0;
};
bool FitBranches(const std::vector<StaticPoint>& points, LineFit* fit) {
  double a[3][3] = {{0}}, b[3] = {0};
  bool up = false, down = false;
  for (const StaticPoint& p : points) {
    const double row[3] = {1.0, -p.pressure_kpa, p.up ? 1.0 : -1.0};
    (p.up ? up : down) = true;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) a[i][j] += row[i] * row[j];
      b[i] += row[i] * p.angle_deg;
    }
  }
  if (points.size() < 3) return false;
  double x[3] = {0, 0, 0};
  if (up && down) {
    if (!Solve3(a, b, x)) return false;
  } else {
    // One branch: a straight line, no width.
    const double n = a[0][0], sp = a[0][1], spp = a[1][1], sy = b[0], spy = b[1];
    const double d = n * spp - sp * sp;
    if (!(std::abs(d) > 1e-12)) return false;
    x[0] = (spp * sy - sp * spy) / d;
    x[1] = (n * spy - sp * sy) / d;
  }
  fit->c = x[0];
  fit->slope = x[1];
  fit->half_width = x[2];
  return true;
}

double Residual(const LineFit& f, const StaticPoint& p) {
  return p.angle_deg - (f.c - f.slope * p.pressure_kpa + (p.up ? 1.0 : -1.0) * f.half_width);
}

// The input of a sampled signal at time t: piecewise constant (the setpoint, held from its frame
// on) or linear between samples (a sensed pressure).
double HeldAt(const std::vector<double>& t, const std::vector<double>& v, double time) {
  if (time <= t.front()) return v.front();
  const size_t k = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());
  return v[k - 1];
}
double LinearAt(const std::vector<double>& t, const std::vector<double>& v, double time) {
  if (time <= t.front()) return v.front();
  if (time >= t.back()) return v.back();
  const size_t k = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());
  const double f = (time - t[k - 1]) / (t[k] - t[k - 1]);
  return v[k - 1] + f * (v[k] - v[k - 1]);
}

constexpr int kSubsteps = 8;  // Per frame, in the simulations of the fits.

// First-order lag plus dead time driven by `input(t)`, sampled at `t`, starting at `y0`.
template <typename Input>
std::vector<double> SimulateLag(const std::vector<double>& t, double y0, double lag_s,
                                double dead_s, Input input) {
  std::vector<double> out(t.size());
  double x = y0;
  out[0] = x;
  for (size_t k = 0; k + 1 < t.size(); ++k) {
    const double h = (t[k + 1] - t[k]) / kSubsteps;
    const double a = 1.0 - std::exp(-h / lag_s);
    for (int s = 0; s < kSubsteps; ++s) {
      const double time = t[k] + (s + 0.5) * h;
      x += a * (input(time - dead_s) - x);
    }
    out[k + 1] = x;
  }
  return out;
}

// The bending model: sensed pressure (linear between samples, delayed) -> static map -> play of
// the hysteresis width -> first-order lag; returns the deflection (straight - angle) per sample.
std::vector<double> SimulateBend(const ActuatorModel& m, const std::vector<double>& t,
                                 const std::vector<double>& pressure, double d0, double lag_s,
                                 double dead_s) {
  std::vector<double> out(t.size());
  const double half = 0.5 * m.hysteresis_deg;
  const double top_kpa = m.saturation_kpa > 0.0 ? m.saturation_kpa : 1e9;
  double play = d0, d = d0;
  out[0] = d;
  for (size_t k = 0; k + 1 < t.size(); ++k) {
    const double h = (t[k + 1] - t[k]) / kSubsteps;
    const double a = 1.0 - std::exp(-h / lag_s);
    for (int s = 0; s < kSubsteps; ++s) {
      const double p = LinearAt(t, pressure, t[k] + (s + 0.5) * h - dead_s);
      const double target =
          m.slope_deg_per_kpa * (std::clamp(p, m.bend_start_kpa, top_kpa) - m.bend_start_kpa);
      play = std::clamp(play, target - half, target + half);
      d += a * (play - d);
    }
    out[k + 1] = d;
  }
  return out;
}

// The grid of a (parameter, dead time) search: the parameter from `lo` up to `hi` in 6 % steps,
// dead times from 0 up to `dead_max_s` in quarter frames.
struct SearchGrid {
  double lo, hi, dead_max_s;
};
// The lags' grid (0.01..3 s) and the duty loop's gains' (0.005..20 per kPa).
constexpr SearchGrid kLagGrid{0.01, 3.0, 0.4};
constexpr SearchGrid kDutyGainGrid{0.005, 20.0, 0.2};

// Grid search of (parameter, dead time) minimising `cost`. Returns {parameter, dead, cost}.
template <typename Cost>
std::array<double, 3> GridSearch(double frame_s, const SearchGrid& grid, Cost cost) {
  std::array<double, 3> best = {0.0, 0.0, std::numeric_limits<double>::infinity()};
  const double dead_step = std::max(1e-3, frame_s / 4.0);
  for (double value = grid.lo; value <= grid.hi; value *= 1.06) {
    for (double dead = 0.0; dead <= grid.dead_max_s + 1e-9; dead += dead_step) {
      const double c = cost(value, dead);
      if (c < best[2]) best = {value, dead, c};
    }
  }
  return best;
}

// FitStaticMap's saturation, bottom up: starting from the three lowest bent levels of the up
// branch, each next level is taken while its up point lies on the line through the levels below
// (within the scatter); the first that lies above it (less bent than the line predicts) is where
// the bend saturates, and it and every point at its level or above (both branches) are left out
// of `bent`, `fit` becoming the line below. 0: no saturation seen.
double SaturationPressure(std::vector<StaticPoint>* bent, LineFit* fit) {
  std::vector<double> levels;  // Up-branch pressures, ascending.
  for (const StaticPoint& p : *bent) {
    if (p.up) levels.push_back(p.pressure_kpa);
  }
  std::sort(levels.begin(), levels.end());
  // The same level reached from above reads a slightly different pressure: a level's points
  // are those below a third of the way up to the next level.
  const auto below_level = [&](size_t i) {
    return i + 1 < levels.size() ? levels[i] + (levels[i + 1] - levels[i]) / 3.0 : 1e9;
  };
  const auto points_to = [&](size_t i) {
    std::vector<StaticPoint> out;
    for (const StaticPoint& p : *bent) {
      if (p.pressure_kpa < below_level(i)) out.push_back(p);
    }
    return out;
  };
  for (size_t i = 3; i < levels.size(); ++i) {
    const std::vector<StaticPoint> below = points_to(i - 1);
    LineFit line;
    if (!FitBranches(below, &line) || !(line.slope > 0.0)) break;
    double sum_sq = 0.0;
    for (const StaticPoint& p : below) sum_sq += Residual(line, p) * Residual(line, p);
    const double scatter = std::sqrt(sum_sq / static_cast<double>(below.size()));
    const StaticPoint* next = nullptr;
    for (const StaticPoint& p : *bent) {
      if (p.up && p.pressure_kpa == levels[i]) next = &p;
    }
    if (Residual(line, *next) > std::max(1.5, 3.0 * scatter)) {
      const double saturated_deg = next->angle_deg;  // (`next` points into `bent`.)
      *bent = below;
      *fit = line;
      return (fit->c + fit->half_width - saturated_deg) / fit->slope;
    }
  }
  return 0.0;
}

// One robust pass: points far off the fit (a step not quite settled) are dropped.
void DropOutliers(std::vector<StaticPoint>* bent, LineFit* fit) {
  std::vector<double> r;
  for (const StaticPoint& p : *bent) r.push_back(std::abs(Residual(*fit, p)));
  std::vector<double> sorted = r;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double limit = std::max(1.0, 4.0 * sorted[sorted.size() / 2]);
  std::vector<StaticPoint> kept;
  for (size_t i = 0; i < bent->size(); ++i) {
    if (r[i] <= limit) kept.push_back((*bent)[i]);
  }
  LineFit refit;
  if (kept.size() >= 3 && kept.size() < bent->size() && FitBranches(kept, &refit) &&
      refit.slope > 0.0) {
    *bent = kept;
    *fit = refit;
  }
}

// The PRBS part of an experiment, with an angle and a pressure in every frame used: time,
// setpoint, sensed pressure, angle.
struct PrbsFrames {
  std::vector<double> t, u, p, a;
};

PrbsFrames PrbsFramesOf(const IdentificationExperiment& experiment) {
  PrbsFrames f;
  for (const IdentifySample& s : experiment.samples()) {
    if (s.phase != IdentificationExperiment::kPrbs || !s.angle_deg ||
        !std::isfinite(s.pressure_kpa)) {
      continue;
    }
    f.t.push_back(s.time_s);
    f.u.push_back(s.setpoint_kpa);
    f.p.push_back(s.pressure_kpa);
    f.a.push_back(*s.angle_deg);
  }
  return f;
}

// Bending: sensed pressure -> static map with its play -> lag + dead time -> angle. The cost of
// (lag, dead time): the squared error left after an offset and a scale (least squares, for each
// candidate) absorb what the static fit left.
double BendCost(const ActuatorModel& m, const PrbsFrames& f, double d0, double lag, double dead) {
  const std::vector<double>& t = f.t, &p = f.p, &a = f.a;
  const std::vector<double> d = SimulateBend(m, t, p, d0, lag, dead);
  // a = alpha - beta d.
  double n = 0, sd = 0, sdd = 0, sa = 0, sda = 0;
  for (size_t k = 0; k < d.size(); ++k) {
    n += 1;
    sd += d[k];
    sdd += d[k] * d[k];
    sa += a[k];
    sda += d[k] * a[k];
  }
  const double det = n * sdd - sd * sd;
  double alpha = sa / n, beta = 0.0;
  if (det > 1e-12) {
    beta = -(n * sda - sd * sa) / det;
    alpha = (sa + beta * sd) / n;
  }
  double sse = 0.0;
  for (size_t k = 0; k < d.size(); ++k) {
    const double e = a[k] - (alpha - beta * d[k]);
    sse += e * e;
  }
  return sse;
}

// The same as the board's loop works (ActuatorModel::pressure_duty_per_kpa): a duty
// proportional to the error, saturating, times the probe's rates; the gain by a grid of 6 %
// steps (as the lags).
void FitDutyLoop(const InnerLoopMeasurement& probe, const InnerLoopGains& gains,
                 const PrbsFrames& f, double frame_s, ActuatorModel* m) {
  const std::vector<double>& t = f.t, &u = f.u, &p = f.p;
  const double inflate = std::max(1e-3, probe.inflate_kpa_per_s);
  const double vent = std::max(1e-3, probe.vent_kpa_per_s) * (gains.given() ? gains.vent_scale : 1.0);
  const double vent_at = std::max(0.05, probe.vent_at_kpa);
  const auto duty_cost = [&](double gain, double dead) {
    double x = p[0], sse = 0.0;
    for (size_t k = 0; k + 1 < t.size(); ++k) {
      const double h = (t[k + 1] - t[k]) / kSubsteps;
      for (int sub = 0; sub < kSubsteps; ++sub) {
        const double sp = HeldAt(t, u, t[k] + (sub + 0.5) * h - dead);
        const double duty = std::clamp(gain * (sp - x), -1.0, 1.0);
        const double rate = duty >= 0.0 ? duty * inflate
                                         : duty * vent * std::sqrt(std::max(x, 0.05) / vent_at);
        const double next = x + h * rate;
        x = std::max(0.0, (next - sp) * (x - sp) < 0.0 ? sp : next);
      }
      sse += (x - p[k + 1]) * (x - p[k + 1]);
    }
    return sse;
  };
  const std::array<double, 3> best = GridSearch(frame_s, kDutyGainGrid, duty_cost);
  m->pressure_duty_per_kpa = best[0];
  m->pressure_duty_dead_time_s = best[1];
  m->pressure_duty_rms_kpa = std::sqrt(best[2] / static_cast<double>(t.size()));
}

}  // namespace

// ---- The experiment ------------------------------------------------------------------------------

IdentificationExperiment::IdentificationExperiment(const IdentifyOptions& options,
                                                   double ceiling_kpa)
    : options_(options), ceiling_kpa_(ceiling_kpa) {
  if (!(ceiling_kpa > 0.0) || !std::isfinite(ceiling_kpa)) {
    throw InputError("identify: the pressure ceiling " + ShortNumber(ceiling_kpa, 3) +
                     " kPa must be positive (control.controller.max_kpa, the board's limit)");
  }
  if (options_.levels < 3) throw InputError("identify: at least 3 pressure levels");
}

void IdentificationExperiment::start_hold(double time_s, double setpoint_kpa) {
  hold_start_s_ = time_s;
  hold_first_sample_ = samples_.size();
  setpoint_kpa_ = std::clamp(setpoint_kpa, 0.0, ceiling_kpa_);
}

bool IdentificationExperiment::hold_complete(double time_s) const {
  const double held = time_s - hold_start_s_;
  if (held >= options_.max_hold_s) return true;
  if (held < options_.min_hold_s) return false;
  // Steady: the mean angle and pressure of the last window against the window before it.
  const double w = options_.steady_window_s;
  double sum[2][2] = {{0, 0}, {0, 0}};
  int n[2] = {0, 0};
  for (size_t k = hold_first_sample_; k < samples_.size(); ++k) {
    const IdentifySample& s = samples_[k];
    if (!s.angle_deg || !std::isfinite(s.pressure_kpa)) continue;
    const double age = time_s - s.time_s;
    const int window = age < w ? 0 : age < 2 * w ? 1 : -1;
    if (window < 0) continue;
    sum[window][0] += *s.angle_deg;
    sum[window][1] += s.pressure_kpa;
    ++n[window];
  }
  if (n[0] < 2 || n[1] < 2) return false;
  const double angle_drift = std::abs(sum[0][0] / n[0] - sum[1][0] / n[1]);
  const double pressure_drift = std::abs(sum[0][1] / n[0] - sum[1][1] / n[1]);
  return angle_drift < options_.steady_deg && pressure_drift < 0.3;
}

StaticPoint IdentificationExperiment::steady_point(bool up) const {
  StaticPoint p;
  p.up = up;
  const double end_s = samples_.back().time_s;
  double sa = 0, sp = 0;
  int n = 0;
  for (size_t k = hold_first_sample_; k < samples_.size(); ++k) {
    const IdentifySample& s = samples_[k];
    if (!s.angle_deg || !std::isfinite(s.pressure_kpa)) continue;
    if (end_s - s.time_s >= options_.steady_window_s) continue;
    sa += *s.angle_deg;
    sp += s.pressure_kpa;
    ++n;
  }
  if (n == 0) throw IdentifyAbort("identify: no angle measured while holding a pressure step");
  p.angle_deg = sa / n;
  p.pressure_kpa = sp / n;
  return p;
}

void IdentificationExperiment::start_prbs(double time_s) {
  const ActuatorModel m = FitStaticMap(static_points_, *straight_deg_);
  const double top = m.saturation_kpa > 0.0 ? std::min(m.saturation_kpa, m.valid_max_kpa)
                                            : m.valid_max_kpa;
  const double span = top - m.bend_start_kpa;
  if (!(span > 0.0)) {
    throw IdentifyAbort("identify: no linear range between the bend start (" +
                        ShortNumber(m.bend_start_kpa, 3) + " kPa) and the saturation (" + ShortNumber(top, 3) +
                        " kPa)");
  }
  prbs_centre_kpa_ = m.bend_start_kpa + 0.5 * span;
  prbs_amplitude_kpa_ = options_.prbs_amplitude * span;
  // 5-bit maximal-length shift register (x^5 + x^3 + 1): 31 bits, every pattern of up to 5 once.
  prbs_bits_.clear();
  unsigned state = 0x15;
  for (int i = 0; i < 31; ++i) {
    prbs_bits_.push_back(static_cast<int>(state & 1u));
    const unsigned feedback = (state ^ (state >> 2)) & 1u;
    state = (state >> 1) | (feedback << 4);
  }
  phase_ = kPrbs;
  prbs_start_s_ = -1.0;  // After the working point is reached.
  start_hold(time_s, prbs_centre_kpa_);
}

double IdentificationExperiment::next(double time_s, std::optional<double> angle_deg) {
  if (phase_ == kDone) return 0.0;
  // Markers lost for too long: the experiment cannot go on blind.
  if (!angle_deg) {
    if (!lost_since_s_) lost_since_s_ = time_s;
    if (time_s - *lost_since_s_ >= options_.lost_s) {
      throw IdentifyAbort("identify: markers lost for " + Seconds(time_s - *lost_since_s_) +
                          " at " + Seconds(time_s) + " (" +
                          ShortNumber(samples_.empty() ? 0.0 : samples_.back().pressure_kpa, 3) +
                          " kPa); vented");
    }
  } else {
    lost_since_s_.reset();
  }
  if (samples_.empty()) start_hold(time_s, 0.0);
  IdentifySample sample;
  sample.time_s = time_s;
  sample.angle_deg = angle_deg;
  sample.pressure_kpa = std::numeric_limits<double>::quiet_NaN();
  sample.phase = phase_;
  samples_.push_back(sample);

  switch (phase_) {
    case kBaseline:
      if (hold_complete(time_s)) {
        straight_deg_ = steady_point(true).angle_deg;
        phase_ = kInnerLoop;
        probe_.emplace(kProbeFraction * ceiling_kpa_);
        probe(time_s);
      }
      break;
    case kInnerLoop:
      probe(time_s);
      break;
    case kStepsUp:
      if (hold_complete(time_s)) {
        const StaticPoint p = steady_point(true);
        static_points_.push_back(p);
        if (p.pressure_kpa < 0.5 * setpoint_kpa_ && setpoint_kpa_ > 2.0) {
          throw IdentifyAbort("identify: the pressure does not follow the setpoint: " +
                              ShortNumber(p.pressure_kpa, 3) + " kPa after " +
                              Seconds(time_s - hold_start_s_) + " at " + ShortNumber(setpoint_kpa_, 3) +
                              " kPa (leak, pump or valve?); vented");
        }
        if (2 * level_ >= options_.levels &&
            std::abs(*straight_deg_ - p.angle_deg) < options_.min_response_deg) {
          throw IdentifyAbort("identify: the angle does not respond: " +
                              ShortNumber(*straight_deg_ - p.angle_deg, 3) + " deg of bend at " +
                              ShortNumber(p.pressure_kpa, 3) + " kPa (tubing, markers, config?); vented");
        }
        if (level_ < options_.levels) {
          ++level_;
          start_hold(time_s, ceiling_kpa_ * level_ / options_.levels);
        } else {
          phase_ = kStepsDown;
          --level_;
          start_hold(time_s, ceiling_kpa_ * level_ / options_.levels);
        }
      }
      break;
    case kStepsDown:
      if (hold_complete(time_s)) {
        static_points_.push_back(steady_point(false));
        if (level_ > 0) {
          --level_;
          start_hold(time_s, ceiling_kpa_ * level_ / options_.levels);
        } else {
          start_prbs(time_s);
        }
      }
      break;
    case kPrbs:
      if (prbs_start_s_ < 0.0) {
        if (hold_complete(time_s)) prbs_start_s_ = time_s;
      }
      if (prbs_start_s_ >= 0.0) {
        const size_t bit = static_cast<size_t>((time_s - prbs_start_s_) / options_.prbs_bit_s);
        if (bit >= prbs_bits_.size()) {
          phase_ = kDone;
          setpoint_kpa_ = 0.0;
        } else {
          setpoint_kpa_ = std::clamp(
              prbs_centre_kpa_ + (prbs_bits_[bit] ? 1.0 : -1.0) * prbs_amplitude_kpa_, 0.0,
              ceiling_kpa_);
        }
      }
      break;
    case kDone:
      break;
  }
  samples_.back().setpoint_kpa = duty_ ? 0.0 : setpoint_kpa_;
  samples_.back().duty = duty_;
  return duty_ ? 0.0 : setpoint_kpa_;
}

void IdentificationExperiment::probe(double time_s) {
  duty_ = probe_->next(time_s);
  if (duty_) return;
  inner_loop_ = probe_->measurement();
  if (const std::optional<InnerLoopGains> gains = InnerLoopGainsFor(*inner_loop_, ceiling_kpa_)) {
    inner_loop_gains_ = *gains;
    gains_to_send_ = true;
  }
  phase_ = kStepsUp;
  level_ = 1;
  start_hold(time_s, ceiling_kpa_ * level_ / options_.levels);
}

std::optional<InnerLoopGains> IdentificationExperiment::take_gains_to_send() {
  if (!gains_to_send_) return std::nullopt;
  gains_to_send_ = false;
  return inner_loop_gains_;
}

void IdentificationExperiment::answered(double pressure_kpa, int64_t board_time_ms) {
  if (samples_.empty()) return;
  samples_.back().pressure_kpa = pressure_kpa;
  samples_.back().board_time_ms = board_time_ms;
  if (probe_ && phase_ == kInnerLoop) probe_->answered(board_time_ms, pressure_kpa);
  if (pressure_kpa > ceiling_kpa_ + options_.over_ceiling_kpa) {
    throw IdentifyAbort("identify: the sensed pressure " + ShortNumber(pressure_kpa, 3) +
                        " kPa is above the experiment's ceiling of " + ShortNumber(ceiling_kpa_, 3) +
                        " kPa; vented");
  }
}

// ---- The fits ------------------------------------------------------------------------------------

ActuatorModel FitStaticMap(const std::vector<StaticPoint>& points, double straight_deg) {
  // The bent points: more than 1.5 deg from straight (below that, noise and the play's rest).
  // A down point below the lowest bent up point may still be held bent by the play with no
  // pressure to speak of (the down branch leaves the line at the bend start): left out too.
  std::vector<StaticPoint> bent;
  double max_kpa = 0.0, min_deg = straight_deg, lowest_up_kpa = 1e9;
  for (const StaticPoint& p : points) {
    max_kpa = std::max(max_kpa, p.pressure_kpa);
    min_deg = std::min(min_deg, p.angle_deg);
    if (p.up && straight_deg - p.angle_deg > 1.5) {
      lowest_up_kpa = std::min(lowest_up_kpa, p.pressure_kpa);
    }
  }
  for (const StaticPoint& p : points) {
    if (straight_deg - p.angle_deg > 1.5 && (p.up || p.pressure_kpa > 0.9 * lowest_up_kpa)) {
      bent.push_back(p);
    }
  }
  LineFit fit;
  auto no_bend = [&] {
    return IdentifyAbort("identify: the angle does not respond: " + ShortNumber(straight_deg - min_deg, 3) +
                         " deg of bend up to " + ShortNumber(max_kpa, 3) + " kPa; vented");
  };
  if (bent.size() < 3 || !FitBranches(bent, &fit) || !(fit.slope > 0.0)) throw no_bend();

  // Where the bend saturates (its points left out), then one robust pass.
  const double saturation_kpa = SaturationPressure(&bent, &fit);
  if (saturation_kpa == 0.0 && !FitBranches(bent, &fit)) throw no_bend();
  DropOutliers(&bent, &fit);
  ActuatorModel m;
  m.straight_deg = straight_deg;
  m.slope_deg_per_kpa = fit.slope;
  m.hysteresis_deg = std::max(0.0, 2.0 * fit.half_width);
  // The up branch leaves straight at c + w - slope p = straight + w, i.e. where the bend of the
  // mid line reaches half the width: the mid line starts at p0 = (c - straight) / slope.
  m.bend_start_kpa = std::max(0.0, (fit.c - straight_deg) / fit.slope);
  m.saturation_kpa = saturation_kpa;
  double sum_sq = 0.0;
  for (const StaticPoint& p : bent) sum_sq += Residual(fit, p) * Residual(fit, p);
  m.static_rms_deg = std::sqrt(sum_sq / static_cast<double>(bent.size()));
  m.valid_min_kpa = 0.0;
  m.valid_max_kpa = max_kpa;
  m.valid_min_deg = min_deg;
  m.valid_max_deg = straight_deg;
  return m;
}

std::vector<double> PredictAngles(const ActuatorModel& m, const std::vector<IdentifySample>& s) {
  std::vector<double> t, p;
  for (const IdentifySample& x : s) {
    t.push_back(x.time_s);
    p.push_back(std::isfinite(x.pressure_kpa) ? x.pressure_kpa : 0.0);
  }
  if (t.empty()) return {};
  const std::vector<double> d = SimulateBend(m, t, p, 0.0, std::max(1e-3, m.lag_s), m.dead_time_s);
  std::vector<double> out;
  for (double v : d) out.push_back(m.straight_deg - v);
  return out;
}

std::vector<double> PredictPressures(const ActuatorModel& m,
                                     const std::vector<IdentifySample>& s) {
  std::vector<double> t, u;
  for (const IdentifySample& x : s) {
    t.push_back(x.time_s);
    u.push_back(x.setpoint_kpa);
  }
  if (t.empty()) return {};
  const double p0 = std::isfinite(s.front().pressure_kpa) ? s.front().pressure_kpa : 0.0;
  return SimulateLag(t, p0, std::max(1e-3, m.pressure_lag_s), m.pressure_dead_time_s,
                     [&](double time) { return HeldAt(t, u, time); });
}

ActuatorModel FitActuatorModel(const IdentificationExperiment& experiment) {
  if (!experiment.straight_deg()) throw IdentifyAbort("identify: the experiment did not finish");
  ActuatorModel m = FitStaticMap(experiment.static_points(), *experiment.straight_deg());
  const PrbsFrames frames = PrbsFramesOf(experiment);
  const std::vector<double>& t = frames.t, &u = frames.u, &p = frames.p, &a = frames.a;
  if (t.size() < 20) throw IdentifyAbort("identify: too few frames in the dynamic test");
  const double frame_s = (t.back() - t.front()) / static_cast<double>(t.size() - 1);

  // Inner loop: setpoint (held from its frame) -> sensed pressure. The answer of frame k is the
  // pressure before the setpoint of frame k acted, so the model's output at t_k is compared.
  const auto pressure_cost = [&](double lag, double dead) {
    const std::vector<double> y =
        SimulateLag(t, p[0], lag, dead, [&](double time) { return HeldAt(t, u, time); });
    double sse = 0.0;
    for (size_t k = 0; k < y.size(); ++k) sse += (y[k] - p[k]) * (y[k] - p[k]);
    return sse;
  };
  const auto pressure_fit = GridSearch(frame_s, kLagGrid, pressure_cost);
  m.pressure_lag_s = pressure_fit[0];
  m.pressure_dead_time_s = pressure_fit[1];
  m.pressure_rms_kpa = std::sqrt(pressure_fit[2] / static_cast<double>(t.size()));

  // Bending: sensed pressure -> static map with its play -> lag + dead time -> angle. An offset
  // and a scale (least squares, for each candidate) absorb what the static fit left.
  const double d0 = m.straight_deg - a[0];
  const auto bend_cost = [&](double lag, double dead) {
    return BendCost(m, frames, d0, lag, dead);
  };
  if (const std::optional<InnerLoopMeasurement>& probe = experiment.inner_loop()) {
    FitDutyLoop(*probe, experiment.inner_loop_gains(), frames, frame_s, &m);
  }

  const auto bend_fit = GridSearch(frame_s, kLagGrid, bend_cost);
  m.lag_s = bend_fit[0];
  m.dead_time_s = bend_fit[1];
  m.dynamic_rms_deg = std::sqrt(bend_fit[2] / static_cast<double>(t.size()));
  if (const std::optional<InnerLoopMeasurement>& probe = experiment.inner_loop()) {
    m.valve_dead_time_s = probe->dead_time_s;
    m.inflate_kpa_per_s = probe->inflate_kpa_per_s;
    m.vent_kpa_per_s = probe->vent_kpa_per_s;
    m.vent_at_kpa = probe->vent_at_kpa;
  }
  return m;
}

double IdentificationCeiling(const ControllerOptions& controller, double board_limit_kpa) {
  return std::min({controller.max_kpa, 0.9 * board_limit_kpa, board_limit_kpa - 4.0});
}

ControlSample StepIdentification(IdentificationExperiment& experiment, ControlSession& session,
                                 double time_s, std::optional<double> angle_deg) {
  const double setpoint_kpa = experiment.next(time_s, angle_deg);
  // Gains the probe has just chosen reach the board before the first step that needs them.
  if (const std::optional<InnerLoopGains> gains = experiment.take_gains_to_send()) {
    session.set_inner_loop_gains(*gains);
  }
  const ControlSample sample =
      experiment.duty() ? session.step_duty(time_s, *experiment.duty(), angle_deg)
                        : session.step_pressure(time_s, setpoint_kpa, angle_deg);
  experiment.answered(sample.board.pressure_kpa, sample.board.time_ms);
  return sample;
}

// ---- Tuning --------------------------------------------------------------------------------------

// Integral separation of the tuned controller: errors beyond this are left to the feed-forward
// and P (see ControllerOptions::integral_band_deg).
constexpr double kIntegralBandDeg = 3.0;

ControllerOptions TuneController(ActuatorModel* model, const ControllerOptions& base,
                                 double frame_period_s, std::optional<double> closed_loop_s) {
  const ActuatorModel& m = *model;
  const double k = m.slope_deg_per_kpa;
  // The two lags by the half rule.
  const double tau1 = std::max(m.lag_s, m.pressure_lag_s);
  const double tau2 = std::min(m.lag_s, m.pressure_lag_s);
  const double tau = std::max(1e-3, tau1 + 0.5 * tau2);
  const double theta =
      m.dead_time_s + m.pressure_dead_time_s + 0.5 * tau2 + 0.5 * frame_period_s;
  // Tight control (SIMC's tau_c = theta) on the measured dead times (not the share of the smaller
  // lag the half rule moves into theta), but no faster than three camera periods: the loop sees
  // the actuator only once per frame.
  const double measured_dead_s =
      m.dead_time_s + m.pressure_dead_time_s + 0.5 * frame_period_s;
  // Behind a tube the board's loop runs on the probe's gentle gains (no faster than the tube
  // lets it, and saturating on large steps): the outer loop is no faster than that inner loop.
  const double inner_s = m.valve_dead_time_s > kShortTubeS ? 3.0 * m.pressure_lag_s : 0.0;
  const double tau_c = closed_loop_s.value_or(
      std::max({measured_dead_s, 3.0 * frame_period_s, inner_s}));
  model->closed_loop_s = tau_c;
  ControllerOptions c = base;
  c.kp_kpa_per_deg = std::clamp(tau / (k * (tau_c + theta)), 0.0, 100.0);
  const double tau_i = std::min(tau, 4.0 * (tau_c + theta));
  c.ki_kpa_per_deg_s = std::clamp(c.kp_kpa_per_deg / tau_i, 0.0, 1000.0);
  c.kd_kpa_s_per_deg = 0.0;
  // The feed-forward is written against 180 deg: the pressure for a target a is
  // bend_start + (straight - a) / K = [bend_start - (180 - straight) / K] + (180 - a) / K.
  c.bias_kpa = m.bend_start_kpa - (180.0 - m.straight_deg) / k;
  c.integral_band_deg = kIntegralBandDeg;
  c.ff_kpa_per_deg = std::min(100.0, 1.0 / k);
  c.hysteresis_kpa = std::min(100.0, m.hysteresis_deg / k);
  // The inverse of the two lags (1 + tau1 s)(1 + tau2 s) and, to first order, of the dead times.
  c.ff_lead_s = std::min(10.0, m.lag_s + m.pressure_lag_s + m.dead_time_s + m.pressure_dead_time_s);
  c.ff_lead2_s2 = std::min(100.0, m.lag_s * m.pressure_lag_s);
  // The slew limit must not be the slowest part of the loop: the setpoint may cross the whole
  // output range in two closed-loop times, or the loop is no faster than the ramp (the config's
  // gentle 60 kPa/s held a 40 deg step to ~0.7 s and left the lead to the integral, which then
  // overshot). A gentler loop: a longer closed-loop time (--closed-loop-s).
  c.max_rate_kpa_per_s = std::clamp((c.max_kpa - c.min_kpa) / (2.0 * tau_c), 1.0, 1000.0);
  // The model-based loop runs on the model; the PI above is what the config holds for
  // model_inverse: false. It corrects the model's error over the closed-loop time.
  c.model_inverse = true;
  c.model_correction_s = std::clamp(tau_c, 0.001, 10.0);
  // Its setpoint leads the pressure by up to 1/g at full duty (the error at which the board's
  // duty saturates) and must come back in one frame when the model says stop, on top of the
  // pressure's own rate: a slower slew limit would hold it on (overshoot).
  if (m.pressure_duty_per_kpa > 0.0) {
    const double swing = 1.0 / (m.pressure_duty_per_kpa * frame_period_s) +
                         std::max(m.inflate_kpa_per_s, m.vent_kpa_per_s);
    c.max_rate_kpa_per_s = std::clamp(std::max(c.max_rate_kpa_per_s, swing), 1.0, 1000.0);
  }
  return c;
}

}  // namespace softsight
