// The world on the device and one step of the scheduler's device phases (1 to 5 of MODEL.md 8).
// Kept apart from CudaSimulation so that nvcc never sees the scenario's TOML headers: this header
// needs only the world, the event API and the CUDA runtime.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "framework/cuda/cuda_events.hpp"
#include "framework/cuda/device_broadphase.hpp"
#include "framework/world.hpp"

namespace gem::cuda {

struct DeviceState;

// What a step hands back to the host (small; the records only when there are some).
struct DeviceStepResult {
  int candidates = 0, contacts = 0;
  std::vector<ImpactRecord> impacts;  // device order (atomic counter): the caller orders them
  std::vector<BreakRequest> breaks;
  Vec2 vesselImpulse{0, 0};           // N s, this step's contact impulses on the vessel
  Vec2 vesselPosition{0, 0}, vesselVelocity{0, 0};
  Real vesselAngle = 0;
};

class DeviceWorld {
 public:
  DeviceWorld();
  ~DeviceWorld();
  DeviceWorld(const DeviceWorld&) = delete;
  DeviceWorld& operator=(const DeviceWorld&) = delete;

  // Pair and solo drivers run in the order added (the registry's order, as on the CPU).
  void addPairEvent(std::unique_ptr<CudaEventDriver> driver);
  void addSoloEvent(std::unique_ptr<CudaEventDriver> driver);
  void addMotionEvent(std::unique_ptr<CudaEventDriver> driver);
  // Phase 2's strategy (device_broadphase.hpp); nullptr (the default) is the step's own hashed grid.
  void setBroadphase(std::unique_ptr<CudaBroadphase> broadphase);
  const CudaBroadphase* broadphase() const;

  // The whole host world to the device (set-up, after breaks and re-sorts).
  void upload(const World& world, int vesselDof, int vesselSlot);
  // Positions, angles and velocities back into the host world (the rest never changes on the device).
  void download(World& world) const;
  void step(const StepContext& ctx, DeviceStepResult& result);

 private:
  std::unique_ptr<DeviceState> m_state;
};

}  // namespace gem::cuda
