#include "control/model_loop.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace softsight {
namespace {

constexpr double kStepS = 0.001;  // The model's integration step.

// The side of the play to push on (+1: more bend) for its output to reach `wanted` from `play`;
// `last` when it is there.
double Branch(double wanted, double play, double last) {
  if (wanted > play + 0.01) return 1.0;
  if (wanted < play - 0.01) return -1.0;
  return last;
}

// The setpoint in [lo_kpa, hi_kpa] whose pressure after the frame is `goal` (the nearer end where
// the goal is out of reach), by bisection.
template <typename PressureAfter>
double SetpointFor(double goal, double lo_kpa, double hi_kpa, const PressureAfter& pressure_after) {
  if (pressure_after(hi_kpa) <= goal) return hi_kpa;
  if (pressure_after(lo_kpa) >= goal) return lo_kpa;
  double lo = lo_kpa, hi = hi_kpa;
  for (int i = 0; i < 30 && hi - lo > 1e-4; ++i) {
    const double mid = 0.5 * (lo + hi);
    (pressure_after(mid) < goal ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

ModelLoop::ModelLoop(const ActuatorModel& m, double vent_scale, const ControllerOptions& options)
    : straight_(m.straight_deg),
      p0_(m.bend_start_kpa),
      k_(m.slope_deg_per_kpa),
      sat_(m.saturation_kpa > 0.0 ? m.saturation_kpa : std::numeric_limits<double>::infinity()),
      half_(0.5 * m.hysteresis_deg),
      tau_b_(std::max(1e-3, m.lag_s)),
      theta_b_(m.dead_time_s),
      g_(m.pressure_duty_per_kpa),
      theta_p_(m.pressure_duty_per_kpa > 0.0 ? m.pressure_duty_dead_time_s
                                             : m.pressure_dead_time_s),
      inflate_(m.inflate_kpa_per_s > 0.0 ? m.inflate_kpa_per_s : 1e4),
      vent_((m.vent_kpa_per_s > 0.0 ? m.vent_kpa_per_s : 1e4) * vent_scale),
      vent_at_(m.vent_at_kpa),
      correction_s_(options.model_correction_s),
      max_rate_(options.max_rate_kpa_per_s) {
  assert(m.identified());
  if (!(g_ > 0.0)) {
    // A model from before the duty fit: its linear lag is the inflation's time constant.
    g_ = 1.0 / (std::max(1e-3, m.pressure_lag_s) * inflate_);
  }
}

void ModelLoop::reset() {
  started_ = false;
  correction_ = 0.0;
  sent_.clear();
  deflection_.clear();
}

double ModelLoop::pressure_rate(double p, double u) const {
  const double duty = std::clamp(g_ * (u - p), -1.0, 1.0);
  if (duty >= 0.0) return duty * inflate_;
  const double scale = vent_at_ > 0.0 ? std::sqrt(std::max(p, 0.05) / vent_at_) : 1.0;
  return duty * vent_ * scale;
}

double ModelLoop::sent_at(double time_s) const {
  double u = initial_u_;
  for (const auto& [t, v] : sent_) {
    if (t > time_s + 1e-9) break;
    u = v;
  }
  return u;
}

template <typename Command>
void ModelLoop::advance(State* s, double to_s, const Command& command) const {
  const double a_full = 1.0 - std::exp(-kStepS / tau_b_);
  while (s->time_s < to_s - 1e-12) {
    const double h = std::min(kStepS, to_s - s->time_s);
    const double a = h == kStepS ? a_full : 1.0 - std::exp(-h / tau_b_);
    const double u = command(s->time_s + 0.5 * h - theta_p_);
    const double next = s->p + h * pressure_rate(s->p, u);
    // Never past the setpoint within a step (the loop's duty is 0 there).
    s->p = std::max(0.0, (next - u) * (s->p - u) < 0.0 ? u : next);
    const double bend = k_ * (std::clamp(s->p, p0_, std::max(p0_, sat_)) - p0_);
    s->play = std::clamp(s->play, bend - half_, bend + half_);
    s->d += a * (s->play - s->d);
    s->time_s += h;
  }
}

double ModelLoop::static_pressure(double deflection_deg, double direction) const {
  return std::max(0.0, std::min(p0_ + (deflection_deg + direction * half_) / k_,
                                std::max(p0_, sat_)));
}

void ModelLoop::observe_pressure(double pressure_kpa) {
  if (started_ && std::isfinite(pressure_kpa)) state_.p = std::max(0.0, pressure_kpa);
}

void ModelLoop::sent(double setpoint_kpa) {
  if (!sent_.empty()) sent_.back().second = setpoint_kpa;
}

// The model advanced to this frame, its error against the measurement (seen through the
// camera's dead time) filtered, and the histories it needs kept short.
void ModelLoop::follow_measurement(double time_s, std::optional<double> measured_deg) {
  const double measured_d = straight_ - measured_deg.value_or(straight_);
  if (!started_) {
    started_ = true;
    state_ = State{};
    state_.time_s = time_s;
    state_.d = state_.play = std::max(0.0, measured_d);
    state_.p = measured_d > 0.5 ? static_pressure(measured_d, 0.0) : 0.0;
    initial_u_ = state_.p;
    correction_ = 0.0;
    direction_ = 1.0;
  } else {
    const double dt = time_s - state_.time_s;
    if (dt > 1e-6 && dt < 1.0) frame_s_ = dt;
    advance(&state_, time_s, [this](double t) { return sent_at(t); });
    // The model error: the measured deflection against the model's, seen through the camera's
    // dead time.
    double seen_d = state_.d;
    for (auto it = deflection_.rbegin(); it != deflection_.rend(); ++it) {
      if (it->first <= time_s - theta_b_ + 1e-9) {
        seen_d = it->second;
        break;
      }
    }
    if (theta_b_ <= 0.0) seen_d = state_.d;
    // Without a measurement (markers lost for a moment) the model runs on, its error frozen.
    if (measured_deg) {
      const double a = 1.0 - std::exp(-std::max(0.0, dt) / correction_s_);
      correction_ += a * ((measured_d - seen_d) - correction_);
    }
  }
  deflection_.emplace_back(time_s, state_.d);
  while (deflection_.size() > 2 && deflection_[1].first < time_s - theta_b_ - 1.0) {
    deflection_.pop_front();
  }
  while (sent_.size() > 1 && sent_[1].first < time_s - theta_p_ - 1.0) {
    initial_u_ = sent_.front().second;
    sent_.pop_front();
  }
}

double ModelLoop::update(double time_s, std::optional<double> measured_deg, double target_deg,
                         const AngleController::Preview& preview, double lo_kpa,
                         double hi_kpa) {
  follow_measurement(time_s, measured_deg);

  const double frame = frame_s_;
  const double look = theta_p_ + theta_b_;  // What a setpoint sent now takes to be seen.
  // The deflection wanted at absolute time t, the model error taken off.
  const auto wanted = [&](double t) {
    const double target = preview ? preview(t - time_s) : target_deg;
    return straight_ - target - correction_;
  };
  const double hd = 0.5 * frame;
  const auto led = [&](double t) {
    return wanted(t) + tau_b_ * (wanted(t + hd) - wanted(t - hd)) / (2.0 * hd);
  };

  const double reach_t = time_s + frame + look;
  const double gap = wanted(time_s) - state_.d;

  // The model when this frame's setpoint starts to act.
  State acting = state_;
  advance(&acting, time_s + theta_p_, [this](double t) { return sent_at(t); });
  // What the lag is to be fed: the led target, plus the model's own gap to the target closed
  // over three frames or twice the dead times (the lag alone would close it over its time
  // constant: a laggy bend left behind where it could not relax fast enough stayed behind for a
  // half cycle).
  const double catch_up_s = std::max(3.0 * frame, 2.0 * look);
  const double behind = wanted(time_s + theta_p_ + theta_b_) - acting.d;
  const double aim = led(reach_t) + tau_b_ * behind / catch_up_s;
  // The hysteresis branch: the play's output must move towards that, so its input is half the
  // width beyond it that way (the play operator's exact inverse).
  direction_ = Branch(aim, acting.play, direction_);
  const auto pressure_after = [&](double u) {
    State s = acting;
    advance(&s, time_s + theta_p_ + frame, [u](double) { return u; });
    return s.p;
  };

  double setpoint = 0.0;
  bool full = false;
  if (std::abs(gap) > kJumpDeg) {
    // Catching up with a step: full pressure (or none) this frame, if switching to the target's
    // pressure next frame leaves no overshoot in the model.
    const double dir = gap > 0.0 ? 1.0 : -1.0;
    // Full duty through the frame, the setpoint no further than that from the pressure (1/g: the
    // error at which the loop's duty saturates), so that switching back takes one frame.
    const double bang =
        dir > 0.0 ? std::min(hi_kpa, pressure_after(hi_kpa) + 1.0 / g_)
                  : std::max(lo_kpa, pressure_after(lo_kpa) - 1.0 / g_);
    State s = state_;
    double last = bang;
    double last_t = time_s + frame;
    double branch = dir;
    const auto command = [&](double t) {
      if (t < time_s) return sent_at(t);
      if (t < time_s + frame) return bang;
      const double bend = wanted(t + look);
      branch = Branch(bend, s.play, branch);
      const double want = static_pressure(bend, branch);
      if (max_rate_ > 0.0) {
        const double step = max_rate_ * std::max(0.0, t - last_t);
        last = std::clamp(want, last - step, last + step);
      } else {
        last = want;
      }
      last_t = t;
      return last;
    };
    const double horizon = std::min(3.0, 4.0 * tau_b_ + 0.3) + look;
    double over = -std::numeric_limits<double>::infinity();
    const double end = time_s + frame + horizon;
    for (double t = time_s; t < end;) {
      const double next = std::min(end, t + 0.01);
      advance(&s, next, command);
      t = next;
      if (t >= time_s + frame) over = std::max(over, dir * (s.d - wanted(t + theta_b_)));
    }
    if (over <= kOvershootDeg) {
      setpoint = bang;
      full = true;
    }
  }
  if (!full) {
    const double goal = std::max(0.0, std::min(p0_ + (aim + direction_ * half_) / k_,
                                               std::max(p0_, sat_)));
    setpoint = SetpointFor(goal, lo_kpa, hi_kpa, pressure_after);
  }
  sent_.emplace_back(time_s, setpoint);
  return setpoint;
}

}  // namespace softsight
