// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/analysis/statistics.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/statistics.hpp\" is deprecated: include \"framework/analysis/statistics.hpp\"")
#include "framework/analysis/statistics.hpp"
