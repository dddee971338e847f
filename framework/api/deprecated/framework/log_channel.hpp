// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/api/log_channel.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/log_channel.hpp\" is deprecated: include \"framework/api/log_channel.hpp\"")
#include "framework/api/log_channel.hpp"
