// sweep_and_prune: the device part (docs/plugins.md "A broadphase on the GPU"). The same rule as
// sweep_and_prune.cpp: each body's bounding circle gives the x interval [x - R, x + R]; the
// intervals are sorted by their start (a CUB radix sort, every step: on the device a fresh sort
// costs less than the CPU's insertion sort's sequential walk), then each body walks forward while
// the next interval starts before its own ends and emits the pairs whose circles overlap. The
// framework sorts the pairs by (a, b), so the run is bit for bit the one of any other strategy.
#include <cub/device/device_radix_sort.cuh>

#include <algorithm>

#include "framework/api/cuda_events.hpp"
#include "framework/api/device_broadphase.hpp"
#include "framework/api/registry.hpp"

namespace gem {
namespace {

using cuda::BroadphaseBodies;
using cuda::CandidateSink;

__global__ void intervalStartKernel(BroadphaseBodies b, Real* start, int* slot) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= b.n) return;
  start[i] = b.x[i] - b.radius[i];
  slot[i] = i;
}

__global__ void sweepKernel(BroadphaseBodies b, const Real* sortedStart, const int* sortedSlot, CandidateSink sink) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= b.n) return;
  const int a = sortedSlot[k];
  const Real end = b.x[a] + b.radius[a];
  for (int l = k + 1; l < b.n && sortedStart[l] <= end; ++l) {
    const int c = sortedSlot[l];
    const Real dx = b.x[a] - b.x[c], dy = b.y[a] - b.y[c], reach = b.radius[a] + b.radius[c];
    if (dx * dx + dy * dy > reach * reach) continue;
    if (b.kind[a] == BodyKind::Wall && b.kind[c] == BodyKind::Wall) continue;  // both immovable
    sink.add(a, c);
  }
}

class DeviceSweepAndPrune final : public cuda::CudaBroadphase {
 public:
  explicit DeviceSweepAndPrune(const BroadphaseSettings&) {}
  void upload(const World& world) override {
    m_n = world.size();
    const size_t n = static_cast<size_t>(std::max(m_n, 1));
    m_start.ensure(n), m_sortedStart.ensure(n), m_slot.ensure(n), m_sortedSlot.ensure(n);
    size_t bytes = 0;  // CUB's scratch, sized here: nothing may be allocated inside the step's graph
    GEM_CUDA_CHECK(
        cub::DeviceRadixSort::SortPairs(nullptr, bytes, m_start.get(), m_sortedStart.get(), m_slot.get(), m_sortedSlot.get(), m_n));
    m_temp.ensure(std::max<size_t>(bytes, 1));
    m_tempBytes = bytes;
  }
  bool reorder(const int*, int, cudaStream_t) override { return true; }  // keeps nothing per body between steps
  void enqueue(const BroadphaseBodies& b, const CandidateSink& sink, cudaStream_t stream) override {
    if (b.n < 2) return;
    intervalStartKernel<<<cuda::blocksFor(b.n), cuda::kBlock, 0, stream>>>(b, m_start.get(), m_slot.get());
    GEM_CUDA_CHECK_LAUNCH();
    GEM_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(m_temp.get(), m_tempBytes, m_start.get(), m_sortedStart.get(), m_slot.get(),
                                                   m_sortedSlot.get(), b.n, 0, static_cast<int>(sizeof(Real) * 8), stream));
    sweepKernel<<<cuda::blocksFor(b.n), cuda::kBlock, 0, stream>>>(b, m_sortedStart.get(), m_sortedSlot.get(), sink);
    GEM_CUDA_CHECK_LAUNCH();
  }

 private:
  int m_n = 0;
  cuda::DeviceArray<Real> m_start, m_sortedStart;
  cuda::DeviceArray<int> m_slot, m_sortedSlot;
  cuda::DeviceArray<unsigned char> m_temp;
  size_t m_tempBytes = 0;
};

}  // namespace

GEM_REGISTER_CUDA_BROADPHASE(DeviceSweepAndPrune, "sweep_and_prune");

}  // namespace gem
