// The CUDA backend: the scheduler of framework/simulation.cpp (MODEL.md 8) with the world on the
// device for the whole run. Per step, on one stream:
//   1 prepare: world vertices, boxes, the pair/solo views of every body
//   2 broadphase: the scenario's, on the device (device_broadphase.hpp; broadphase/NAME.cu), its pairs
//     radix-sorted by (a, b) as on the CPU; uniform_grid is the step's own hashed grid (cell key per
//     body, CUB radix sort, 3 x 3 search, each body's partners j > i sorted, counts -> scan -> write)
//   3 narrowphase (box prefilter, computeContact), compacted in order by a scan; onset by binary
//     search in the previous step's sorted contact id pairs
//   4 pair events, solo events (the same evaluator structs as the CPU, templated kernels)
//   5 gather: each body sums its contacts in contact order (no floating-point atomics), motion
//   6 topology on the host (flexural_breaking), only in the rare steps that asked for a break.
// The whole step is one captured CUDA graph (re-captured when the body count or the candidate
// capacity changes); the host syncs once per step, on a small pinned record of counters.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "framework/stepper.hpp"

namespace gem {

class Simulation;

namespace cuda {
class DeviceWorld;
struct DeviceStepResult;
}

class CudaSimulation final : public Stepper {
 public:
  explicit CudaSimulation(const Scenario& scenario);
  ~CudaSimulation() override;

  void step() override;
  long stepIndex() const override { return m_step; }
  Real time() const override { return m_time; }
  const World& hostWorld() override;
  VesselSample vessel() override;
  const std::vector<ImpactRecord>& impacts() const override { return m_impacts; }
  int contactCount() const override { return m_contactCount; }
  Vec2 vesselIceForce() const override { return m_vesselIceForce; }
  double rubbleMass() const override { return m_rubbleMass; }
  long floesBroken() const override { return m_floesBroken; }
  std::string device() const override { return m_deviceName; }
  std::string backend() const override { return "cuda"; }
  int candidateCount() const { return m_candidateCount; }
  // Rebuilds of the device broadphase's kept list (0 for one that keeps none): reads the device.
  long broadphaseRebuilds() const;

 private:
  void upload();          // host world -> device (all arrays), after set-up, breaks and re-sorts
  void downloadState();   // device kinematics -> host world
  void reorderAlongCurve();

  World& world();                     // the host mirror (the CPU simulation's world, never stepped there)
  const Scenario& scenario() const;

  std::unique_ptr<Simulation> m_cpu;  // parses the events (and runs the topology ones) and holds the host world
  bool m_hostCurrent = true;
  std::unique_ptr<cuda::DeviceWorld> m_device;
  cuda::DeviceStepResult* m_result = nullptr;  // owned by m_resultStore
  std::unique_ptr<cuda::DeviceStepResult> m_resultStore;
  std::string m_deviceName;
  long m_step = 0;
  Real m_time = 0;
  std::int64_t m_vesselId = -1;
  int m_vesselSlot = -1;
  int m_contactCount = 0, m_candidateCount = 0;
  std::vector<ImpactRecord> m_impacts;
  std::vector<BreakRequest> m_breaks;
  Vec2 m_vesselIceForce{0, 0};
  VesselSample m_vessel{false, {0, 0}, 0, {0, 0}};
  double m_rubbleMass = 0;
  long m_floesBroken = 0;
};

// True when the CUDA runtime sees at least one device (never throws).
bool cudaAvailable();
std::string cudaDeviceName();

}  // namespace gem
