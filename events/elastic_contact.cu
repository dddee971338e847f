// elastic_contact: the CUDA driver, the same evaluator as the CPU (docs/architecture.md "Writing an event").
#include "events/elastic_contact.hpp"
#include "framework/api/cuda_events.hpp"
#include "framework/api/registry.hpp"

namespace gem {
GEM_REGISTER_CUDA_PAIR_EVENT(ElasticContact, "elastic_contact");
}  // namespace gem
