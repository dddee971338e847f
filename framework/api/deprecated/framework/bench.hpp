// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "bench/bench.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/bench.hpp\" is deprecated: include \"bench/bench.hpp\"")
#include "bench/bench.hpp"
