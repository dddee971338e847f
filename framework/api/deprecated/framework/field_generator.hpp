// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/field/field_generator.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/field_generator.hpp\" is deprecated: include \"framework/field/field_generator.hpp\"")
#include "framework/field/field_generator.hpp"
