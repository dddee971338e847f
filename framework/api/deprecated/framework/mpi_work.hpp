// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/app/mpi_work.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/mpi_work.hpp\" is deprecated: include \"framework/app/mpi_work.hpp\"")
#include "framework/app/mpi_work.hpp"
