#include "framework/analyze.hpp"

#include "framework/errors.hpp"

namespace gem {

int runAnalyze(const AnalyzeOptions&) { throw InputError("gem analyze is not implemented yet"); }

}  // namespace gem
