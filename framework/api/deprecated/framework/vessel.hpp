// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/world/vessel.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/vessel.hpp\" is deprecated: include \"framework/world/vessel.hpp\"")
#include "framework/world/vessel.hpp"
