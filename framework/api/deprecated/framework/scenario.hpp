// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/scenario/scenario.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/scenario.hpp\" is deprecated: include \"framework/scenario/scenario.hpp\"")
#include "framework/scenario/scenario.hpp"
