// The table of device broadphases, keyed by the broadphase's registry name and origin (as
// cuda_events.cu's table of event drivers).
#include <map>
#include <utility>

#include "framework/api/device_broadphase.hpp"

namespace gem::cuda {

// A function-local static: the strategies' static registrations may run before this file's statics.
// Plugins add to it from gem_plugin_register, under the loader's lock (one at a time).
using BroadphaseKey = std::pair<std::string, std::string>;  // (name, origin)
struct DevicePart {
  CudaBroadphaseFactory factory;
  std::vector<std::string> settings;
};
static std::map<BroadphaseKey, DevicePart>& broadphaseTable() {
  static std::map<BroadphaseKey, DevicePart> t;
  return t;
}

void addCudaBroadphase(const std::string& name, CudaBroadphaseFactory factory, const std::string& origin,
                       std::vector<std::string> settings) {
  broadphaseTable()[BroadphaseKey{name, origin}] = DevicePart{std::move(factory), std::move(settings)};
}

const CudaBroadphaseFactory* findCudaBroadphase(const std::string& name, const std::string& origin) {
  auto it = broadphaseTable().find(BroadphaseKey{name, origin});
  return it == broadphaseTable().end() ? nullptr : &it->second.factory;
}

std::vector<std::string> cudaBroadphaseSettings(const std::string& name, const std::string& origin) {
  auto it = broadphaseTable().find(BroadphaseKey{name, origin});
  return it == broadphaseTable().end() ? std::vector<std::string>{} : it->second.settings;
}

}  // namespace gem::cuda
