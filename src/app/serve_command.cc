// softsight serve: the live bench in a browser (src/web): a camera, a video or a rendered scene
// tracked as `live` tracks it, watched and tuned from any number of pages, one in control.
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "app/capture_options.h"
#include "app/commands.h"
#include "app/python_hook.h"
#include "app/scene_config.h"
#include "app/serve_rig.h"
#include "app/shared_flags.h"
#include "app/stop_request.h"
#include "softsight/config/config.h"
#include "softsight/core/error.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/track/tracker.h"
#include "web/access.h"
#include "web/serve_run.h"

namespace softsight {
namespace {

struct ServeArgs {
  std::optional<CameraId> camera;
  std::string input;
  std::string compare;  // A second video beside the first (--compare).
  std::string config;
  std::optional<std::string> method;
  std::string bind = "127.0.0.1";
  int port = 8090;
  std::string folder = ".";
  std::string record_prefix = "serve";
  int jpeg_quality = 80;
  bool no_pace = false;
  CaptureArgs capture;
  ServeRigArgs rig;
  HookArgs hook;
};

int RunServeCommand(ServeArgs args) {
  // A rendered scene brings the config a person would write for it: `serve --input
  // synth:bending` alone opens a page with markers to watch and tune.
  std::error_code error;
  if (!std::filesystem::is_directory(args.folder, error)) {
    throw InputError("--folder " + args.folder + " is not a folder");
  }
  // The rig's loop steps on every frame, on the frames' clock: frames that come live and in
  // order (the simulated rig's own camera, or a camera), never a file that pauses or seeks.
  if (args.rig.simulate && (args.camera || !args.input.empty())) {
    throw InputError("serve --simulate renders the simulated rig's own frames: no --camera or --input");
  }
  if (!args.compare.empty() && args.input.empty()) {
    throw InputError("--compare needs --input (a file served: a camera cannot seek to the same position)");
  }
  if (args.rig.board_port && !args.camera) {
    throw InputError("serve --board-port needs --camera: the loop runs on live frames");
  }
  if (args.config.empty()) {
    args.config = args.rig.simulate ? ConfigForSimulatedRig(args.folder, args.rig.fps)
                                    : ConfigForBuiltinInput(args.input, args.folder);
  }
  TrackingConfig config = LoadTrackingConfig(args.config, args.method);
  ServeOptions options;
  options.folder = std::filesystem::canonical(args.folder);
  options.config_path = args.config;
  options.pace_files = !args.no_pace;
  options.jpeg_quality = args.jpeg_quality;
  options.live.record_prefix = (options.folder / args.record_prefix).string();
  options.server.bind = args.bind;
  options.server.port = args.port;
  // Off this computer's loopback anyone on the network could reach the rig: a token, printed
  // in the URL, is then asked of every request.
  if (!IsLoopbackAddress(args.bind)) options.server.token = NewAccessToken();
  if (std::string problem; !options.live.Check(&problem)) throw InputError(problem);

  std::unique_ptr<ServeRig> rig;
  if (args.rig.simulate || args.rig.board_port) {
    rig = OpenServeRig(args.rig, config, std::cout);
    options.rig = rig->panel.get();
  }
  FrameSourceSpec spec;
  std::unique_ptr<FrameSource> source =
      args.rig.simulate
          ? SimulatedRigCamera(*rig, args.rig.fps)
          : OpenLiveSource(args.camera, args.input, args.capture, args.config, config, &spec);
  FrameSourceOpener reopen;
  if (!args.compare.empty()) {
    FrameSourceSpec compare_spec;
    compare_spec.input = args.compare;
    compare_spec.sequence_fps = spec.sequence_fps;
    OpenFrameSource(compare_spec);  // Checked now: a missing file is an error before serving.
    options.compare = [compare_spec] { return OpenFrameSource(compare_spec); };
  }
  // A file can be opened again to seek in it; the simulated rig's frames cannot (nor a camera's).
  if (!source->is_live() && !args.rig.simulate) reopen = [spec] { return OpenFrameSource(spec); };
  // The hook first among the sinks: the page and the recordings show its columns.
  const std::unique_ptr<CommandHook> hook =
      CommandHook::Open(args.hook, source->is_live(), TrackingColumns(config), std::cerr);
  if (hook) {
    options.live.sinks.push_back(&hook->sink());
    options.live.extra_columns = hook->columns();
  }
  StopRequest stop;
  LiveRunResult run = RunServe(config, std::move(source), options, reopen,
                               [&stop] { return stop.requested(); }, std::cout);
  if (hook) {  // The run does not end the program's sinks: the hook ends here, with its summary.
    hook->sink().end(run.summary.run);
    hook->sink().report(run.summary.run);
  }
  std::cerr << run.summary.Report();
  if (!run.last_recording.empty()) {
    std::cerr << "softsight serve: last recording " << run.last_recording << ".*\n";
  }
  return ExitCodeAfterStop(0);
}

const FlagTable<ServeArgs>& ServeFlags() {
  using A = ServeArgs;
  static const FlagTable<ServeArgs> table = {
      CameraFlag<A>("--camera", &A::camera, "The camera"),
      ValueFlag<A>(kInputFlag, &A::input)
          .Help("Video file, image sequence or synth:NAME instead of a camera")
          .Excludes("--camera"),
      ValueFlag<A>("--compare", &A::compare)
          .Help("A second video shown beside --input's, frame by frame at the same position "
                "(two runs side by side in sync; the page's compare opens its CSV)"),
      ValueFlag<A>(kConfigFlag, &A::config)
          .Help("Marker configuration (YAML, see examples/); a synth: input without one uses "
                "the scene's own, written to <folder>/synth-NAME.yaml"),
      MethodFlag<A>(&A::method),
      ValueFlag<A>("--bind", &A::bind)
          .Help("Address to listen on; any but loopback requires the printed token")
          .ShowDefault(),
      ValueFlag<A>("--port", &A::port)
          .Help("TCP port; 0 picks a free one (the URL says which)")
          .Check(CLI::Range(0, 65535))
          .ShowDefault(),
      ValueFlag<A>("--folder", &A::folder)
          .Help("The only folder pages save configs and recordings in")
          .ShowDefault(),
      RecordPrefixFlag<A>(&A::record_prefix, "<folder>/"),
      ValueFlag<A>("--jpeg-quality", &A::jpeg_quality)
          .Help("Quality of the frames sent, 1-100")
          .Check(CLI::Range(1, 100))
          .ShowDefault(),
      NoPaceFlag<A>([](A& a) { a.no_pace = true; }),
      SwitchFlag<A>("--simulate", [](A& a) -> auto& { return a.rig.simulate; })
          .Help("Serve the simulated rig (a board on a pseudo-terminal and its actuator, rendered "
                "in lock-step with the loop at 30 fps, paced to the wall clock): the page's "
                "control panel drives it; the config's `control:` section applies, and without "
                "--config <folder>/rig-simulated.yaml is written and used")
          .Excludes("--camera")
          .Excludes("--input"),
      ValueFlag<A>("--board-port", [](A& a) -> auto& { return a.rig.board_port; })
          .Help("Serial device of a board to control from the page (with --camera): "
                "/dev/ttyACM0, or the /dev/pts/N `softsight rig --pty` prints")
          .Excludes("--simulate"),
  };
  return table;
}

}  // namespace

CommandRunner SetupServeCommand(CLI::App& sub) {
  auto args = std::make_shared<ServeArgs>();
  sub.footer(
      "Serves the live bench as a web page: open the printed URL in a browser (this computer's,\n"
      "or, with --bind 0.0.0.0, any on the network; the URL then carries a token that every\n"
      "request needs). The page shows the frames with the overlay, the measurements, the status\n"
      "(fps, dropped frames, latency), plots of the run against time and, for a file, a timeline\n"
      "to seek. Click a marker to pick its colour, drag a box to reselect it or cut its template;\n"
      "switch method, undo (saying what it undid), record, and save the config into --folder.\n"
      "Several pages may watch; one controls the run at a time, the others are read-only until\n"
      "they take control. Ctrl-C stops the server and prints the run's summary.\n"
      "With a rig (--simulate, or --board-port with --camera) the page has a control\n"
      "panel: a target angle or a profile, run and STOP (any page; it vents at once), the\n"
      "pressure and angle traces, the board's state and the limits. A page that leaves\n"
      "mid-run leaves the rig safe: its last pressure held for hold_s, then vented.\n"
      "Examples: softsight serve --input synth:bending\n"
      "          softsight serve --simulate");
  AddFlags(sub, ServeFlags(), args.get());
  AddFlags(sub, CaptureFlags(), &args->capture);
  AddFlags(sub, HookFlags(), &args->hook);
  return [args] { return RunServeCommand(*args); };
}

}  // namespace softsight
