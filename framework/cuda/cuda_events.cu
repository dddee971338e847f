// The table of CUDA event drivers, keyed by the event's registry name.
#include <map>

#include "framework/cuda/cuda_events.hpp"

namespace gem::cuda {

// A function-local static: the events' static registrations may run before this file's statics.
static std::map<std::string, CudaEventFactory>& table() {
  static std::map<std::string, CudaEventFactory> t;
  return t;
}

void addCudaEvent(const std::string& name, CudaEventFactory factory) { table()[name] = std::move(factory); }

const CudaEventFactory* findCudaEvent(const std::string& name) {
  auto it = table().find(name);
  return it == table().end() ? nullptr : &it->second;
}

}  // namespace gem::cuda
