// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/app/sweep.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/sweep.hpp\" is deprecated: include \"framework/app/sweep.hpp\"")
#include "framework/app/sweep.hpp"
