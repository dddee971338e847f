// A plugin whose record output counts its rows under summary.json's "steps": refused at load (exit
// 2), override or not; it once turned a 100-step run's "steps" into its row count (tests/plugin_test.cpp).
#include <string>

#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"

GEM_PLUGIN("takes_steps_key", "0.0.1")

namespace gem {

static void writeNothing(const void*, std::string& row) { row += "0\n"; }

GEM_REGISTER_RECORD_OUTPUT("takes_steps_key_rows", "takes_steps_key.csv", "t", writeNothing, "steps", "", nullptr);

}  // namespace gem
