// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/output/vtk_writer.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/vtk_writer.hpp\" is deprecated: include \"framework/output/vtk_writer.hpp\"")
#include "framework/output/vtk_writer.hpp"
