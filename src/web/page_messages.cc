#include "web/page_messages.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace softsight {
namespace {

using Json = nlohmann::json;
using Kind = PageCommand::Kind;

struct TypeInfo {
  const char* name;
  Kind kind;
  std::set<std::string> fields;  // Besides "type".
};

const std::vector<TypeInfo>& Types() {
  static const std::vector<TypeInfo> kTypes = {
      {"play", Kind::kPlay, {}},           {"pause", Kind::kPause, {}},
      {"step", Kind::kStep, {"delta"}},    {"seek", Kind::kSeek, {"position"}},
      {"speed", Kind::kSpeed, {"value"}},  {"pick", Kind::kPick, {"x", "y"}},
      {"select", Kind::kSelect, {"x", "y", "w", "h"}},
      {"method", Kind::kMethod, {}},       {"undo", Kind::kUndo, {}},
      {"marker", Kind::kMarker, {"index"}}, {"save", Kind::kSave, {"name"}},
      {"record", Kind::kRecord, {}},       {"reset_reference", Kind::kResetReference, {}},
      {"ping", Kind::kPing, {"t"}},        {"take_control", Kind::kTakeControl, {}},
      {"rig_run", Kind::kRigRun, {"target_deg"}},
      {"rig_profile", Kind::kRigProfile, {"text"}},
      {"rig_stop", Kind::kRigStop, {}},
      {"hsv", Kind::kHsv, {"index", "value"}},
      {"mask_view", Kind::kMaskView, {"on"}},
      {"load", Kind::kLoad, {"name"}},     {"list_configs", Kind::kListConfigs, {}},
      {"range", Kind::kRange, {"x", "y", "grow"}},
      {"scale", Kind::kScale, {"ax", "ay", "bx", "by", "mm"}},
  };
  return kTypes;
}

// A bound as a person writes it: 299, not 299.0.
std::string Bound(double value) {
  if (value == std::floor(value) && std::abs(value) < 1e15) {
    return std::to_string(static_cast<int64_t>(value));
  }
  return Json(value).dump();
}

// The number in `field`, which must be finite and within [lo, hi].
bool Number(const Json& message, const char* type, const char* field, double lo, double hi,
            double* value, std::string* error) {
  const Json& v = message.at(field);
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    *error = std::string(type) + ": " + field + " must be a number";
    return false;
  }
  *value = v.get<double>();
  if (*value < lo || *value > hi) {
    *error = std::string(type) + ": " + field + " " + v.dump() + " is outside [" + Bound(lo) +
             ", " + Bound(hi) + "]";
    return false;
  }
  return true;
}

// The integer in `field` (a number with no fraction) within [lo, hi].
bool Integer(const Json& message, const char* type, const char* field, int64_t lo, int64_t hi,
             int64_t* value, std::string* error) {
  double number = 0;
  if (!Number(message, type, field, static_cast<double>(lo), static_cast<double>(hi), &number,
              error)) {
    return false;
  }
  if (number != std::floor(number)) {
    *error = std::string(type) + ": " + field + " must be a whole number";
    return false;
  }
  *value = static_cast<int64_t>(number);
  return true;
}

bool NeedFrame(const PageLimits& limits, const char* type, std::string* error) {
  if (limits.frame_size.area() > 0) return true;
  *error = std::string(type) + ": no frame yet";
  return false;
}

// A point of the frame (x, y). Pixel centres are at integers: the image spans -0.5 .. size - 0.5.
bool ReadPoint(const Json& m, const char* type, const PageLimits& limits, PageCommand* c,
               std::string* error) {
  const double w = limits.frame_size.width, h = limits.frame_size.height;
  return NeedFrame(limits, type, error) && Number(m, type, "x", 0, w - 1, &c->point_px.x, error) &&
         Number(m, type, "y", 0, h - 1, &c->point_px.y, error);
}

// A box of at least 3 x 3 pixels inside the frame (x, y, w, h).
bool ReadBox(const Json& m, const char* type, const PageLimits& limits, PageCommand* c,
             std::string* error) {
  const double w = limits.frame_size.width, h = limits.frame_size.height;
  int64_t x = 0, y = 0, bw = 0, bh = 0;
  if (!NeedFrame(limits, type, error) || !Integer(m, type, "x", 0, w - 1, &x, error) ||
      !Integer(m, type, "y", 0, h - 1, &y, error) || !Integer(m, type, "w", 3, w - x, &bw, error) ||
      !Integer(m, type, "h", 3, h - y, &bh, error)) {
    return false;
  }
  c->box_px = cv::Rect(static_cast<int>(x), static_cast<int>(y), static_cast<int>(bw),
                       static_cast<int>(bh));
  return true;
}

