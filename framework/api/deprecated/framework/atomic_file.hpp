// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/output/atomic_file.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/atomic_file.hpp\" is deprecated: include \"framework/output/atomic_file.hpp\"")
#include "framework/output/atomic_file.hpp"
