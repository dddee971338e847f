// fixed_radius on the device: fixed_radius.cpp's kept list (centroids within one global radius,
// default 2 x the largest floe radius + skin, or R_a + R_b + skin where that is larger), built,
// checked and filtered on the device by device_neighbour_list.cuh. The global radius is fixed at
// each upload; a break keeps it (every pair's reach is at least R_a + R_b + skin, which covers any
// piece, whatever the largest floe is now).
#include "broadphase/device_neighbour_list.cuh"
#include "framework/registry.hpp"

namespace gem::cuda {
namespace {

class DeviceFixedRadius final : public CudaBroadphase {
 public:
  explicit DeviceFixedRadius(const BroadphaseSettings& s) : m_list(checkedSettings(s).skin), m_fixedRadius(s.fixedRadius) {}
  void upload(const World& world) override {
    const Real skin = m_list.skin();
    std::vector<Real> half(world.radius.begin(), world.radius.end());
    for (Real& h : half) h += skin / 2;
    m_list.upload(world, half, m_fixedRadius > 0 ? m_fixedRadius : 2 * largestFloeRadius(world) + skin);
  }
  void reserve(cudaStream_t) override { m_list.reserve(); }
  bool reorder(const int* order, int n, cudaStream_t stream) override {
    m_list.reorder(order, n, stream);
    return true;
  }
  bool edited(const int* keptOrder, int kept, const World& after, int firstAdded, cudaStream_t stream) override {
    // The global radius stays: the R_a + R_b + skin reach covers the pieces (see the top).
    std::vector<Real> half;
    std::vector<unsigned char> always;
    appendedListInputs(after, firstAdded, m_list.skin(), half, always);
    m_list.edited(keptOrder, kept, half, always, stream);
    return true;
  }
  void enqueue(const BroadphaseBodies& bodies, const CandidateSink& sink, cudaStream_t stream) override {
    m_list.enqueue(bodies, sink, stream, AcceptAll{});
  }
  long rebuilds() const override { return m_list.rebuilds(); }

 private:
  DeviceNeighbourList m_list;
  Real m_fixedRadius;
};

}  // namespace

GEM_REGISTER_CUDA_BROADPHASE(DeviceFixedRadius, "fixed_radius");

}  // namespace gem::cuda
