#include "events/motion.hpp"

#include "framework/api/registry.hpp"

namespace gem {

static Motion::Params parseMotion(EventConfig&) { return Motion::Params{0}; }

GEM_REGISTER_MOTION_EVENT(Motion, "motion", "semi-implicit Euler position update, degrees of freedom enforced (A.21-A.23)", true,
                          parseMotion);

}  // namespace gem
