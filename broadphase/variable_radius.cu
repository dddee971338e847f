// variable_radius on the device: the kept list of variable_radius.cpp (|c_a - c_b| <= R_a + R_b +
// skin at the build, R_a + R_b each step), built, checked and filtered on the device by
// device_neighbour_list.cuh. Everything runs on the device, inside the step's graph.
#include "broadphase/device_neighbour_list.cuh"
#include "framework/registry.hpp"

namespace gem::cuda {
namespace {

class DeviceVariableRadius final : public CudaBroadphase {
 public:
  explicit DeviceVariableRadius(const BroadphaseSettings& s) : m_list(checkedSettings(s).skin) {}
  void upload(const World& world) override {
    // |c_a - c_b| <= (R_a + skin / 2) + (R_b + skin / 2), as variable_radius.cpp.
    std::vector<Real> half(world.radius.begin(), world.radius.end());
    for (Real& h : half) h += m_list.skin() / 2;
    m_list.upload(world, half, 0);
  }
  void reserve(cudaStream_t) override { m_list.reserve(); }
  bool reorder(const int* order, int n, cudaStream_t stream) override {
    m_list.reorder(order, n, stream);
    return true;
  }
  bool edited(const int* keptOrder, int kept, const World& after, int firstAdded, cudaStream_t stream) override {
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
};

}  // namespace

GEM_REGISTER_CUDA_BROADPHASE(DeviceVariableRadius, "variable_radius");

}  // namespace gem::cuda
