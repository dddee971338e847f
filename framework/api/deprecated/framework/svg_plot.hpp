// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/analysis/svg_plot.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/svg_plot.hpp\" is deprecated: include \"framework/analysis/svg_plot.hpp\"")
#include "framework/analysis/svg_plot.hpp"
