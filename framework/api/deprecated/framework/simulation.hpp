// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/step/simulation.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/simulation.hpp\" is deprecated: include \"framework/step/simulation.hpp\"")
#include "framework/step/simulation.hpp"
