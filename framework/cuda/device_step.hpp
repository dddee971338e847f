// The world on the device and one step of the scheduler's device phases (1 to 5 of docs/model.md 8).
// Kept apart from CudaStepper so that nvcc never sees the scenario's TOML headers: this header
// needs only the world, the event API and the CUDA runtime.
#pragma once
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "framework/api/cuda_events.hpp"
#include "framework/api/device_broadphase.hpp"
#include "framework/world/world.hpp"

namespace gem::cuda {

struct DeviceState;
struct ResidentProgram;

// One completed step's results, as the device's step graph writes them into its ring. The record
// ends index the batch's rows of each record stream: step s's rows of stream q are
// [steps[s-1].recordEnd[q], steps[s].recordEnd[q]).
struct StepRecord {
  int candidates, contacts;  // over all worlds
  int recordEnd[kMaxRecordStreams];
};

// One world's share of a completed step. A device state holds one world per case: one for a run,
// several when a sweep batches its cases (upload's worldOf); bodies of two worlds never touch.
struct WorldStepRecord {
  int contacts;
  Vec2 vesselImpulse;                   // N s, this step's contact impulses on the world's vessel
  Vec2 vesselPosition, vesselVelocity;  // after the step (zero in a world without a vessel)
  Real vesselAngle;
  // The resident driver's breaks in the kernel (resident_kernel.cuh): 1 when the kernel ran this
  // world's topology phase itself this step (the host's then has nothing to do), with the floes it
  // broke and the mass that left as rubble (kg), as FlexuralBreaking::apply counts them.
  int topologyOnDevice, floesBroken;
  Real rubbleMass;
};

// What the resident driver's breaks in the kernel changed during a run of steps (the device state
// is dense again when run() returns: DeviceStep::editBodies made it so, and a run stops after the
// launch that changed it). removedIds: device ids of the bodies that left (broken floes; ids made
// and broken within the launch among them, which no mirror knows); added: the new
// bodies that remain, as on the device after the run (shapes, mass properties and kinematics),
// their worlds addedWorlds; nextIds: per world, its next free id (the case's own, not shifted).
struct DeviceBodyEdits {
  std::vector<std::int64_t> removedIds;
  World added;
  std::vector<int> addedWorlds;
  std::vector<std::int64_t> nextIds;
  bool empty() const { return removedIds.empty(); }
};

// What a run of steps hands back: copied off the device once, through pinned buffers, at its end
// (thesis 5.7). The rows of a step are in device order (atomic counters): the caller orders them by
// their tags (event, contact) and, with several worlds, keeps its own (tag.world).
struct DeviceBatchResult {
  int worlds = 1;
  std::vector<StepRecord> steps;
  std::vector<WorldStepRecord> worldSteps;                // steps.size() x worlds: step s's world w at s * worlds + w
  std::vector<unsigned char> records[kMaxRecordStreams];  // rows (RecordTag + record) of each stream
  DeviceBodyEdits edits;                                  // the resident kernel's breaks (empty: none)
  // The resident kernel's re-sort along the curve, after the edits (empty: none): new slot k holds
  // slot order[k] of the state as the edits left it, whose worlds were worldBefore.
  std::vector<int> order, worldBefore;
  bool hostTopology = false;  // the last step's topology is the host's (a launch stopped for it)
};

class DeviceStep {
 public:
  DeviceStep();
  ~DeviceStep();
  DeviceStep(const DeviceStep&) = delete;
  DeviceStep& operator=(const DeviceStep&) = delete;

  // Pair and solo drivers run in the order added (the registry's order, as on the CPU).
  void addPairEvent(std::unique_ptr<CudaEventDriver> driver);
  void addSoloEvent(std::unique_ptr<CudaEventDriver> driver);
  void addMotionEvent(std::unique_ptr<CudaEventDriver> driver);
  // Phase 2's strategy (device_broadphase.hpp); nullptr (the default) is the step's own hashed grid.
  void setBroadphase(std::unique_ptr<CudaBroadphase> broadphase);
  // The step's own grid (uniform_grid): its cell, m; 0 = twice the largest floe's bounding radius.
  void setGridCell(Real cellSize);
  // The run's record streams: each one's row stride (bytes), and the streams whose rows end a batch
  // (a topology event reads them: the host's topology phase comes next), one bit each.
  void setRecordStreams(const std::vector<int>& strides, unsigned haltStreams);
  // Several worlds: body ids on the device are world x idStride + the case's own id; the views the
  // events see (PairBody::id) carry the case's own, so that their records need no translation.
  void setIdStride(std::int64_t idStride);
  const CudaBroadphase* broadphase() const;

