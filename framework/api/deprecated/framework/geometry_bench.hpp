// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "bench/geometry_bench.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/geometry_bench.hpp\" is deprecated: include \"bench/geometry_bench.hpp\"")
#include "bench/geometry_bench.hpp"
