// Device broadphases: the CUDA twin of framework/api/broadphase.hpp (docs/architecture.md "The one
// idea": a broadphase proposes candidate pairs and knows nothing about events). Modelled on
// cuda_events.hpp.
//
// The contract, for a strategy's .cu (broadphase/NAME.cu, or a plugin's):
//   - enqueue() puts this step's work on the stream it is given. That work is captured once into
//     the step's CUDA graph and replayed every step: no host sync, no allocation, and nothing that
//     changes from step to step in the kernel arguments (read it from device memory: the bodies'
//     arrays, or the strategy's own device state).
//   - Every candidate goes to CandidateSink::add(i, j), in any order and from any thread: the
//     framework then radix-sorts the pairs by (a, b), so the contacts, and so the trajectories, do
//     not depend on the strategy (docs/model.md 9, broadphase.hpp).
//   - Conservative: emit every pair whose world boxes overlap (every pair whose bounding circles
//     overlap is a superset of those). More is allowed: the narrowphase drops pairs whose boxes do
//     not overlap and pairs of two immovable bodies, as the CPU's prefilter does. Each pair once.
//   - Storage the strategy keeps (DeviceArray, device_array.hpp) is sized on the host in upload()
//     and reserve(), outside the graph. When a kernel finds its own storage too small it calls
//     sink.redo(): the step then leaves the state alone, the host calls reserve() (grow there) and
//     re-captures, and the step runs again, exactly as when the candidate list itself overflows.
// Registration is one line in the .cu, for a class constructible from BroadphaseSettings:
//   GEM_REGISTER_CUDA_BROADPHASE(DeviceSweepAndPrune, "sweep_and_prune");
// keyed by (name, origin) as the event drivers are: CudaStepper runs a broadphase on the device
// only with the device part of the same origin as its registry entry (a plugin's with its own).
#pragma once
#include <cuda_runtime.h>

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "framework/api/broadphase.hpp"
#include "framework/api/cuda_check.hpp"
#include "framework/api/device_array.hpp"  // DeviceArray, for a strategy's own storage
#include "framework/world/world.hpp"
#include "geometry/polygon.hpp"

