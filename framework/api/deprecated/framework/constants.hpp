// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/world/constants.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/constants.hpp\" is deprecated: include \"framework/world/constants.hpp\"")
#include "framework/world/constants.hpp"
