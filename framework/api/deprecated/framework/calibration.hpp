// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/app/calibration.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/calibration.hpp\" is deprecated: include \"framework/app/calibration.hpp\"")
#include "framework/app/calibration.hpp"
