// The shared board code, found where each build puts it: the host build compiles it from the
// repository (src/control/, include/softsight/control/board_config.h); an Arduino build uses the
// copy that firmware/copy_shared.sh places in this sketch's src/ folder.
#pragma once

#include <Arduino.h>

#if defined(SOFTSIGHT_HOST_BUILD)
#include "control/board.h"
#else
#include "src/board.h"
#endif
