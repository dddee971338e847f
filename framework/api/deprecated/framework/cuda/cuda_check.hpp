// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/api/cuda_check.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/cuda/cuda_check.hpp\" is deprecated: include \"framework/api/cuda_check.hpp\"")
#include "framework/api/cuda_check.hpp"
