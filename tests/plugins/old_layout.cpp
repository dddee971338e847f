// A plugin written against GEM 0.1's SDK layout, include paths and all (framework/event_api.hpp,
// framework/registry.hpp, ...): it must still build, against the forwarding headers of
// framework/api/deprecated, and run. Its event pushes every floe towards +y at `accel` m/s^2.
#include "framework/event_api.hpp"
#include "framework/plugin_api.hpp"
#include "framework/registry.hpp"
#include "framework/table_reader.hpp"

GEM_PLUGIN("old_layout", "0.1.0")

namespace gem {

struct SidewaysPush {
  struct Params {
    Real accel;  // m/s^2
  };
  GEM_HD static void apply(const Params& p, const SoloBody& body, VelocityChange& change, const StepContext& ctx) {
    if (body.kind == BodyKind::Floe) change.dv.y += p.accel * ctx.dt;
  }
};

static SidewaysPush::Params parseSidewaysPush(EventConfig& config) { return {config.params.getReal("accel", Real(0.5))}; }

GEM_REGISTER_SOLO_EVENT(SidewaysPush, "sideways_push", "test plugin of the 0.1 layout: pushes floes towards +y", false, parseSidewaysPush);

}  // namespace gem
