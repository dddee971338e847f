// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/api/registry.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/registry.hpp\" is deprecated: include \"framework/api/registry.hpp\"")
#include "framework/api/registry.hpp"
