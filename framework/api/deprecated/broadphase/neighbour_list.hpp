// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "broadphase/kept_list/neighbour_list.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"broadphase/neighbour_list.hpp\" is deprecated: include \"broadphase/kept_list/neighbour_list.hpp\"")
#include "broadphase/kept_list/neighbour_list.hpp"
