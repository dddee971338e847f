#include "framework/sweep.hpp"

#include "framework/errors.hpp"

namespace gem {

int runSweep(const SweepOptions&) { throw InputError("gem sweep is not implemented yet"); }

}  // namespace gem
