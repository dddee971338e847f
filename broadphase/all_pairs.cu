// all_pairs on the device: every pair whose bounding circles overlap, tested afresh each step, as
// all_pairs.cpp. O(n^2) work: the reference for small fields. A block of threads per row a takes
// the b > a in strides; the grid's rows wrap past its y limit.
#include <algorithm>

#include "framework/api/cuda_events.hpp"
#include "framework/api/device_broadphase.hpp"
#include "framework/api/registry.hpp"

namespace gem::cuda {
namespace {

constexpr int kMaxRows = 65535;  // gridDim.y

__global__ void allPairsKernel(BroadphaseBodies b, CandidateSink sink) {
  for (int a = blockIdx.y; a < b.n; a += gridDim.y) {
    const int j = a + 1 + blockIdx.x * blockDim.x + threadIdx.x;
    if (j >= b.n) continue;
    if (b.kind[a] == BodyKind::Wall && b.kind[j] == BodyKind::Wall) continue;  // both immovable
    const Real dx = b.x[a] - b.x[j], dy = b.y[a] - b.y[j], reach = b.radius[a] + b.radius[j];
    if (dx * dx + dy * dy <= reach * reach) sink.add(a, j);
  }
}

class DeviceAllPairs final : public CudaBroadphase {
 public:
  explicit DeviceAllPairs(const BroadphaseSettings&) {}
  bool reorder(const int*, int, cudaStream_t) override { return true; }  // keeps nothing per body
  void enqueue(const BroadphaseBodies& bodies, const CandidateSink& sink, cudaStream_t stream) override {
    if (bodies.n < 2) return;
    const dim3 grid(static_cast<unsigned>(blocksFor(bodies.n - 1)), static_cast<unsigned>(std::min(bodies.n, kMaxRows)));
    allPairsKernel<<<grid, kBlock, 0, stream>>>(bodies, sink);
    GEM_CUDA_CHECK_LAUNCH();
  }
};

}  // namespace

GEM_REGISTER_CUDA_BROADPHASE(DeviceAllPairs, "all_pairs");

}  // namespace gem::cuda
