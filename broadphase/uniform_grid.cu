// uniform_grid on the device is the step's own hashed grid (framework/cuda/broadphase_grid.cu, phase
// 2): a loose grid rebuilt every step from the boxes, each body's partners written already sorted
// by (a, b), so it needs no kept list and no sort of its pairs. Its entry here is a factory that
// returns no strategy object, which DeviceStep reads as "use the built-in grid".
#include "framework/api/device_broadphase.hpp"

namespace gem::cuda {

// cell_size reaches the grid through DeviceStep::setGridCell (framework/cuda/cuda_stepper.cpp).
static const RegisterCudaBroadphase kUniformGrid{
    "uniform_grid", [](const BroadphaseSettings&) -> std::unique_ptr<CudaBroadphase> { return nullptr; }, {"cell_size"}};

}  // namespace gem::cuda
