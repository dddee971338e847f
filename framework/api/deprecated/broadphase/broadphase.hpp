// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/api/broadphase.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"broadphase/broadphase.hpp\" is deprecated: include \"framework/api/broadphase.hpp\"")
#include "framework/api/broadphase.hpp"
