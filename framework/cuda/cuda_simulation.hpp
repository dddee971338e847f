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
//   6 topology (flexural_breaking), only in the steps that asked for a break: the events cut the
//     floes on the host mirror (the few bodies named fetched first) and the device replays the
//     edit (survivors compacted in order, new floes appended, ids stable): the world stays put.
// The whole step is one captured CUDA graph, the body of a device-side loop: copy_back_every steps
// run as one launch, and their results (a small record per step, the impacts and logs) are copied
// off once, through pinned buffers (thesis 5.7). step() then hands them out one step at a time.
// A batch never runs past a step whose state the host needs: a frame, a re-sort, the run's last
// step, or a break (the device stops itself there).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "framework/stepper.hpp"

namespace gem {

class Simulation;

namespace cuda {
class DeviceWorld;
struct DeviceBatchResult;
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
  // Tests: run the topology phase through a whole-world round trip (download, edit, upload), the
  // reference that the device edit must match bit for bit.
  void setTopologyThroughHost(bool on) { m_topologyThroughHost = on; }

 private:
  void upload();          // host world -> device (all arrays), after set-up, breaks and re-sorts
  void downloadState();   // device kinematics -> host world
  void runBatch();        // the next batch of steps on the device
  bool deviceAhead() const;  // the device has run steps that step() has not handed out yet
  void runTopology();        // phase 6 on the mirror, replayed on the device
  void reSortAlongCurve();
  int mirrorSlot(int deviceSlot) const;  // the host mirror's row of a device slot
  const std::vector<int>& slotOfId();

  World& world();                     // the host mirror (the CPU simulation's world, never stepped there)
  const Scenario& scenario() const;

  static int bindThreadToDevice();  // the worker's device (useCudaDeviceForWorker), before any CUDA call
  int m_deviceOrdinal;               // first: every member after it lives on this device
  std::unique_ptr<Simulation> m_cpu;  // parses the events (and runs the topology ones) and holds the host world
  bool m_hostCurrent = true;
  // Re-sorts on the device leave the host mirror in the old slot order: device slot k holds the
  // mirror's body m_pendingOrder[k]. Applied (World::permute) when the host next needs its world.
  std::vector<int> m_pendingOrder;
  std::vector<int> m_slotOfId;  // device slot of each body id (-1: gone), for ordering records; empty: stale
  bool m_topologyThroughHost = false;
  std::unique_ptr<cuda::DeviceWorld> m_device;
  std::unique_ptr<cuda::DeviceBatchResult> m_batch;
  size_t m_batchNext = 0;  // the batch's next step to hand out
  std::string m_deviceName;
  long m_step = 0;
  Real m_time = 0;
  std::int64_t m_vesselId = -1;
  int m_vesselSlot = -1;
  int m_contactCount = 0, m_candidateCount = 0;
  std::vector<ImpactRecord> m_impacts;
  std::vector<BreakRequest> m_breaks;
  std::vector<LogRecord> m_logs;
  Vec2 m_vesselIceForce{0, 0};
  VesselSample m_vessel{false, {0, 0}, 0, {0, 0}};
  // Host wall time by part (GEM_CUDA_TIMING=1 prints it when the run ends), s.
  struct HostTimes {
    long batches = 0, topologies = 0, resorts = 0;
    double batch = 0, fetch = 0, events = 0, edit = 0, bookkeeping = 0, resort = 0, ordering = 0;
  } m_times;
  double m_rubbleMass = 0;
  long m_floesBroken = 0;
};

// True when the CUDA runtime sees at least one device (never throws).
bool cudaAvailable();
// The current device's name; with several devices, which one ("NVIDIA H200 (device 1 of 2)").
std::string cudaDeviceName();
// The CudaSimulations this host thread makes from now on run on device `worker` modulo the count.
void useCudaDeviceForWorker(int worker);

}  // namespace gem
