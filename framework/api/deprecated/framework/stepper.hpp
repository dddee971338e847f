// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/step/stepper.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/stepper.hpp\" is deprecated: include \"framework/step/stepper.hpp\"")
#include "framework/step/stepper.hpp"
