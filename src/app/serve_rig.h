// The rig behind `softsight serve --simulate` / `--board-port` (private to the serve command):
// the board (the simulated rig on a real pseudo-terminal, as `control --simulate`, or a device),
// the link and the control session, shaken hands and idle (vented), and the rig's control panel
// (web/rig_panel.h) that pages drive. With --simulate, also the rig's camera: the simulated rig
// rendered at the wall clock's pace, as a live camera.
#pragma once

#include <iosfwd>
#include <memory>
#include <optional>
#include <string>

#include "softsight/config/config.h"
#include "softsight/control/board_link.h"
#include "softsight/control/rig.h"
#include "softsight/control/session.h"
#include "softsight/control/transport.h"
#include "softsight/io/frame_source.h"
#include "softsight/sim/scene.h"
#include "web/rig_panel.h"

namespace softsight {

struct ServeRigArgs {
  bool simulate = false;
  std::optional<std::string> board_port;  // A board's serial device.
  double fps = 30.0;                      // The simulated rig's camera.
};

// Declared in the order they are made: destroyed the other way round, so the panel goes first
// and the session vents (STOP) before the link and the board go.
struct ServeRig {
  std::unique_ptr<SimulatedRig> rig;  // --simulate.
  std::unique_ptr<RigServer> rig_server;
  std::unique_ptr<SyntheticScene> scene;
  std::unique_ptr<Transport> transport;
  std::unique_ptr<BoardLink> link;
  std::unique_ptr<ControlSession> session;
  std::unique_ptr<RigPanel> panel;
};

// The config a person would write for the simulated rig's scene (markers and no `control:`
// section: the defaults), written once to <folder>/rig-simulated.yaml and kept; its path.
std::string ConfigForSimulatedRig(const std::string& folder, double fps);

// Opens the board and shakes hands (the board's limit bounds the host's max_kpa); says what it
// opened on `out`. Throws InputError (a bad `control:` section, no board answering) with nothing
// left open.
std::unique_ptr<ServeRig> OpenServeRig(const ServeRigArgs& args, const TrackingConfig& config,
                                       std::ostream& out);

// The simulated rig's camera (--simulate): each frame renders the rig's bend, then the rig
// advances one frame period (lock-step, as `control --simulate`); the run paces it to the wall
// clock at `fps` as it paces a file, so pages and a person pressing STOP see real time. It
// cannot step or seek, and with the rig's panel pages cannot pause it.
std::unique_ptr<FrameSource> SimulatedRigCamera(ServeRig& rig, double fps);

}  // namespace softsight
