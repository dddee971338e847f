// The CUDA backend: the scheduler of framework/step/cpu_stepper.cpp (docs/model.md 8) with the world on the
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
//     The resident driver cuts them in its kernel instead (resident_kernel.cuh breakFloes), and
//     the mirror follows after the batch (followDeviceEdit); the host's way is its fallback for a
//     world that ran out of room for new floes.
// The whole step is one captured CUDA graph, the body of a device-side loop: copy_back_every steps
// run as one launch, and their results (a small record per step, the impacts and logs) are copied
// off once, through pinned buffers (thesis 5.7). step() then hands them out one step at a time.
// A batch never runs past a step whose state the host needs: a frame, a re-sort, the run's last
// step, or a break the host makes (the device stops itself there).
//
// A device state may hold several cases (CudaStepper::together): a world each, with its own
// Params, vessel and records, its bodies never paired with another world's (gem sweep, issue 5).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "framework/step/stepper.hpp"

namespace gem {

class CpuStepper;

class CudaBatch;

class CudaStepper final : public Stepper {
 public:
  explicit CudaStepper(const Scenario& scenario);  // alone on its device state
  // Several cases in one device state, a world each, so that small cases fill the GPU (gem sweep
  // batches them). Each steps exactly as it would alone, bit for bit: its bodies keep the order
  // of its own run, its events their own Params. They share the step loop, so they are stepped
  // together: every case's step k before any case's step k + 1 (runScenariosTogether does). The
  // scenarios must agree on batchKey (else BackendUnsupported says what differs).
  static std::vector<std::unique_ptr<CudaStepper>> together(const std::vector<const Scenario*>& scenarios);
  // What cases must share to run together: "" when a scenario cannot share a device state (a
  // device broadphase other than the built-in uniform_grid, which alone keeps worlds apart).
  static std::string batchKey(const Scenario& scenario);
  ~CudaStepper() override;

  void step() override;
  long stepIndex() const override { return m_step; }
  Real time() const override { return m_time; }
  const World& hostWorld() override;
  VesselSample vessel() override;
  const StepRecords& records() const override { return m_records; }
  int contactCount() const override { return m_contactCount; }
  Vec2 vesselIceForce() const override { return m_vesselIceForce; }
  double rubbleMass() const override { return m_rubbleMass; }
  long floesBroken() const override { return m_floesBroken; }
  std::string device() const override { return m_deviceName; }
  std::string backend() const override { return "cuda"; }
  std::string driver() const override;  // "resident" or "device"
  double deviceSeconds() const override;
  int candidateCount() const { return m_candidateCount; }  // over the whole device state
  int casesOnDevice() const;                               // 1 alone, the batch's size when run together
  // Checkpoints, alone on a device state only; the state is on the host between copy-back batches.
  bool stateOnHost() const override { return !deviceAhead(); }
  // Each body's contact force over the last step, alone on a device state and between batches
  // (frames are); null otherwise.
  const std::vector<std::pair<std::int64_t, Real>>* contactForces() const override;
  StepperState saveState() override;
  void restoreState(const StepperState& state) override;
  // Rebuilds of the device broadphase's kept list (0 for one that keeps none): reads the device.
  long broadphaseRebuilds() const;
  // Launches of the resident kernel so far (0 on the device-wide driver): breaks no longer end one.
  long residentLaunches() const;
  // Those of them that re-sorted along the curve in the kernel (nor does a re-sort end one).
  long residentResortLaunches() const;
  // Tests, alone only: run the topology phase through a whole-world round trip (download, edit,
  // upload), the reference that the device edit must match bit for bit.
  void setTopologyThroughHost(bool on) { m_topologyThroughHost = on; }

 private:
  friend class CudaBatch;
  struct Member {};
  CudaStepper(const Scenario& scenario, Member);  // a case of a batch; the batch attaches itself

  void downloadState();                               // device kinematics -> host mirror
  bool deviceAhead() const;                           // the device has run steps that step() has not handed out yet
  void runTopology();                                 // phase 6 on the mirror, replayed on the device (CudaBatch::addEdit)
  void followReorder(const std::vector<int>& order);  // a device re-sort of this world's bodies
  // A topology edit of this world (runTopology's, or the resident kernel's) in the mirror's order.
  void followEdit(const std::vector<int>& removedDevice, const std::vector<int>& removedMirror, int firstAdded);
  void followDeviceEdit(const std::vector<std::int64_t>& removed, const World& added, std::int64_t nextId);
  void flushPendingOrder();              // the mirror into the device's order
  void locateVessel();                   // m_vesselSlot from the mirror (in the device's order)
  int mirrorSlot(int deviceSlot) const;  // the host mirror's row of a device slot
  const std::vector<int>& slotOfId();

  World& world();  // the host mirror (the CPU simulation's world, never stepped there)
  const Scenario& scenario() const;

  static int bindThreadToDevice();     // the worker's device (useCudaDeviceForWorker), before any CUDA call
  int m_deviceOrdinal;                 // first: every member after it lives on this device
  std::unique_ptr<CpuStepper> m_cpu;   // parses the events (and runs the topology ones) and holds the host world
  std::shared_ptr<CudaBatch> m_batch;  // the device state, alone or shared
  int m_world = 0;                     // this case's world in it
  bool m_hostCurrent = true;
  // Device slots below are this world's own, in the device's order (with several worlds, the
  // batch maps them to the shared slots). Re-sorts on the device leave the host mirror in the old
  // order: device slot k holds the mirror's body m_pendingOrder[k]. Applied (World::permute) when
  // the host next needs its world.
  std::vector<int> m_pendingOrder;
  std::vector<int> m_slotOfId;  // device slot of each body id (-1: gone), for ordering records; empty: stale
  bool m_topologyThroughHost = false;
  std::string m_deviceName;
  long m_step = 0;
  long m_taken = 0;  // steps whose results step() has handed out (the step in progress included)
  Real m_time = 0;
  std::int64_t m_vesselId = -1;
  int m_vesselSlot = -1;
  int m_contactCount = 0, m_candidateCount = 0;
  StepRecords m_records;  // the last step's rows, this case's, in the CPU's order
  Vec2 m_vesselIceForce{0, 0};
  VesselSample m_vessel{false, {0, 0}, 0, {0, 0}};
  double m_rubbleMass = 0;
  long m_floesBroken = 0;
  mutable std::vector<std::pair<std::int64_t, Real>> m_contactForces;  // contactForces()' answer
};

// True when the CUDA runtime sees at least one device (never throws).
bool cudaAvailable();
// The current device's name; with several devices, which one ("NVIDIA H200 (device 1 of 2)").
std::string cudaDeviceName();
// The CudaSimulations this host thread makes from now on run on device `worker` modulo the count.
void useCudaDeviceForWorker(int worker);

}  // namespace gem