  // The whole host world to the device (set-up, after breaks and re-sorts). worldOf[i] is body i's
  // world (empty: all in world 0); vesselSlots[w] world w's vessel (-1: none) and vesselDofs[w]
  // its degrees of freedom; the number of worlds is vesselSlots.size(). Bodies of different worlds
  // never make a pair, and each world's bodies should keep the order of its own run (ascending
  // slots), so that its sums are those of that run: then each world steps bit for bit as alone.
  void upload(const World& world, const std::vector<int>& worldOf, const std::vector<int>& vesselSlots, const std::vector<int>& vesselDofs);
  // One world holding everything (a single run).
  void upload(const World& world, int vesselDof, int vesselSlot) { upload(world, {}, {vesselSlot}, {vesselDof}); }
  int worlds() const;
  // Each device slot's world, on the host (follows re-sorts and edits).
  const std::vector<int>& worldOfSlots() const;
  // Re-sorts the bodies along the curve on the device, as World::curveOrder + World::permute do on
  // the host, bit for bit: world by world (each world's curve over its own bodies' box), worlds in
  // ascending order. Returns the order (new slot k holds old slot order[k]) so that the host
  // can apply it to its mirror when it next needs it. The captured graph stays valid unless a
  // device broadphase could not follow the new order (CudaBroadphase::reorder): then
  // *broadphaseFollowed is false and the caller uploads the world.
  std::vector<int> reorderAlongCurve(bool* broadphaseFollowed);
  // Positions, angles and velocities back into the host world (the rest changes on the device only
  // through editBodies, which the host made first). One world only.
  void download(World& world) const;
  // The same for a few bodies only: device slot deviceSlots[k] into host row hostSlots[k] (the
  // topology phase reads only the bodies its requests name).
  void downloadKinematics(const std::vector<int>& deviceSlots, const std::vector<int>& hostSlots, World& world) const;
  // A topology edit, replayed on the device without moving the world: the bodies at removedSlots
  // (ascending) leave, the others keep their order and their state, and the bodies
  // added[firstAdded..] (made on the host by World::addBody) are appended, body k of them into world
  // addedWorlds[k] (empty: world 0). vesselDofs: per world, as upload's. Returns false when the
  // device broadphase could not follow (CudaBroadphase::edited): the caller then hands it the
  // world in the device's order (uploadBroadphase).
  bool editBodies(const std::vector<int>& removedSlots, const World& added, int firstAdded, const std::vector<int>& addedWorlds,
                  const std::vector<int>& vesselDofs);
  // The device broadphase rebuilds its per-body storage from the host world (in the device's order).
  void uploadBroadphase(const World& world);
  // The resident driver (framework/cuda/resident.cuh) steps from now on: each world's whole step in
  // one thread block. program: the events as the resident kernel holds them; params: worlds rows of
  // paramsStride bytes, the Params of world w's events at the program's offsets.
  // resort: the kernel re-sorts each world along the curve every kResortPeriod steps itself (the
  // scenario's morton_sort), so that a re-sort ends no launch either.
  void useResident(const ResidentProgram& program, const std::vector<unsigned char>& params, int paramsStride, bool resort);
  bool resident() const;
  // The resident driver's breaks in the kernel give new bodies the next ids of their world: each
  // world's next free id (the case's own), before each run.
  void setNextIds(const std::vector<std::int64_t>& nextIds);
  // Launches of the resident kernel so far (a break in the kernel no longer ends one).
  long residentLaunches() const;
  // Those of them whose kernel re-sorted a world along the curve (a re-sort no longer ends one).
  long residentResortLaunches() const;
  // Steps kept on the device between two copies to the host (the ring's length), and threads per
  // block of the per-body and per-contact kernels. Before the first run.
  void configure(int copyBackEvery, int blockSize);
  // Runs `steps` steps from step index firstStep (time = index x dt) without the host, and then
  // copies their results off. Stops early after a step that asked for a break (the host's topology
  // phase comes next), and on the resident driver after a launch whose kernel broke floes or
  // re-sorted (result.edits, result.order: the host's mirrors follow). A step that overflowed a buffer is redone, bit-identically, with
  // more room.
  void run(long firstStep, Real dt, int steps, DeviceBatchResult& result);
  // One world: each body's |sum of its contact impulses| over the last step (N s), by id, ids
  // [0, nextId) (0 for a body without contact, or gone).
  std::vector<Real> contactImpulsesById(std::int64_t nextId) const;
  // Checkpoints (one world only): the id pairs in contact after the last step, lower id first,
  // sorted (a contact's onset compares against them), and the same set on a state just uploaded.
  std::vector<std::pair<std::int64_t, std::int64_t>> touchingPairs() const;
  void setTouchingPairs(const std::vector<std::pair<std::int64_t, std::int64_t>>& pairs);
  // Step graphs captured and instantiated so far, and the host's seconds for them (a change of
  // the body count, a topology edit, makes the next batch capture anew).
  std::pair<long, double> captures() const;

 private:
  std::unique_ptr<DeviceState> m_state;
};

}  // namespace gem::cuda
