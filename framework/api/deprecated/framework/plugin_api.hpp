// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/api/plugin_api.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/plugin_api.hpp\" is deprecated: include \"framework/api/plugin_api.hpp\"")
#include "framework/api/plugin_api.hpp"
