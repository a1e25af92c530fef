// Private to the program (app, web). The control loop's sample as CSV columns, under the names
// `softsight control` writes: one table for `control`'s CSV (app/control_parts.h) and for
// serve's rows with a rig (web/rig_panel.h). Here, not in control: it joins control's sample to
// io's column table, and control comes before io in the layers (docs/architecture.md).
#pragma once

#include <optional>
#include <vector>

#include "softsight/control/session.h"
#include "softsight/io/csv_columns.h"

namespace softsight {

// target_deg, setpoint_kpa, board_pressure_kpa, board_setpoint_kpa, duty, board_flags,
// control_action (ControllerOutput::Action as a number): read from `*sample` when a row is
// written, so `sample` (the sample of the row's frame) must outlive the columns. For rows of one
// camera's results (FrameResult) or two cameras' (StereoFrameResult).
template <typename Row = FrameResult>
std::vector<BasicCsvColumn<Row>> ControlSampleColumns(const ControlSample* sample) {
  const auto column = [sample](const char* name, auto value) {
    return NumberColumn<Row>(name, [sample, value](const Row&) -> std::optional<double> {
      return value(*sample);
    });
  };
  using S = const ControlSample&;
  return {
      column("target_deg", [](S s) { return s.target_deg; }),
      column("setpoint_kpa", [](S s) { return s.setpoint_kpa; }),
      column("board_pressure_kpa", [](S s) { return s.board.pressure_kpa; }),
      column("board_setpoint_kpa", [](S s) { return s.board.setpoint_kpa; }),
      column("duty", [](S s) { return s.board.duty; }),
      column("board_flags", [](S s) { return static_cast<double>(s.board.flags); }),
      column("control_action", [](S s) { return static_cast<double>(static_cast<int>(s.action)); }),
  };
}

}  // namespace softsight
