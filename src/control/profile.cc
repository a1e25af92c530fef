#include "softsight/control/profile.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "softsight/core/error.h"
#include "softsight/core/format.h"

namespace softsight {
namespace {

constexpr double kMinAngleDeg = 0.0;
constexpr double kMaxAngleDeg = 180.0;

// The words after a segment's keyword, each a finite number; `where` is "file:line: ".
std::vector<double> SegmentNumbers(std::istringstream& words, const std::string& where,
                                   const std::string& keyword) {
  std::vector<double> values;
  std::string word;
  while (words >> word) {
    size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(word, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != word.size() || !std::isfinite(v)) {
      throw InputError(where + keyword + ": '" + word + "' is not a number");
    }
    values.push_back(v);
  }
  return values;
}

void ExpectCount(const std::vector<double>& values, size_t n, const char* usage,
                 const std::string& where, const std::string& keyword) {
  if (values.size() != n) {
    throw InputError(where + keyword + ": expected " + usage + ", got " +
                     std::to_string(values.size()) + " value(s)");
  }
}

double CheckedAngle(double v, const std::string& where, const std::string& keyword) {
  if (v < kMinAngleDeg || v > kMaxAngleDeg) {
    throw InputError(where + keyword + ": angle " + std::to_string(v) +
                     " deg is outside 0..180 (the angle at the middle marker)");
  }
  return v;
}

// A segment's duration, `v`, starting at `t` s into the profile.
double CheckedDuration(double v, double t, const std::string& where, const std::string& keyword) {
  if (!(v > 0.0)) {
    throw InputError(where + keyword + ": duration " + std::to_string(v) + " s must be > 0");
  }
  if (t + v > TargetProfile::kMaxSeconds) {
    throw InputError(where + keyword + ": the profile would last " + ShortNumber(t + v) +
                     " s, longer than a week (" + ShortNumber(TargetProfile::kMaxSeconds) + " s)");
  }
  return v;
}

}  // namespace

TargetProfile TargetProfile::Constant(double angle_deg) {
  TargetProfile p;
  p.start_deg_ = angle_deg;
  return p;
}

TargetProfile TargetProfile::Parse(std::string_view text, const std::string& source) {
  TargetProfile p;
  double t = 0.0;
  double current = 180.0;
  bool started = false;
  std::istringstream lines{std::string(text)};
  std::string line;
  int line_no = 0;
  while (std::getline(lines, line)) {
    ++line_no;
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string keyword;
    if (!(words >> keyword)) continue;
    const std::string where = source + ":" + std::to_string(line_no) + ": ";
    const std::vector<double> values = SegmentNumbers(words, where, keyword);
    const auto expect = [&](size_t n, const char* usage) {
      ExpectCount(values, n, usage, where, keyword);
    };
    const auto angle = [&](double v) { return CheckedAngle(v, where, keyword); };
    const auto duration = [&](double v) { return CheckedDuration(v, t, where, keyword); };
    if (p.segments_.size() >= kMaxSegments) {
      throw InputError(where + "more than " + std::to_string(kMaxSegments) + " segments");
    }
    Segment s;
    s.start_s = t;
    s.from_deg = current;
    if (keyword == "start") {
      expect(1, "'start ANGLE_DEG'");
      if (started) throw InputError(where + "start: must come before every other segment");
      current = p.start_deg_ = angle(values[0]);
      started = true;
      continue;
    } else if (keyword == "hold") {
      expect(1, "'hold SECONDS'");
      s.kind = Segment::Kind::kHold;
      s.duration_s = duration(values[0]);
      s.to_deg = current;
    } else if (keyword == "step") {
      expect(1, "'step ANGLE_DEG'");
      current = angle(values[0]);
      // A step is a zero-length jump: the next segments start from the new value.
      started = true;
      if (p.segments_.empty()) p.start_deg_ = current;
      else p.segments_.push_back({Segment::Kind::kHold, t, 0.0, current, current, 0.0, 0.0});
      continue;
    } else if (keyword == "ramp") {
      expect(2, "'ramp ANGLE_DEG SECONDS'");
      s.kind = Segment::Kind::kRamp;
      s.to_deg = angle(values[0]);
      s.duration_s = duration(values[1]);
      current = s.to_deg;
    } else if (keyword == "sine") {
      expect(4, "'sine CENTRE_DEG AMPLITUDE_DEG FREQUENCY_HZ SECONDS'");
      s.kind = Segment::Kind::kSine;
      s.to_deg = angle(values[0]);
      s.amplitude_deg = values[1];
      if (s.amplitude_deg < 0.0) {
        throw InputError(where + "sine: amplitude " + std::to_string(values[1]) + " must be >= 0");
      }
      angle(s.to_deg - s.amplitude_deg);
      angle(s.to_deg + s.amplitude_deg);
      s.frequency_hz = values[2];
      if (!(s.frequency_hz > 0.0 && s.frequency_hz <= kMaxFrequencyHz)) {
        throw InputError(where + "sine: frequency " + ShortNumber(values[2]) + " Hz must be in (0, " +
                         ShortNumber(kMaxFrequencyHz) + "]");
      }
      s.duration_s = duration(values[3]);
      current = s.to_deg + s.amplitude_deg *
                               std::sin(2.0 * M_PI * s.frequency_hz * s.duration_s);
    } else {
      throw InputError(where + "unknown segment '" + keyword +
                       "' (use start, hold, step, ramp or sine)");
    }
    started = true;
    p.segments_.push_back(s);
    t += s.duration_s;
  }
  if (p.segments_.empty() && !started) {
    throw InputError(source + ": the profile has no segments (e.g. 'step 120' then 'hold 5')");
  }
  p.duration_s_ = t;
  // A trailing step with nothing after it defines the final value.
  if (!p.segments_.empty()) {
    Segment tail;
    tail.kind = Segment::Kind::kHold;
    tail.start_s = t;
    tail.from_deg = tail.to_deg = current;
    p.segments_.push_back(tail);
  } else {
    p.start_deg_ = current;
  }
  return p;
}

TargetProfile TargetProfile::Load(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(EscapeForMessage(file) + ": cannot read the target profile");
  // Read in bounded pieces: /dev/zero or a huge file is refused, not read until memory ends.
  std::string text(kMaxBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(in.gcount()));
  if (text.size() > kMaxBytes) {
    throw InputError(EscapeForMessage(file) + ": larger than " + std::to_string(kMaxBytes >> 20) +
                     " MiB; a target profile is a short text of segments (docs/control.md)");
  }
  if (text.find('\0') != std::string::npos) {
    throw InputError(EscapeForMessage(file) + ": not a text file (it holds NUL bytes)");
  }
  return Parse(text, EscapeForMessage(file));
}

double TargetProfile::at(double time_s) const {
  return std::clamp(unclamped_at(time_s), clamp_lowest_deg_, clamp_highest_deg_);
}

double TargetProfile::lowest_deg() const {
  double lowest = start_deg_;
  for (const Segment& s : segments_) {
    lowest = std::min({lowest, s.from_deg, s.to_deg - s.amplitude_deg});
  }
  return std::clamp(lowest, clamp_lowest_deg_, clamp_highest_deg_);
}

double TargetProfile::highest_deg() const {
  double highest = start_deg_;
  for (const Segment& s : segments_) {
    highest = std::max({highest, s.from_deg, s.to_deg + s.amplitude_deg});
  }
  return std::clamp(highest, clamp_lowest_deg_, clamp_highest_deg_);
}

TargetProfile TargetProfile::ClampedTo(double lowest_deg, double highest_deg) const {
  TargetProfile out = *this;
  out.clamp_lowest_deg_ = std::max(clamp_lowest_deg_, lowest_deg);
  out.clamp_highest_deg_ = std::max(out.clamp_lowest_deg_, std::min(clamp_highest_deg_, highest_deg));
  return out;
}

double TargetProfile::unclamped_at(double time_s) const {
  if (segments_.empty() || time_s < 0.0) return start_deg_;
  // Segments are few (a profile file is written by hand): a linear scan is fine.
  const Segment* active = &segments_.front();
  for (const Segment& s : segments_) {
    if (s.start_s <= time_s) active = &s;
    else break;
  }
  const double u = time_s - active->start_s;
  switch (active->kind) {
    case Segment::Kind::kHold:
      return active->to_deg;
    case Segment::Kind::kRamp:
      if (u >= active->duration_s) return active->to_deg;
      return active->from_deg + (active->to_deg - active->from_deg) * u / active->duration_s;
    case Segment::Kind::kSine:
      return active->to_deg +
             active->amplitude_deg * std::sin(2.0 * M_PI * active->frequency_hz *
                                              std::min(u, active->duration_s));
  }
  return active->to_deg;
}

}  // namespace softsight
