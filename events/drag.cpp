// Drag: parameters from [events.drag] and registration.
#include "events/drag.hpp"

#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

namespace gem {

static Drag::Params parseDrag(EventConfig& config) {
  TableReader& t = config.params;
  Drag::Params p{};
  // Ranges far beyond any sea (docs/scenario.md 2.6), that keep the first step finite.
  p.cd = t.getRealIn("cd", Real(0.05), 0, 10);
  p.rhoWater = t.getPositive("rho_water", kRhoWater, 1e4);
  p.rotationLength = t.getRealIn("rotation_length", 1, 0, 1e4);
  p.linear = t.getRealIn("linear", 0, 0, 1e4);
  p.isotropic = t.getChoice("form", "component", {"component", "isotropic"}) == "isotropic";
  return p;
}

GEM_REGISTER_SOLO_EVENT(Drag, "drag", "water drag on floes, quadratic per component (A.105-A.107), optional isotropic and linear terms",
                        true, parseDrag);

}  // namespace gem
