// The table of CUDA event drivers, keyed by the event's registry name and origin.
#include <map>
#include <utility>

#include "framework/api/cuda_events.hpp"

namespace gem::cuda {

// A function-local static: the events' static registrations may run before this file's statics.
// Plugins add to it from gem_plugin_register, under the loader's lock (one at a time).
using Key = std::pair<std::string, std::string>;  // (name, origin)
static std::map<Key, CudaEventFactory>& table() {
  static std::map<Key, CudaEventFactory> t;
  return t;
}

void addCudaEvent(const std::string& name, CudaEventFactory factory, const std::string& origin) {
  table()[Key{name, origin}] = std::move(factory);
}

const CudaEventFactory* findCudaEvent(const std::string& name, const std::string& origin) {
  auto it = table().find(Key{name, origin});
  return it == table().end() ? nullptr : &it->second;
}

}  // namespace gem::cuda
