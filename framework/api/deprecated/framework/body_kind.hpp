// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/world/body_kind.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/body_kind.hpp\" is deprecated: include \"framework/world/body_kind.hpp\"")
#include "framework/world/body_kind.hpp"
