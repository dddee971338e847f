// A plugin whose event's parse function throws a plain std::runtime_error instead of calling
// TableReader::fail: refused with exit 2, naming the scenario, the event's table and the plugin,
// whether the event is on or off (every event's table is read) (tests/plugin_test.cpp).
#include <stdexcept>

#include "framework/api/event_api.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("throws_in_parse", "0.0.1")

namespace gem {

struct ThrowsInParse {
  struct Params {
    Real unused;
  };
  static void apply(const Params&, const SoloBody&, VelocityChange&, const StepContext&) {}
};

static ThrowsInParse::Params parseThrowsInParse(EventConfig&) { throw std::runtime_error("throws_in_parse: parsing fails on purpose"); }

GEM_REGISTER_SOLO_EVENT(ThrowsInParse, "throws_in_parse", "test plugin: its parse function throws", false, parseThrowsInParse);

}  // namespace gem