namespace gem::cuda {

// The bodies as a strategy sees them in one step: device arrays, by slot, valid for the step
// (passed by value; the pointers are fixed between uploads, the contents change every step).
struct BroadphaseBodies {
  int n;
  const Real* x;  // centroid, m
  const Real* y;
  const Real* angle;    // rad
  const Real* radius;   // bounding radius about the centroid (World::radius), m
  const Box* boxes;     // this step's world-aligned boxes
  const Real* invMass;  // 0: immovable (walls)
  const BodyKind* kind;
  const Vec2* worldVertices;  // this step's, kMaxVertices per body
  const int* vertexCount;
};

// Where candidates go. A pair is one 64-bit key (min << slotBits) | max, so the framework's sort by
// key is the sort by (a, b). `count` counts every add, past the capacity too: the framework grows
// the capacity to what was needed and runs the step again.
struct CandidateSink {
  unsigned long long* keys;
  int capacity;
  int* count;    // device
  int slotBits;  // a slot fits in slotBits bits
#if defined(__CUDACC__)
  __device__ void add(int i, int j) const {
    const int k = atomicAdd(count, 1);
    if (k >= capacity) return;
    const unsigned long long lo = static_cast<unsigned long long>(i < j ? i : j), hi = static_cast<unsigned long long>(i < j ? j : i);
    keys[k] = (lo << slotBits) | hi;
  }
  // The strategy's own storage was too small: the step is redone after reserve().
  __device__ void redo() const { atomicMax(count, capacity + 1); }
#endif
};

class CudaBroadphase {
 public:
  virtual ~CudaBroadphase() = default;
  // Host, outside the graph: the world was (re)uploaded (set-up, breaks, re-sorts): slots may name
  // other bodies now, so any kept structure is stale. Per-body storage is sized here.
  virtual void upload(const World& world) { (void)world; }
  // Host, outside the graph, before every capture: a sync is fine here. Grow what a kernel found
  // too small (after sink.redo()); anything reallocated must be marked stale on the device.
  virtual void reserve(cudaStream_t stream) { (void)stream; }
  // Host, outside the graph: the bodies were re-sorted on the device (new slot k holds old slot
  // order[k], a device array of n). Return true once the strategy's per-body storage follows the
  // bodies (and kept structures are marked stale); false (the default) makes the host upload the
  // whole world instead, which a strategy written before this existed handles in upload().
  virtual bool reorder(const int* order, int n, cudaStream_t stream) {
    (void)order, (void)n, (void)stream;
    return false;
  }
  // Host, outside the graph: a topology edit replayed on the device (breaks): slot k < kept now
  // holds old slot keptOrder[k] (a device array), and after the survivors come the new bodies,
  // which are rows [firstAdded, after.size()) of the host world `after` (in that order; the rows
  // before firstAdded may be in another order than the device's). Return true once the strategy's
  // per-body storage follows; false (the default) makes the host put its world in the device's
  // order and call upload() with it.
  virtual bool edited(const int* keptOrder, int kept, const World& after, int firstAdded, cudaStream_t stream) {
    (void)keptOrder, (void)kept, (void)after, (void)firstAdded, (void)stream;
    return false;
  }
  virtual void enqueue(const BroadphaseBodies& bodies, const CandidateSink& sink, cudaStream_t stream) = 0;
  // How many times a kept structure was (re)built (reads the device: host, between steps).
  virtual long rebuilds() const { return 0; }
};

// A factory returning nullptr means "the step's own hashed grid" (framework/cuda/broadphase_grid.cu),
// the built-in uniform_grid: its sorted-rows path writes the pairs already in order and needs no sort.
using CudaBroadphaseFactory = std::function<std::unique_ptr<CudaBroadphase>(const BroadphaseSettings&)>;
// origin: "built-in", or the registering plugin's. A second factory of one (name, origin) replaces the first.
// settings: the keys of BroadphaseSettings the device part honours (its class's kSettings); a
// scenario that sets another is refused on the device (docs/scenario.md [broadphase.NAME]).
void addCudaBroadphase(const std::string& name, CudaBroadphaseFactory factory, const std::string& origin = "built-in",
                       std::vector<std::string> settings = {});
// nullptr when no device part of that name comes from that origin.
const CudaBroadphaseFactory* findCudaBroadphase(const std::string& name, const std::string& origin = "built-in");
// The settings that device part honours (empty when there is none).
std::vector<std::string> cudaBroadphaseSettings(const std::string& name, const std::string& origin = "built-in");

struct RegisterCudaBroadphase {
  RegisterCudaBroadphase(const char* name, CudaBroadphaseFactory factory, std::vector<std::string> settings = {}) {
    addCudaBroadphase(name, std::move(factory), "built-in", std::move(settings));
  }
};

}  // namespace gem::cuda

#if defined(GEM_BUILDING_PLUGIN)
// A plugin: a node of the plugin's own list (registry.hpp's GEM_REGISTRATION, which needs
// registry.hpp included), run by gem_plugin_register under the origin the loader is registering.
#define GEM_REGISTER_CUDA_BROADPHASE(CLASS, NAME)                                                                                 \
  GEM_REGISTRATION(cuda_broadphase_, ::gem::cuda::addCudaBroadphase(                                                              \
                                         NAME,                                                                                    \
                                         [](const ::gem::BroadphaseSettings& s) -> std::unique_ptr<::gem::cuda::CudaBroadphase> { \
                                           return std::make_unique<CLASS>(s);                                                     \
                                         },                                                                                       \
                                         registry.pluginOrigin(), ::gem::declaredBroadphaseSettings<CLASS>()))
#else
#define GEM_REGISTER_CUDA_BROADPHASE(CLASS, NAME)                                                                                        \
  static const ::gem::cuda::RegisterCudaBroadphase GEM_CONCAT(gem_register_cuda_broadphase_, __LINE__) {                                 \
    NAME, [](const ::gem::BroadphaseSettings& s) -> std::unique_ptr<::gem::cuda::CudaBroadphase> { return std::make_unique<CLASS>(s); }, \
        ::gem::declaredBroadphaseSettings<CLASS>()                                                                                       \
  }
#endif
