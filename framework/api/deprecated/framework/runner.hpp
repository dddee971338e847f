// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/app/runner.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/runner.hpp\" is deprecated: include \"framework/app/runner.hpp\"")
#include "framework/app/runner.hpp"
