#include "app/target_feed.h"

#include <algorithm>
#include <cmath>

#include "softsight/core/error.h"
#include "softsight/core/format.h"

namespace softsight {

TargetFeed::TargetFeed(std::string endpoint, TargetFeedOptions options)
    : endpoint_(std::move(endpoint)), options_(std::move(options)) {}

std::optional<double> TargetFeed::checked(double deg) {
  std::string problem;
  // The same range as --target-deg (180 = straight), then the same reach as a profile.
  if (!std::isfinite(deg) || deg < 0.0 || deg > 180.0) {
    problem = ShortNumber(deg) + " deg is not in [0, 180]";
  } else if (const std::optional<std::string> outside =
                 OutsideReach(options_.model, deg, deg, options_.max_kpa)) {
    if (!options_.allow_saturation) {
      problem = *outside;
    } else {
      const ActuatorReach reach = ReachOf(options_.model, options_.max_kpa);
      ++limited_;
      return std::clamp(deg, reach.most_bent_deg, reach.straightest_deg);
    }
  }
  if (problem.empty()) return deg;
  if (refused_ == 0) first_refusal_ = problem;
  ++refused_;
  return std::nullopt;
}

void TargetFeed::take(const ReceivedTargets& received) {
  received_ += received.messages;
  if (received.malformed > 0) {
    if (refused_ == 0) first_refusal_ = received.first_problem;
    refused_ += received.malformed;
    malformed_ += received.malformed;
  }
  // Any message, even a refused one, says the source is alive; only a good one moves the target.
  if (received.messages > 0) heard_since_last_frame_ = true;
  if (received.newest_deg) {
    if (const std::optional<double> deg = checked(*received.newest_deg)) requested_deg_ = deg;
  }
}

double TargetFeed::first(const ReceivedTargets& arrived, double waited_s) {
  take(arrived);
  if (!arrived.newest_deg) {
    throw InputError("--target-from " + endpoint_ + ": no target within " + ShortNumber(waited_s) +
                     " s (--target-wait-s)" +
                     (arrived.malformed > 0 ? "; " + std::to_string(arrived.malformed) +
                                                  " malformed messages, the first " +
                                                  arrived.first_problem
                                            : std::string()) +
                     "; nothing sent to the board");
  }
  if (!requested_deg_) {
    throw InputError("--target-from " + endpoint_ + ": the first target: " + first_refusal_ +
                     "; nothing sent to the board");
  }
  return *requested_deg_;
}

std::optional<double> TargetFeed::at(double time_s, const ReceivedTargets& arrived) {
  take(arrived);
  if (!heard_at_s_ || heard_since_last_frame_) heard_at_s_ = time_s;
  heard_since_last_frame_ = false;
  const double dt = last_time_s_ ? std::max(0.0, time_s - *last_time_s_) : 0.0;
  last_time_s_ = time_s;

  const double silence_s = time_s - *heard_at_s_;
  if (silence_s > options_.silence_s) {
    if (!silent_) ++silences_;
    silent_ = true;
    longest_silence_s_ = std::max(longest_silence_s_, silence_s);
    ++vented_frames_;
    followed_deg_.reset();  // Speaking again starts from the new target, not a stale ramp.
    return std::nullopt;
  }
  silent_ = false;
  if (!requested_deg_) return std::nullopt;  // Nothing accepted yet (wait_first says why).
  if (!followed_deg_ || options_.max_rate_deg_per_s <= 0.0) {
    followed_deg_ = requested_deg_;
  } else {
    const double step = options_.max_rate_deg_per_s * dt;
    followed_deg_ = *followed_deg_ + std::clamp(*requested_deg_ - *followed_deg_, -step, step);
  }
  return followed_deg_;
}

std::vector<std::string> TargetFeed::notes() const {
  std::vector<std::string> notes;
  std::string line = "--target-from " + endpoint_ + ": " + std::to_string(received_) +
                     " target messages";
  if (refused_ > 0) {
    line += ", " + std::to_string(refused_) + " refused (kept the previous target; the first: " +
            first_refusal_ + ")";
  }
  if (limited_ > 0) {
    line += ", " + std::to_string(limited_) + " limited to the actuator's reach (--allow-saturation)";
  }
  notes.push_back(line);
  if (vented_frames_ > 0) {
    notes.push_back("--target-from: the source went silent " + std::to_string(silences_) +
                    " times for more than " + ShortNumber(options_.silence_s) +
                    " s (controller.target_silence_s), longest " +
                    FixedNumber(longest_silence_s_, 2) + " s: vented in " +
                    std::to_string(vented_frames_) + " frames");
  }
  return notes;
}

}  // namespace softsight
