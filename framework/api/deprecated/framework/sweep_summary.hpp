// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/analysis/sweep_summary.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/sweep_summary.hpp\" is deprecated: include \"framework/analysis/sweep_summary.hpp\"")
#include "framework/analysis/sweep_summary.hpp"
