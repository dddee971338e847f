// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/api/device_broadphase.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/cuda/device_broadphase.hpp\" is deprecated: include \"framework/api/device_broadphase.hpp\"")
#include "framework/api/device_broadphase.hpp"
