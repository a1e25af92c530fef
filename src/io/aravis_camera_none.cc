// A build without Aravis (CMake found no aravis-0.8): `--camera aravis:...` and the listing say
// so in one line, and everything else works as before.
#include "io/aravis_camera.h"

#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr char kNoAravis[] =
    ": this build has no Aravis support (install libaravis-dev, then configure and build again)";

}  // namespace

std::unique_ptr<FrameSource> OpenAravisCamera(const CameraId& id, const CameraSettings&,
                                              CameraSettingsReport*) {
  throw InputError("camera " + id.text() + kNoAravis);
}

void SetFakeCameraPainter(FakeCameraPainter) {}

bool HaveAravisSupport() { return false; }

std::vector<std::string> ListAravisCameras() { throw InputError(std::string("aravis:") + kNoAravis); }

}  // namespace softsight
