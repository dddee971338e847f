// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/api/errors.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/errors.hpp\" is deprecated: include \"framework/api/errors.hpp\"")
#include "framework/api/errors.hpp"
