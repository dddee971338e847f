// Drag: parameters from [events.drag] and registration.
#include "events/drag.hpp"

#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

namespace gem {

static Drag::Params parseDrag(EventConfig& config) {
  TableReader& t = config.params;
  Drag::Params p{};
  p.cd = t.getNonNegative("cd", Real(0.05));
  p.rhoWater = t.getPositive("rho_water", kRhoWater);
  p.rotationLength = t.getNonNegative("rotation_length", 1);
  p.linear = t.getNonNegative("linear", 0);
  p.isotropic = t.getChoice("form", "component", {"component", "isotropic"}) == "isotropic";
  return p;
}

GEM_REGISTER_SOLO_EVENT(Drag, "drag", "water drag on floes, quadratic per component (A.105-A.107), optional isotropic and linear terms",
                        true, parseDrag);

}  // namespace gem
