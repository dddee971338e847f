// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/app/plugin_loader.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/plugin_loader.hpp\" is deprecated: include \"framework/app/plugin_loader.hpp\"")
#include "framework/app/plugin_loader.hpp"
