#include "events/elastic_contact.hpp"

#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

namespace gem {

static ElasticContact::Params parseElasticContact(EventConfig& config) {
  TableReader& t = config.params;
  ElasticContact::Params p{};
  p.sigmaMax = t.getPositive("sigma_max", Real(1e6), 1e9);  // ice is 1e6 to 1e7 Pa
  p.stiffness = t.getPositive("k_ice", 100, 1e9);
  p.factor = t.getRealIn("factor", Real(0.05), 0, 10);
  p.vessel = t.getBool("vessel", false);  // ice-ice only, as the thesis (docs/validation/sensitivity.md)
  return p;
}

GEM_REGISTER_PAIR_EVENT(ElasticContact, "elastic_contact",
                        "steady elastic push-apart 0.05 C sigma_max w h dt while bodies overlap (MODEL 4)", true, parseElasticContact);

}  // namespace gem
