// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/analysis/analyze.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/analyze.hpp\" is deprecated: include \"framework/analysis/analyze.hpp\"")
#include "framework/analysis/analyze.hpp"
