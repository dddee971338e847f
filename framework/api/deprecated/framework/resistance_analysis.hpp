// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/analysis/resistance_analysis.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/resistance_analysis.hpp\" is deprecated: include \"framework/analysis/resistance_analysis.hpp\"")
#include "framework/analysis/resistance_analysis.hpp"
