// fixed_radius on the device: fixed_radius.cpp's kept list (centroids within one global radius,
// default 2 x the largest floe radius + skin, or R_a + R_b + skin where that is larger), built,
// checked and filtered on the device by device_neighbour_list.cuh. The global radius is fixed at
// each upload; a break keeps it (every pair's reach is at least R_a + R_b + skin, which covers any
// piece, whatever the largest floe is now).
#include "broadphase/kept_list/device_neighbour_list.cuh"
#include "framework/api/registry.hpp"

namespace gem::cuda {
namespace {

class DeviceFixedRadius final : public DeviceKeptListBroadphase {
 public:
  static constexpr const char* kSettings[] = {"skin", "fixed_radius"};  // honoured on the device too
  explicit DeviceFixedRadius(const BroadphaseSettings& s)
      : DeviceKeptListBroadphase(checkedSettings(s).skin), m_fixedRadius(s.fixedRadius) {}
  // An edit keeps the global radius: the R_a + R_b + skin reach covers the pieces (see the top).
  void upload(const World& world) override {
    uploadList(world, m_fixedRadius > 0 ? m_fixedRadius : 2 * largestFloeRadius(world) + m_list.skin());
  }
  void enqueue(const BroadphaseBodies& bodies, const CandidateSink& sink, cudaStream_t stream) override {
    m_list.enqueue(bodies, sink, stream, AcceptAll{});
  }

 private:
  Real m_fixedRadius;
};

}  // namespace

GEM_REGISTER_CUDA_BROADPHASE(DeviceFixedRadius, "fixed_radius");

}  // namespace gem::cuda
