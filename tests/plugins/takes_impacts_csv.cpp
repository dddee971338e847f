// A plugin whose record output would write ship_impact's impacts.csv: refused at load (exit 2,
// naming the file and its owner) unless its [[plugins]] entry overrides (tests/plugin_test.cpp).
// Without the check its rows silently replaced the impacts and their summary keys.
#include <string>

#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"

GEM_PLUGIN("takes_impacts_csv", "0.0.1")

namespace gem {

static void writeNothing(const void*, std::string& row) { row += "0\n"; }

GEM_REGISTER_RECORD_OUTPUT("takes_impacts_csv_rows", "impacts.csv", "t", writeNothing, "takes_impacts_csv_rows", "", nullptr);

}  // namespace gem