// Two points of the frame and the distance between them in mm. A distance of 0 (or a negative
// one) is no scale; a million mm is a kilometre.
bool ReadScale(const Json& m, const char* type, const PageLimits& limits, PageCommand* c,
               std::string* error) {
  const double w = limits.frame_size.width, h = limits.frame_size.height;
  if (!NeedFrame(limits, type, error) || !Number(m, type, "ax", 0, w - 1, &c->point_px.x, error) ||
      !Number(m, type, "ay", 0, h - 1, &c->point_px.y, error) ||
      !Number(m, type, "bx", 0, w - 1, &c->point_b_px.x, error) ||
      !Number(m, type, "by", 0, h - 1, &c->point_b_px.y, error) ||
      !Number(m, type, "mm", 0, 1e6, &c->distance_mm, error)) {
    return false;
  }
  if (c->distance_mm <= 0) {
    *error = "scale: mm must be above 0";
    return false;
  }
  return true;
}

// The config's name of a save or a load.
bool ReadConfigName(const Json& m, const TypeInfo& info, PageCommand* c, std::string* error) {
  if (!m.at("name").is_string()) {
    *error = std::string(info.name) + ": name must be a string";
    return false;
  }
  c->name = m.at("name").get<std::string>();
  if (!ValidConfigName(c->name, error)) {
    if (info.kind == Kind::kLoad) error->replace(0, 4, "load");  // "save: ..." -> "load: ...".
    return false;
  }
  return true;
}

// A target profile's text, with the profile file's own checks (its bounds, every angle in
// 0..180): a page's profile is no less checked than a file given to `control --profile`.
bool ReadProfile(const Json& m, PageCommand* c, std::string* error) {
  if (!m.at("text").is_string()) {
    *error = "rig_profile: text must be a string";
    return false;
  }
  try {
    c->profile = TargetProfile::Parse(m.at("text").get<std::string>(), "rig_profile");
  } catch (const std::exception& refused) {
    *error = refused.what();
    return false;
  }
  return true;
}

// The fields of a known type, checked against the run.
bool ReadFields(const Json& m, const TypeInfo& info, const PageLimits& limits, PageCommand* c,
                std::string* error) {
  const char* type = info.name;
  int64_t integer = 0;
  switch (info.kind) {
    case Kind::kStep:
      if (!Integer(m, type, "delta", -1, 1, &integer, error)) return false;
      if (integer == 0) {
        *error = "step: delta must be 1 or -1";
        return false;
      }
      c->delta = static_cast<int>(integer);
      return true;
    case Kind::kSeek: {
      const int64_t last = limits.length ? std::max<int64_t>(0, *limits.length - 1) : INT32_MAX;
      if (!Integer(m, type, "position", 0, last, &integer, error)) return false;
      c->position = integer;
      return true;
    }
    case Kind::kSpeed:
      return Number(m, type, "value", 0.1, 4.0, &c->speed, error);
    case Kind::kPick:
      return ReadPoint(m, type, limits, c, error);
    case Kind::kSelect:
      return ReadBox(m, type, limits, c, error);
    case Kind::kRange:
      if (!m.at("grow").is_boolean()) {
        *error = "range: grow must be true or false";
        return false;
      }
      c->grow = m.at("grow").get<bool>();
      return ReadPoint(m, type, limits, c, error);
    case Kind::kScale:
      return ReadScale(m, type, limits, c, error);
    case Kind::kMarker:
      if (!Integer(m, type, "index", 0, std::max(0, limits.markers - 1), &integer, error)) {
        return false;
      }
      c->marker = static_cast<int>(integer);
      return true;
    case Kind::kSave:
    case Kind::kLoad:
      return ReadConfigName(m, info, c, error);
    case Kind::kPing:
      return Number(m, type, "t", 0, 1e15, &c->page_time_ms, error);
    case Kind::kRigRun:
      return Number(m, type, "target_deg", 0, 180, &c->target_deg, error);
    case Kind::kHsv: {
      // Hue is OpenCV's 0..179; a hue range with lo above hi wraps through red (170..10), as
      // in a config: both ends are free within 0..179.
      if (!Integer(m, type, "index", 0, 5, &integer, error)) return false;
      c->hsv_index = static_cast<int>(integer);
      if (!Integer(m, type, "value", 0, c->hsv_index < 2 ? 179 : 255, &integer, error)) return false;
      c->hsv_value = static_cast<int>(integer);
      return true;
    }
    case Kind::kMaskView:
      if (!m.at("on").is_boolean()) {
        *error = "mask_view: on must be true or false";
        return false;
      }
      c->on = m.at("on").get<bool>();
      return true;
    case Kind::kRigProfile:
      return ReadProfile(m, c, error);
    default:
      return true;
  }
}

}  // namespace

