// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "broadphase/kept_list/device_neighbour_list.cuh" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"broadphase/device_neighbour_list.cuh\" is deprecated: include \"broadphase/kept_list/device_neighbour_list.cuh\"")
#include "broadphase/kept_list/device_neighbour_list.cuh"
