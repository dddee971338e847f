// variable_radius on the device: the kept list of variable_radius.cpp (|c_a - c_b| <= R_a + R_b +
// skin at the build, R_a + R_b each step), built, checked and filtered on the device by
// device_neighbour_list.cuh. Everything runs on the device, inside the step's graph.
#include "broadphase/kept_list/device_neighbour_list.cuh"
#include "framework/api/registry.hpp"

namespace gem::cuda {
namespace {

class DeviceVariableRadius final : public DeviceKeptListBroadphase {
 public:
  static constexpr const char* kSettings[] = {"skin"};  // honoured on the device too
  explicit DeviceVariableRadius(const BroadphaseSettings& s) : DeviceKeptListBroadphase(checkedSettings(s).skin) {}
  void upload(const World& world) override { uploadList(world, 0); }  // |c_a - c_b| <= (R_a + skin / 2) + (R_b + skin / 2)
  void enqueue(const BroadphaseBodies& bodies, const CandidateSink& sink, cudaStream_t stream) override {
    m_list.enqueue(bodies, sink, stream, AcceptAll{});
  }
};

}  // namespace

GEM_REGISTER_CUDA_BROADPHASE(DeviceVariableRadius, "variable_radius");

}  // namespace gem::cuda