bool ChangesTheRun(PageCommand::Kind kind) {
  return kind != Kind::kPing && kind != Kind::kTakeControl && kind != Kind::kRigStop &&
         kind != Kind::kListConfigs;
}

bool ValidConfigName(std::string_view name, std::string* error) {
  constexpr std::string_view kSuffix = ".yaml";
  bool plain = !name.empty() && name.size() <= 64 && name.front() != '.';
  for (const char ch : name) {
    plain = plain && (std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '_' ||
                      ch == '-' || ch == '.');
  }
  if (!plain || name.size() <= kSuffix.size() ||
      name.substr(name.size() - kSuffix.size()) != kSuffix) {
    *error = "save: \"" + std::string(name.substr(0, 64)) +
             "\" is not a config name (letters, digits, _ - . ending in .yaml; no folders)";
    return false;
  }
  return true;
}

std::optional<PageCommand> ParsePageCommand(std::string_view text, const PageLimits& limits,
                                            std::string* error) {
  if (text.size() > kMaxPageMessageBytes) {
    *error = "message of " + std::to_string(text.size()) + " bytes refused (at most " +
             std::to_string(kMaxPageMessageBytes) + ")";
    return std::nullopt;
  }
  const Json message = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (message.is_discarded() || !message.is_object()) {
    *error = "message is not a JSON object";
    return std::nullopt;
  }
  if (!message.contains("type") || !message["type"].is_string()) {
    *error = "message has no \"type\"";
    return std::nullopt;
  }
  const std::string type = message["type"].get<std::string>();
  const TypeInfo* info = nullptr;
  for (const TypeInfo& candidate : Types()) {
    if (type == candidate.name) info = &candidate;
  }
  if (info == nullptr) {
    *error = "unknown message type \"" + type.substr(0, 40) + "\"";
    return std::nullopt;
  }
  for (const auto& [key, value] : message.items()) {
    if (key != "type" && info->fields.count(key) == 0) {
      *error = type + ": unknown field \"" + key.substr(0, 40) + "\"";
      return std::nullopt;
    }
  }
  for (const std::string& field : info->fields) {
    if (!message.contains(field)) {
      *error = type + ": missing field \"" + field + "\"";
      return std::nullopt;
    }
  }
  if ((info->kind == Kind::kStep || info->kind == Kind::kSeek) && !limits.seekable) {
    *error = type + ": a camera plays as it comes (no stepping or seeking)";
    return std::nullopt;
  }
  const bool for_rig =
      info->kind == Kind::kRigRun || info->kind == Kind::kRigProfile || info->kind == Kind::kRigStop;
  if (for_rig && !limits.rig) {
    *error = type + ": no rig here (serve --simulate, or --board-port with a board)";
    return std::nullopt;
  }
  if ((info->kind == Kind::kPause || info->kind == Kind::kStep || info->kind == Kind::kSeek) &&
      limits.rig) {
    // A paused run tracks no frame, and the loop steps on every frame: the board's watchdog
    // would vent it behind the page's back; a seek would turn its clock back. STOP is the way
    // to vent.
    *error = type + ": the rig's loop runs on every frame, as it comes (STOP vents the actuator)";
    return std::nullopt;
  }
  PageCommand command;
  command.kind = info->kind;
  if (!ReadFields(message, *info, limits, &command, error)) return std::nullopt;
  return command;
}

}  // namespace softsight
