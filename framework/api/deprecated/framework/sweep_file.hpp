// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/scenario/sweep_file.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/sweep_file.hpp\" is deprecated: include \"framework/scenario/sweep_file.hpp\"")
#include "framework/scenario/sweep_file.hpp"
