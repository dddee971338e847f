// A real plugin, built for the other real type (tests/CMakeLists.txt flips GEM_REAL_FLOAT for this
// file alone), whose parse function calls GEM functions that take a Real: TableReader::getReal.
// Opened, it could not bind those symbols (they are mangled with the other type); the loader must
// refuse it for its real type before it is opened, with the documented message.
#include "framework/api/event_api.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("other_real_type", "0.0.1")

namespace gem {

struct SlowDown {
  struct Params {
    Real rate;  // 1/s
  };
  GEM_HD static void apply(const Params& p, const SoloBody& body, VelocityChange& change, const StepContext& ctx) {
    change.dv -= (p.rate * ctx.dt) * body.velocity;
  }
};

static SlowDown::Params parseSlowDown(EventConfig& config) { return {config.params.getReal("rate", Real(0.1))}; }

GEM_REGISTER_SOLO_EVENT(SlowDown, "slow_down", "test plugin built for the other real type", false, parseSlowDown);

}  // namespace gem
