// A test plugin whose solo event gives every floe an infinite angular velocity from step at_step
// on (0: the first step), its position and velocity left finite: a state that is no longer finite
// in the angular velocity alone (tests/end_to_end_test.cpp, tests/bad_input_test.cpp). Its event's
// name is longer than gem info's old 18-character column (tests/plugin_test.cpp).
#include <limits>

#include "framework/api/event_api.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("spin_up", "0.0.1")

namespace gem {

struct SpinUp {
  struct Params {
    long atStep;
  };
  static void apply(const Params& p, const SoloBody& body, VelocityChange& change, const StepContext& ctx) {
    if (ctx.step >= p.atStep && body.kind == BodyKind::Floe) change.domega = std::numeric_limits<Real>::infinity();
  }
};

static SpinUp::Params parseSpinUp(EventConfig& config) {
  return SpinUp::Params{static_cast<long>(config.params.getInt("at_step", 0, 0, 1000000))};
}

GEM_REGISTER_SOLO_EVENT(SpinUp, "spin_past_any_finite_rate", "test plugin: every floe's angular velocity infinite from step at_step", false,
                        parseSpinUp);

}  // namespace gem
