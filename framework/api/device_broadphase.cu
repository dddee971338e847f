// The table of device broadphases, keyed by the broadphase's registry name and origin (as
// cuda_events.cu's table of event drivers).
#include <map>
#include <utility>

#include "framework/api/device_broadphase.hpp"

namespace gem::cuda {

// A function-local static: the strategies' static registrations may run before this file's statics.
// Plugins add to it from gem_plugin_register, under the loader's lock (one at a time).
using BroadphaseKey = std::pair<std::string, std::string>;  // (name, origin)
static std::map<BroadphaseKey, CudaBroadphaseFactory>& broadphaseTable() {
  static std::map<BroadphaseKey, CudaBroadphaseFactory> t;
  return t;
}

void addCudaBroadphase(const std::string& name, CudaBroadphaseFactory factory, const std::string& origin) {
  broadphaseTable()[BroadphaseKey{name, origin}] = std::move(factory);
}

const CudaBroadphaseFactory* findCudaBroadphase(const std::string& name, const std::string& origin) {
  auto it = broadphaseTable().find(BroadphaseKey{name, origin});
  return it == broadphaseTable().end() ? nullptr : &it->second;
}

}  // namespace gem::cuda
