#include "app/serve_rig.h"

#include <filesystem>
#include <ostream>

#include "app/scene_config.h"
#include "softsight/control/control_config.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

class SimulatedRigCameraSource : public FrameSource {
 public:
  SimulatedRigCameraSource(SimulatedRig& rig, SyntheticScene& scene, double fps)
      : rig_(rig), scene_(scene), fps_(fps) {}

  // Lock-step, as `control --simulate`: each frame renders the rig's bend, then the rig advances
  // one frame period. Paced to the wall clock by the run (a file's pacing, PacedFrameSource);
  // never dropped: a machine too slow for 30 fps slows the simulated world with it, so the
  // tracker sees every frame of the actuator's motion and the frames' clock stays the rig's.
  bool read(Frame& frame) override {
    if (index_ > 0) rig_.advance(1.0 / fps_);
    const double t = static_cast<double>(index_) / fps_;
    scene_.render_at_bend(rig_.snapshot().bend_deg, t, static_cast<int>(index_ % 1000000), frame.image);
    frame.index = index_++;
    frame.time_s = t;
    return true;
  }
  std::string description() const override { return "simulated rig"; }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override { return fps_; }

 private:
  SimulatedRig& rig_;
  SyntheticScene& scene_;
  double fps_;
  int64_t index_ = 0;
};

SceneOptions RigScene(double fps) {
  SceneOptions scene;  // What `control --simulate` renders.
  scene.fps = fps;
  return scene;
}

}  // namespace

std::string ConfigForSimulatedRig(const std::string& folder, double fps) {
  const std::string path = (std::filesystem::path(folder) / "rig-simulated.yaml").string();
  std::error_code error;
  if (!std::filesystem::exists(path, error)) SaveTrackingConfig(ConfigForScene(RigScene(fps)), path);
  return path;
}

std::unique_ptr<ServeRig> OpenServeRig(const ServeRigArgs& args, const TrackingConfig& config,
                                       std::ostream& out) {
  const ControlConfig control = config.control.value_or(ControlConfig{});
  auto rig = std::make_unique<ServeRig>();
  if (args.simulate) {
    rig->rig = std::make_unique<SimulatedRig>(control.rig);
    rig->rig_server = std::make_unique<RigServer>(*rig->rig);
    rig->scene = std::make_unique<SyntheticScene>(RigScene(args.fps), NoiseOptions{}, RenderOptions{});
  }
  const std::string port = rig->rig_server ? rig->rig_server->port() : *args.board_port;
  rig->transport = OpenSerialTransport(port, control.link.baud);
  // No stop request in the link's waits: Ctrl-C ends the serve loop between frames, and the
  // session's destructor vents then; a wait (at most retries x reply_timeout_ms) is never cut.
  rig->link = std::make_unique<BoardLink>(
      *rig->transport, rig->rig_server ? InProcessLinkOptions(control.link) : control.link);
  rig->session = std::make_unique<ControlSession>(control.controller, *rig->link, ControlTarget{});
  rig->session->set_inner_loop_gains(control.inner_loop);
  rig->session->set_model(control.model);
  const BoardInfo info = rig->session->start();
  const std::string name = rig->transport->name() + (args.simulate ? " (simulated rig)" : "");
  rig->panel = std::make_unique<RigPanel>(*rig->session, info, name, control.model);
  const ControllerOptions& c = rig->session->controller().options();
  out << "softsight serve: " << name << ": board protocol " << info.protocol_version
      << ", pressure limit " << info.pressure_limit_kpa << " kPa, watchdog " << info.watchdog_ms
      << " ms; host limits " << c.min_kpa << ".." << c.max_kpa << " kPa, hold " << c.hold_s
      << " s; vented, waiting for a page to run it" << std::endl;
  return rig;
}

std::unique_ptr<FrameSource> SimulatedRigCamera(ServeRig& rig, double fps) {
  if (!rig.rig || !rig.scene) throw InputError("serve: the rig's camera needs --simulate");
  return std::make_unique<SimulatedRigCameraSource>(*rig.rig, *rig.scene, fps);
}

}  // namespace softsight
