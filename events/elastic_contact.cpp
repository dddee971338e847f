#include "events/elastic_contact.hpp"

#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

namespace gem {

static ElasticContact::Params parseElasticContact(EventConfig& config) {
  TableReader& t = config.params;
  ElasticContact::Params p{};
  p.sigmaMax = t.getPositive("sigma_max", Real(1e6));
  p.stiffness = t.getPositive("k_ice", 100);
  p.factor = t.getNonNegative("factor", Real(0.05));
  p.vessel = t.getBool("vessel", false);  // ice-ice only, as the thesis (docs/validation/sensitivity.md)
  return p;
}

GEM_REGISTER_PAIR_EVENT(ElasticContact, "elastic_contact",
                        "steady elastic push-apart 0.05 C sigma_max w h dt while bodies overlap (MODEL 4)", true, parseElasticContact);

}  // namespace gem
