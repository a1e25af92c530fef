// `control --target-from`: the loop's target from another program, with the checks a profile
// gets: every target in 0..180 deg and within the identified actuator's reach (refused, or with
// --allow-saturation limited to the reach), followed at most as fast as
// controller.target_max_rate_deg_per_s allows, and the actuator vented while the source is
// silent for longer than controller.target_silence_s. Private to the control command.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "softsight/control/actuator_model.h"
#include "stream/target_subscriber.h"

namespace softsight {

struct TargetFeedOptions {
  double silence_s = 0.5;           // ControllerOptions::target_silence_s.
  double max_rate_deg_per_s = 0.0;  // ControllerOptions::target_max_rate_deg_per_s (0: unlimited).
  bool allow_saturation = false;    // A target beyond the reach: limited to it, not refused.
  ActuatorModel model;              // Its reach (a model not identified reaches everything).
  double max_kpa = 0.0;             // ControllerOptions::max_kpa, for the reach.
};

// The checks only: what arrived comes from a TargetSubscriber (the caller polls it), so the rules
// are tested without a socket.
class TargetFeed {
 public:
  // `endpoint` names the source in errors and notes.
  TargetFeed(std::string endpoint, TargetFeedOptions options);

  // Before the board is opened, what arrived while waiting (TargetSubscriber::wait, at most
  // `waited_s`): the first target, checked. Throws InputError naming the endpoint when none came
  // or the first was refused (nothing sent to the board yet).
  double first(const ReceivedTargets& arrived, double waited_s);
  // Per frame at `time_s` (the frame's timestamp), with what arrived since the last frame: the
  // target the loop follows now, or nullopt when the source has been silent too long (vent).
  std::optional<double> at(double time_s, const ReceivedTargets& arrived);

  // One line each: targets received and refused, the silences that vented.
  std::vector<std::string> notes() const;
  int64_t vented_frames() const { return vented_frames_; }

 private:
  // The target to use for `deg`, or nullopt (refused: counted, the first reason kept).
  std::optional<double> checked(double deg);
  void take(const ReceivedTargets& received);

  std::string endpoint_;
  TargetFeedOptions options_;
  std::optional<double> requested_deg_;  // The newest accepted target.
  std::optional<double> followed_deg_;   // What the loop follows (rate-limited).
  std::optional<double> last_time_s_;    // The previous frame's time.
  std::optional<double> heard_at_s_;     // Frame time the last message arrived at.
  bool heard_since_last_frame_ = false;
  int64_t received_ = 0, refused_ = 0, malformed_ = 0, limited_ = 0;
  std::string first_refusal_;
  int64_t vented_frames_ = 0, silences_ = 0;
  double longest_silence_s_ = 0.0;
  bool silent_ = false;
};

}  // namespace softsight
