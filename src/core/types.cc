#include "softsight/core/types.h"
#include "softsight/core/error.h"
