// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/field/ice_file.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/ice_file.hpp\" is deprecated: include \"framework/field/ice_file.hpp\"")
#include "framework/field/ice_file.hpp"
