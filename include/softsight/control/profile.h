// Target angle over time: a fixed angle, or a profile file of segments played one after another
// (docs/control.md). Angles are the paper's angle at the middle marker, in degrees; times in seconds.
//
//   # comments start with '#'
//   start 180          # initial angle (default 180, straight)
//   hold 1             # keep the current angle for 1 s
//   step 120           # jump to 120 deg
//   ramp 150 2         # move linearly to 150 deg over 2 s
//   sine 140 15 0.5 4  # centre 140, amplitude 15 deg, 0.5 Hz, for 4 s (starts at the centre)
//
// After the last segment the target stays at its final value.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace softsight {

class TargetProfile {
 public:
  // Bounds on what a profile may ask, so a tiny file cannot start unbounded work: its text (a
  // hand-written profile is a few hundred bytes), its segments, its length (the same week that
  // bounds --duration-s) and a sine's frequency (far above what a soft actuator follows).
  static constexpr size_t kMaxBytes = 1 << 20;
  static constexpr size_t kMaxSegments = 10000;
  static constexpr double kMaxSeconds = 7 * 86400.0;
  static constexpr double kMaxFrequencyHz = 100.0;

  struct Segment {
    enum class Kind { kHold, kRamp, kSine };
    Kind kind = Kind::kHold;
    double start_s = 0.0;
    double duration_s = 0.0;
    double from_deg = 180.0;  // Value at the segment's start.
    double to_deg = 180.0;    // Ramp end value; sine centre.
    double amplitude_deg = 0.0;
    double frequency_hz = 0.0;
  };

  // A constant target.
  static TargetProfile Constant(double angle_deg);
  // Parses the text format above. `source` names the file in errors. Throws InputError
  // "file:line: problem", also for a profile beyond the bounds above.
  static TargetProfile Parse(std::string_view text, const std::string& source);
  // Reads and parses a profile file; throws InputError naming the file.
  static TargetProfile Load(const std::string& file);

  double at(double time_s) const;
  // The lowest and highest target the profile asks for (a sine's full swing included).
  double lowest_deg() const;
  double highest_deg() const;
  // The same profile with every target limited to [lowest_deg, highest_deg] (a target beyond the
  // actuator's reach, run on purpose: `control --allow-saturation`).
  TargetProfile ClampedTo(double lowest_deg, double highest_deg) const;
  // End of the last segment (0 for a constant target).
  double duration_s() const { return duration_s_; }
  const std::vector<Segment>& segments() const { return segments_; }

 private:
  double unclamped_at(double time_s) const;

  double start_deg_ = 180.0;
  double duration_s_ = 0.0;
  double clamp_lowest_deg_ = 0.0;
  double clamp_highest_deg_ = 180.0;
  std::vector<Segment> segments_;
};

}  // namespace softsight
