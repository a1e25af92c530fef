#include "io/control_config.h"

#include "softsight/core/error.h"
#include "softsight/io/control_config.h"

namespace softsight {
namespace {

void Read(YamlMap& map, const std::string& key, double min, double max, double* value) {
  if (const auto v = map.number(key, min, max)) *value = *v;
}

void ReadInt(YamlMap& map, const std::string& key, int min, int max, int* value) {
  if (const auto v = map.integer(key, min, max)) *value = *v;
}

// kPa in the file, integer Pa on the board.
void ReadPa(YamlMap& map, const std::string& key, double min_kpa, double max_kpa, int32_t* pa) {
  if (const auto v = map.number(key, min_kpa, max_kpa)) *pa = static_cast<int32_t>(*v * 1e3 + 0.5);
}

void ReadController(YamlMap& m, ControllerOptions* c) {
  Read(m, "kp_kpa_per_deg", 0, 100, &c->kp_kpa_per_deg);
  Read(m, "ki_kpa_per_deg_s", 0, 1000, &c->ki_kpa_per_deg_s);
  Read(m, "kd_kpa_s_per_deg", 0, 100, &c->kd_kpa_s_per_deg);
  Read(m, "derivative_filter_s", 0, 10, &c->derivative_filter_s);
  Read(m, "bias_kpa", -100, 1000, &c->bias_kpa);
  Read(m, "ff_kpa_per_deg", 0, 100, &c->ff_kpa_per_deg);
  Read(m, "min_kpa", 0, 1000, &c->min_kpa);
  Read(m, "max_kpa", 0, 1000, &c->max_kpa);
  Read(m, "max_rate_kpa_per_s", 0, 100000, &c->max_rate_kpa_per_s);
  Read(m, "hold_s", 0, 60, &c->hold_s);
  m.finish();
}

void ReadLink(YamlMap& m, LinkOptions* l) {
  if (const auto baud = m.choice("baud", {"9600", "19200", "38400", "57600", "115200", "230400"})) {
    l->baud = std::stoi(*baud);
  }
  ReadInt(m, "reply_timeout_ms", 5, 10000, &l->reply_timeout_ms);
  ReadInt(m, "retries", 0, 10, &l->retries);
  m.finish();
}

void ReadBoard(YamlMap& m, BoardConfig* b) {
  ReadPa(m, "pressure_limit_kpa", 1, 1000, &b->pressure_limit_pa);
  ReadPa(m, "guard_margin_kpa", 0, 100, &b->guard_margin_pa);
  ReadPa(m, "guard_release_kpa", 0, 100, &b->guard_release_pa);
  ReadPa(m, "deadband_kpa", 0, 100, &b->deadband_pa);
  if (const auto v = m.integer("loop_hz", 200, 5000)) b->loop_hz = static_cast<uint16_t>(*v);
  if (const auto v = m.integer("watchdog_ms", 10, 10000)) b->watchdog_ms = static_cast<uint16_t>(*v);
  if (const auto v = m.number("kp_per_kpa", 0, 1000)) b->kp_per_kpa = static_cast<float>(*v);
  if (const auto v = m.number("ki_per_kpa_s", 0, 1000)) b->ki_per_kpa_s = static_cast<float>(*v);
  m.finish();
}

void ReadPlant(YamlMap& m, PlantOptions* p) {
  Read(m, "chamber_volume_ml", 0.1, 10000, &p->chamber_volume_ml);
  Read(m, "pump_flow_l_per_min", 0, 1000, &p->pump_flow_l_per_min);
  Read(m, "pump_stall_kpa", 1, 10000, &p->pump_stall_kpa);
  Read(m, "vent_flow_l_per_min", 0.001, 1000, &p->vent_flow_l_per_min);
  Read(m, "leak_l_per_min", 0, 1000, &p->leak_l_per_min);
  Read(m, "bend_start_kpa", 0, 1000, &p->bend_start_kpa);
  Read(m, "bend_deg_per_kpa", 0.001, 1000, &p->bend_deg_per_kpa);
  Read(m, "max_bend_deg", 1, 340, &p->max_bend_deg);
  Read(m, "bend_lag_s", 0.001, 100, &p->bend_lag_s);
  Read(m, "hysteresis_deg", 0, 90, &p->hysteresis_deg);
  m.finish();
}

void ReadRig(YamlMap& m, RigOptions* r) {
  if (m.has("board")) {
    YamlMap board = m.map("board");
    ReadBoard(board, &r->board);
  }
  if (m.has("plant")) {
    YamlMap plant = m.map("plant");
    ReadPlant(plant, &r->plant);
  }
  Read(m, "end_marker_span", 0.01, 1.0, &r->end_marker_span);
  Read(m, "sensor_noise_kpa", 0, 100, &r->sensor_noise_kpa);
  if (const auto seed = m.integer("seed", 0, 1 << 30)) r->seed = static_cast<uint64_t>(*seed);
  m.finish();
}

}  // namespace

void ReadControlConfig(YamlMap& control, ControlConfig* config) {
  if (control.has("controller")) {
    YamlMap m = control.map("controller");
    ReadController(m, &config->controller);
  }
  if (control.has("link")) {
    YamlMap m = control.map("link");
    ReadLink(m, &config->link);
  }
  if (control.has("rig")) {
    YamlMap m = control.map("rig");
    ReadRig(m, &config->rig);
  }
  control.finish();
  std::string problem;
  if (!config->Check(&problem)) {
    throw InputError(control.file() + ": " + control.key_path(problem));
  }
}

ControlConfig LoadControlConfig(const std::string& file) {
  const YAML::Node root = LoadYamlFile(file);
  ControlConfig config;
  if (!root.IsDefined() || root.IsNull()) return config;
  YamlMap top(root, file, "");
  if (top.has("control")) {
    YamlMap control = top.map("control");
    ReadControlConfig(control, &config);
  }
  return config;
}

}  // namespace softsight
