// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/world/world.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/world.hpp\" is deprecated: include \"framework/world/world.hpp\"")
#include "framework/world/world.hpp"
