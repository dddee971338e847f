// A well-formed plugin whose event is named "drag", like the built-in: a clash unless the
// scenario's [[plugins]] entry says override = true. Its drag is the built-in evaluator with a
// 100 times the default C_d, so a run shows which one ran.
#include "events/drag.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("drag_clash", "0.0.1")

namespace gem {

static Drag::Params parseStrongDrag(EventConfig& config) {
  Drag::Params p{};
  p.cd = config.params.getNonNegative("cd", Real(5));
  p.rhoWater = kRhoWater;
  p.rotationLength = 1;
  p.linear = 0;
  p.isotropic = false;
  return p;
}

GEM_REGISTER_SOLO_EVENT(Drag, "drag", "test plugin: drag with C_d = 5", true, parseStrongDrag);
}  // namespace gem
