// The CUDA drivers of events: the device twin of CpuPairDriver / CpuSoloDriver / CpuMotionDriver
// (framework/api/registry.hpp). Each is one templated kernel that calls the very same evaluator struct
// as the CPU, so no physics is written twice. An event's events/NAME.cu is one line:
//   GEM_REGISTER_CUDA_SOLO_EVENT(Drag, "drag");
// which registers, under the event's name, a factory that takes the parsed Params of the CPU
// instance (EventInstance::params()), so both backends run from the very same values: one per
// world when a sweep batches several cases into one device state.
//
// Each driver is also keyed by its origin, as the registry's entries are: "built-in" for GEM's
// own, the plugin's origin ("PATH (NAME VERSION)") for a plugin's. A plugin's .cu uses the same
// macro; compiled with GEM_BUILDING_PLUGIN it defers, like the GEM_REGISTER_* macros, into the
// plugin's own list, and gem_plugin_register adds it under the origin the loader is registering
// (Registry::pluginOrigin). CudaStepper pairs an event only with the driver of the same name
// and the same origin as its registry entry: a plugin's event with its own plugin's driver.
#pragma once
#include <cuda_runtime.h>

#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "framework/api/cuda_check.hpp"
#include "framework/api/event_api.hpp"

namespace gem::cuda {

// Device pointers of one step's pair phase (contacts are sorted by slot pair (a, b)). The step is
// a captured CUDA graph replayed every step, so what changes from step to step is read from device
// memory, not baked into the kernel arguments: the step context and the live contact count (the
// launch covers the buffers' capacity, `count`).
//
// `world` is each body's world: a sweep on a GPU runs several cases in one device state, each case
// a world of its own (DeviceStep::upload), and an event applies its own case's Params to a body.
// Contacts never join two worlds.
struct DevicePairData {
  const PairBody* bodies;
  const int* world;
  const int* contactA;
  const int* contactB;
  const PairContact* contacts;
  PairSlot* slots;
  int count;               // capacity covered by the launch
  int block;               // threads per block (simulation.cuda_block_size)
  const int* liveCount;    // device: this step's contacts
  const StepContext* ctx;  // device
  RecordSink sink;         // device buffers, integer atomic counters
  int event;               // the event's place among the phase's events: stamped on its records
};

struct DeviceSoloData {
  const SoloBody* bodies;
  const int* world;
  VelocityChange* changes;
  int count;
  int block;
  const StepContext* ctx;  // device
};

struct DeviceMotionData {
  MotionBody* bodies;
  const int* world;
  int count;
  int block;
  const StepContext* ctx;  // device
};

constexpr int kBlock = 128;  // the default of simulation.cuda_block_size
inline int blocksFor(int n, int block = kBlock) { return (n + block - 1) / block; }

class CudaEventDriver {
 public:
  virtual ~CudaEventDriver() = default;
  virtual void launchPairs(const DevicePairData&, cudaStream_t) {}
  virtual void launchSolo(const DeviceSoloData&, cudaStream_t) {}
  virtual void launchMotion(const DeviceMotionData&, cudaStream_t) {}
};

// params[w]: the parsed Params of world w's instance of the event (EventInstance::params()), for
// worlds w = 0 .. worlds - 1 (1 but for a sweep's batch of cases).
using CudaEventFactory = std::function<std::unique_ptr<CudaEventDriver>(const void* const* params, int worlds)>;
// origin: "built-in", or the registering plugin's. A second driver of one (name, origin) replaces
// the first.
void addCudaEvent(const std::string& name, CudaEventFactory factory, const std::string& origin = "built-in");
// nullptr when no driver of that name comes from that origin.
const CudaEventFactory* findCudaEvent(const std::string& name, const std::string& origin = "built-in");

#if defined(__CUDACC__)
// The Params of every world: world 0's travel by value as a kernel argument (one case, or a batch
// whose cases agree on this event); when the worlds' differ, all of them also sit in a device
// array, read at the body's world.
template <class Params>
class WorldParams {
 public:
  static_assert(std::is_trivially_copyable_v<Params>,
                "an event's Params must be trivially copyable: it is copied to the GPU as a kernel argument");
  WorldParams(const void* const* params, int worlds) : m_first(*static_cast<const Params*>(params[0])) {
    bool same = true;
    for (int w = 1; w < worlds; ++w) same = same && std::memcmp(params[w], params[0], sizeof(Params)) == 0;
    if (same) return;
    std::vector<Params> all;
    for (int w = 0; w < worlds; ++w) all.push_back(*static_cast<const Params*>(params[w]));
    GEM_CUDA_CHECK(cudaMalloc(&m_perWorld, sizeof(Params) * all.size()));
    GEM_CUDA_CHECK(cudaMemcpy(m_perWorld, all.data(), sizeof(Params) * all.size(), cudaMemcpyHostToDevice));
  }
  WorldParams(const WorldParams&) = delete;
  WorldParams& operator=(const WorldParams&) = delete;
  ~WorldParams() {
    if (m_perWorld) cudaFree(m_perWorld);  // no throw from a destructor
  }
  const Params& first() const { return m_first; }
  const Params* perWorld() const { return m_perWorld; }  // nullptr: every world has first()

