// A test plugin whose solo event fails at a given step (an internal error mid-run, exit status 1):
// the run must keep the whole rows it wrote and leave no summary.json (tests/plugin_test.cpp).
#include <stdexcept>
#include <string>

#include "framework/api/event_api.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("fail_midway", "0.0.1")

namespace gem {

struct FailMidway {
  struct Params {
    long atStep;
  };
  static void apply(const Params& p, const SoloBody&, VelocityChange&, const StepContext& ctx) {
    if (ctx.step >= p.atStep) throw std::runtime_error("fail_midway: failing on purpose at step " + std::to_string(ctx.step));
  }
};

static FailMidway::Params parseFailMidway(EventConfig& config) {
  return FailMidway::Params{static_cast<long>(config.params.getInt("at_step", 5, 0, 1000000))};
}

GEM_REGISTER_SOLO_EVENT(FailMidway, "fail_midway", "test plugin: throws at step at_step", false, parseFailMidway);

}  // namespace gem
