#include "events/impact.hpp"

#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

namespace gem {

static Impact::Params parseImpact(EventConfig& config) {
  Impact::Params p{};
  p.friction = config.params.getNonNegative("friction", 0);
  return p;
}

GEM_REGISTER_PAIR_EVENT(Impact, "impact", "inelastic impulse I = M_ec V_c at the contact point (A.31-A.49), optional Coulomb friction",
                        true, parseImpact);

}  // namespace gem