 private:
  Params m_first;
  Params* m_perWorld = nullptr;
};

// A copy, not a reference: a reference that may point at a kernel parameter makes the compiler
// address the parameter space generically, which compute-sanitizer reported as an out-of-bounds
// global read in kernels of a graph's WHILE body (the pair kernel of ship_impact).
template <class Params>
__device__ inline Params paramsOf(const Params& first, const Params* perWorld, const int* world, int body) {
  return perWorld ? perWorld[world[body]] : first;
}

template <class Event, class Params>
__global__ void pairEventKernel(Params params, const Params* perWorld, DevicePairData d) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= d.count || k >= *d.liveCount) return;
  const StepContext ctx = *d.ctx;
  const int a = d.contactA[k];
  const Params p = paramsOf(params, perWorld, d.world, a);
  Event::apply(p, d.bodies[a], d.bodies[d.contactB[k]], d.contacts[k], d.slots[k], ctx, d.sink.at(d.event, k, d.world[a]));
}

template <class Event, class Params>
__global__ void soloEventKernel(Params params, const Params* perWorld, DeviceSoloData d) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= d.count) return;
  const StepContext ctx = *d.ctx;
  const Params p = paramsOf(params, perWorld, d.world, i);
  Event::apply(p, d.bodies[i], d.changes[i], ctx);
}

template <class Event, class Params>
__global__ void motionKernel(Params params, const Params* perWorld, DeviceMotionData d) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= d.count) return;
  const StepContext ctx = *d.ctx;
  const Params p = paramsOf(params, perWorld, d.world, i);
  Event::apply(p, d.bodies[i], ctx);
}

template <class Event>
class CudaPairDriver final : public CudaEventDriver {
 public:
  using Params = typename Event::Params;
  CudaPairDriver(const void* const* params, int worlds) : m_params(params, worlds) {}
  void launchPairs(const DevicePairData& d, cudaStream_t stream) override {
    if (d.count == 0) return;
    pairEventKernel<Event, Params><<<blocksFor(d.count, d.block), d.block, 0, stream>>>(m_params.first(), m_params.perWorld(), d);
    GEM_CUDA_CHECK_LAUNCH();
  }

 private:
  WorldParams<Params> m_params;
};

template <class Event>
class CudaSoloDriver final : public CudaEventDriver {
 public:
  using Params = typename Event::Params;
  CudaSoloDriver(const void* const* params, int worlds) : m_params(params, worlds) {}
  void launchSolo(const DeviceSoloData& d, cudaStream_t stream) override {
    if (d.count == 0) return;
    soloEventKernel<Event, Params><<<blocksFor(d.count, d.block), d.block, 0, stream>>>(m_params.first(), m_params.perWorld(), d);
    GEM_CUDA_CHECK_LAUNCH();
  }

 private:
  WorldParams<Params> m_params;
};

template <class Event>
class CudaMotionDriver final : public CudaEventDriver {
 public:
  using Params = typename Event::Params;
  CudaMotionDriver(const void* const* params, int worlds) : m_params(params, worlds) {}
  void launchMotion(const DeviceMotionData& d, cudaStream_t stream) override {
    if (d.count == 0) return;
    motionKernel<Event, Params><<<blocksFor(d.count, d.block), d.block, 0, stream>>>(m_params.first(), m_params.perWorld(), d);
    GEM_CUDA_CHECK_LAUNCH();
  }

 private:
  WorldParams<Params> m_params;
};

struct RegisterCudaEvent {
  RegisterCudaEvent(const char* name, CudaEventFactory factory) { addCudaEvent(name, std::move(factory)); }
};
#endif

}  // namespace gem::cuda

#if defined(GEM_BUILDING_PLUGIN)
// A plugin: a node of the plugin's own list (registry.hpp's GEM_REGISTRATION, which needs
// registry.hpp included), run by gem_plugin_register once the descriptor is accepted; it adds the
// driver under the origin the loader is registering.
#define GEM_REGISTER_CUDA_EVENT(DRIVER, EVENT, NAME)                                                                             \
  GEM_REGISTRATION(cuda_event_, ::gem::cuda::addCudaEvent(                                                                       \
                                    NAME,                                                                                        \
                                    [](const void* const* params, int worlds) -> std::unique_ptr<::gem::cuda::CudaEventDriver> { \
                                      return std::make_unique<DRIVER<EVENT>>(params, worlds);                                    \
                                    },                                                                                           \
                                    registry.pluginOrigin()))
#else
#define GEM_REGISTER_CUDA_EVENT(DRIVER, EVENT, NAME)                                                   \
  static const ::gem::cuda::RegisterCudaEvent GEM_CONCAT(gem_register_cuda_event_, __LINE__) {         \
    NAME, [](const void* const* params, int worlds) -> std::unique_ptr<::gem::cuda::CudaEventDriver> { \
      return std::make_unique<DRIVER<EVENT>>(params, worlds);                                          \
    }                                                                                                  \
  }
#endif
#define GEM_REGISTER_CUDA_PAIR_EVENT(EVENT, NAME) GEM_REGISTER_CUDA_EVENT(::gem::cuda::CudaPairDriver, EVENT, NAME)
#define GEM_REGISTER_CUDA_SOLO_EVENT(EVENT, NAME) GEM_REGISTER_CUDA_EVENT(::gem::cuda::CudaSoloDriver, EVENT, NAME)
#define GEM_REGISTER_CUDA_MOTION_EVENT(EVENT, NAME) GEM_REGISTER_CUDA_EVENT(::gem::cuda::CudaMotionDriver, EVENT, NAME)
