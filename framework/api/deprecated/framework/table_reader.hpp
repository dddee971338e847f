// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/api/table_reader.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/table_reader.hpp\" is deprecated: include \"framework/api/table_reader.hpp\"")
#include "framework/api/table_reader.hpp"
