// The CUDA backend's host side: set-up from the scenario (through the CPU CpuStepper, which parses
// and checks every event), record ordering, the topology phase and the periodic re-sort.
#include "framework/cuda/cuda_stepper.hpp"

#include <cuda_runtime.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "framework/api/cuda_check.hpp"
#include "framework/cuda/cuda_batch.hpp"
#include "framework/cuda/device_step.hpp"
#include "framework/api/log_channel.hpp"
#include "framework/api/registry.hpp"
#include "framework/step/phases.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/step/stepper.hpp"

namespace gem {

bool cudaAvailable() {
  static const bool available = [] {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess) {
      cudaGetLastError();  // "no device" is an answer, not an error to leave pending
      return false;
    }
    return count > 0;
  }();
  return available;
}

static int deviceCount() {
  int count = 0;
  return cudaAvailable() && cudaGetDeviceCount(&count) == cudaSuccess ? count : 0;
}

std::string cudaDeviceName() {
  if (!cudaAvailable()) return "none";
  int device = 0;
  cudaDeviceProp prop{};
  if (cudaGetDevice(&device) != cudaSuccess || cudaGetDeviceProperties(&prop, device) != cudaSuccess) return "unknown CUDA device";
  const int count = deviceCount();
  // With several devices the summary says which one ran the case (a sweep spreads its cases).
  return count > 1 ? std::string(prop.name) + " (device " + std::to_string(device) + " of " + std::to_string(count) + ")" : prop.name;
}

// The device of the runs this host thread makes next (-1: the runtime's current one, device 0).
static thread_local int t_workerDevice = -1;

void useCudaDeviceForWorker(int worker) {
  const int count = deviceCount();
  t_workerDevice = count > 0 ? worker % count : -1;
}

int CudaStepper::bindThreadToDevice() {
  int device = 0;
  if (t_workerDevice >= 0) GEM_CUDA_CHECK(cudaSetDevice(t_workerDevice));
  GEM_CUDA_CHECK(cudaGetDevice(&device));
  return device;
}

World& CudaStepper::world() { return m_cpu->world(); }
const Scenario& CudaStepper::scenario() const { return m_cpu->scenario(); }

std::string CudaStepper::batchKey(const Scenario& s) {
  // The device-wide driver keeps worlds apart only with its own grid (uniform_grid); the resident
  // driver, a block per world, with any broadphase. A plugin's events have no place in the resident
  // kernel, so with one only uniform_grid cases share a device.
  if (s.broadphase != "uniform_grid" && (s.cudaDriver == "device" || !s.plugins.empty())) return "";
  std::string key =
      fmt::format("dt={} steps={} copy_back_every={} block={} morton={} frames={} vessel_dof={} cell={} driver={} broadphase={}", s.dt,
                  s.steps, s.copyBackEvery, s.cudaBlockSize, s.mortonSort, s.output.frameEvery, s.vessel.dof, s.broadphaseSettings.cellSize,
                  s.cudaDriver, s.broadphase);
  for (const auto& [name, setting] : s.events) key += fmt::format(" {}={}", name, setting.enabled);
  for (const PluginSpec& p : s.plugins) key += fmt::format(" plugin={}{}", p.path.string(), p.override ? "!" : "");
  return key;
}

long CudaStepper::broadphaseRebuilds() const {
  const cuda::CudaBroadphase* b = m_batch->device().broadphase();
  return b ? b->rebuilds() : 0;
}

long CudaStepper::residentLaunches() const { return m_batch->device().residentLaunches(); }
long CudaStepper::residentResortLaunches() const { return m_batch->device().residentResortLaunches(); }

std::string CudaStepper::driver() const { return m_batch->device().resident() ? "resident" : "device"; }

double CudaStepper::deviceSeconds() const { return m_batch->times.batch; }

int CudaStepper::casesOnDevice() const { return m_batch->worlds(); }

CudaStepper::CudaStepper(const Scenario& scenario, Member)
    : m_deviceOrdinal(bindThreadToDevice()), m_cpu(std::make_unique<CpuStepper>(scenario)), m_deviceName(cudaDeviceName()) {
  const World& w = world();
  for (int i = 0; i < w.size(); ++i)
    if (w.kind[i] == BodyKind::Vessel) m_vesselId = w.id[i];
  m_records.reset(m_cpu->recordStreams());
}

CudaStepper::CudaStepper(const Scenario& scenario) : CudaStepper(scenario, Member{}) {
  m_batch = std::make_shared<CudaBatch>(std::vector<CudaStepper*>{this}, m_deviceOrdinal);
}

std::vector<std::unique_ptr<CudaStepper>> CudaStepper::together(const std::vector<const Scenario*>& scenarios) {
  if (scenarios.empty()) return {};
  const std::string key = batchKey(*scenarios.front());
  for (const Scenario* s : scenarios) {
    const std::string own = batchKey(*s);
    if (own.empty() || own != key)
      throw BackendUnsupported(own.empty()
                                   ? "scenario " + s->file.string() + " cannot share a device state (its broadphase is not uniform_grid)"
                                   : "scenarios " + scenarios.front()->file.string() + " and " + s->file.string() +
                                         " differ in what cases run together must share: " + key + " | " + own);
  }
  // The cases' set-up (parsing, field generation: CPU work, tens of ms each for the load study's
  // fields) on the host's cores, every thread on this thread's device.
  const size_t count = scenarios.size();
  std::vector<std::unique_ptr<CudaStepper>> members(count);
  std::vector<std::exception_ptr> errors(count);
  const int device = bindThreadToDevice();
  std::atomic<size_t> next{0};
  auto setUp = [&] {
    if (cudaSetDevice(device) != cudaSuccess) return;  // the constructor's own CUDA calls then say why
    for (size_t i = next++; i < count; i = next++) {
      try {
        members[i].reset(new CudaStepper(*scenarios[i], Member{}));
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> threads;
  const size_t helpers = std::min<size_t>(count, std::max(1u, std::thread::hardware_concurrency())) - 1;
  for (size_t t = 0; t < helpers; ++t) threads.emplace_back(setUp);
  setUp();
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  std::vector<CudaStepper*> raw;
  for (const auto& m : members) raw.push_back(m.get());
  auto batch = std::make_shared<CudaBatch>(raw, members.front()->m_deviceOrdinal);
  for (auto& m : members) m->m_batch = batch;
  for (size_t w = 0; w < members.size(); ++w) members[w]->m_world = static_cast<int>(w);
  return members;
}

CudaStepper::~CudaStepper() = default;

const std::vector<std::pair<std::int64_t, Real>>* CudaStepper::contactForces() const {
  if (m_batch->worlds() > 1 || deviceAhead()) return nullptr;
  const World& w = m_cpu->world();  // its ids (the order does not matter here)
  const std::vector<Real> impulses = m_batch->device().contactImpulsesById(w.nextId);
  m_contactForces.clear();
  for (int i = 0; i < w.size(); ++i) {
    const Real force = impulses[static_cast<size_t>(w.id[i])] / m_cpu->scenario().dt;  // as the CPU: |impulse| / dt
    if (force > 0) m_contactForces.emplace_back(w.id[i], force);
  }
  std::sort(m_contactForces.begin(), m_contactForces.end());
  return &m_contactForces;
}

StepperState CudaStepper::saveState() {
  if (m_batch->worlds() > 1) throw BackendUnsupported("cases run together on one device write no checkpoint");
  StepperState state;
  state.world = hostWorld();  // between batches: the device's state at step m_step
  state.step = m_step;
  state.time = m_time;
  state.touching = m_batch->device().touchingPairs();
  state.rubbleMass = m_rubbleMass;
  state.floesBroken = m_floesBroken;
  return state;
}

void CudaStepper::restoreState(const StepperState& state) {
  if (m_batch->worlds() > 1) throw BackendUnsupported("cases run together on one device do not resume from a checkpoint");
  if (m_step != 0) throw std::logic_error("CudaStepper::restoreState: for a stepper that has not stepped");
  m_cpu->restoreState(state);  // the host mirror
  m_step = m_taken = state.step;
  m_time = state.time;
  m_rubbleMass = state.rubbleMass;
  m_floesBroken = state.floesBroken;
  m_pendingOrder.clear();
  m_slotOfId.clear();
  m_hostCurrent = true;
  // A device state made from the restored mirror, as the constructor made one from the scenario's.
  m_batch.reset();
  m_batch = std::make_shared<CudaBatch>(std::vector<CudaStepper*>{this}, m_deviceOrdinal);
  m_batch->device().setTouchingPairs(state.touching);
}

void CudaStepper::locateVessel() {
  const World& w = world();
  m_vesselSlot = -1;
  for (int i = 0; i < w.size(); ++i)
    if (w.id[i] == m_vesselId) m_vesselSlot = i;
}

int CudaStepper::mirrorSlot(int deviceSlot) const {
  return m_pendingOrder.empty() ? deviceSlot : m_pendingOrder[static_cast<size_t>(deviceSlot)];
}

// Device slot by body id (ids are dense: never reused, a few new ones per break): one pass over
// the mirror's ids per world order, not per step (at 10^6 floes a pass per step was most of a step).
const std::vector<int>& CudaStepper::slotOfId() {
  if (m_slotOfId.empty()) {
    const World& w = world();
    m_slotOfId.assign(static_cast<size_t>(w.nextId), -1);
    for (int k = 0; k < w.size(); ++k) m_slotOfId[static_cast<size_t>(w.id[static_cast<size_t>(mirrorSlot(k))])] = k;
  }
  return m_slotOfId;
}

// 6. Topology (flexural breaking), in a step that asked for it. The events run on the host mirror,
// whose structure (shapes, mass properties) is always current; only the kinematics of the bodies
// the requests name are fetched. What they removed and appended is then replayed on the device
// (CudaBatch::addEdit, DeviceStep::editBodies): the world's arrays never cross the bus, only the
// few new bodies do.
void CudaStepper::runTopology() {
  CudaBatch& batch = *m_batch;
  Stopwatch clock;
  ++batch.times.topologies;
  World& w = world();
  const std::vector<int>& slotOf = slotOfId();
  std::vector<int> deviceSlots, hostSlots;
  std::vector<std::int64_t> named;  // the bodies the step's rows name, as the events declare them
  for (const EnabledEvent& e : m_cpu->events())
    if (e.phase == EventPhase::Topology) {
      const std::vector<std::int64_t> ids = e.instance->bodiesRead(m_records);
      named.insert(named.end(), ids.begin(), ids.end());
    }
  for (const std::int64_t id : named) {
    const int k = id >= 0 && id < static_cast<std::int64_t>(slotOf.size()) ? slotOf[static_cast<size_t>(id)] : -1;
    if (k < 0 || std::find(hostSlots.begin(), hostSlots.end(), mirrorSlot(k)) != hostSlots.end()) continue;
    deviceSlots.push_back(batch.sharedSlot(m_world, k));
    hostSlots.push_back(mirrorSlot(k));
  }
  if (m_topologyThroughHost) {
    if (batch.worlds() > 1) throw std::logic_error("CudaStepper::setTopologyThroughHost: for a simulation alone on its device");
    downloadState();  // the reference path (tests): the whole world round trips
  } else {
    batch.device().downloadKinematics(deviceSlots, hostSlots, w);
  }
  batch.times.fetch += clock.lap();

  const std::vector<std::int64_t> idsBefore = w.id;
  const std::int64_t nextIdBefore = w.nextId;
  TopologyData topology{&w, &m_records, m_time};
  for (const EnabledEvent& e : m_cpu->events())
    if (e.phase == EventPhase::Topology) e.instance->runTopology(topology);
  m_rubbleMass += topology.rubbleMass;
  m_floesBroken += topology.floesBroken;
  batch.times.events += clock.lap();
  if (!topology.changed) return;
  if (m_topologyThroughHost) {
    locateVessel();
    batch.uploadAll();
    return;
  }

  // What the events did, as World::removeBodies and World::addBody do it: the survivors keep their
  // order, the new bodies (new ids) follow them.
  int firstAdded = w.size();
  while (firstAdded > 0 && w.id[static_cast<size_t>(firstAdded - 1)] >= nextIdBefore) --firstAdded;
  std::vector<int> removedMirror, removedDevice;
  int survivor = 0;
  for (int i = 0; i < static_cast<int>(idsBefore.size()); ++i) {
    if (survivor < firstAdded && w.id[static_cast<size_t>(survivor)] == idsBefore[static_cast<size_t>(i)]) {
      ++survivor;
    } else {
      removedMirror.push_back(i);
      removedDevice.push_back(slotOf[static_cast<size_t>(idsBefore[static_cast<size_t>(i)])]);
    }
  }
  if (survivor != firstAdded)
    throw std::logic_error(
        "CUDA backend: a topology event reordered the bodies (only World::removeBodies and World::addBody may change them)");
  std::sort(removedDevice.begin(), removedDevice.end());
  batch.times.bookkeeping += clock.lap();
  batch.addEdit(m_world, removedDevice, w, firstAdded);
  followEdit(removedDevice, removedMirror, firstAdded);
  batch.times.bookkeeping += clock.lap();
}

// The device's edit of this world (removedDevice: its device slots, ascending, that left;
// removedMirror: the same bodies' mirror rows, ascending; the mirror's rows from firstAdded on are
// the new bodies, which the device appends in the same order) in the mirror's bookkeeping.
void CudaStepper::followEdit(const std::vector<int>& removedDevice, const std::vector<int>& removedMirror, int firstAdded) {
  const World& w = world();
  // The mirror's order after a device re-sort: device slot j (a survivor) held device slot
  // keptDevice[j], i.e. mirror body pendingOrder[keptDevice[j]], which the removal moved down.
  if (!m_pendingOrder.empty()) {
    std::vector<int> composed;
    composed.reserve(static_cast<size_t>(w.size()));
    size_t r = 0;
    for (int old = 0; old < static_cast<int>(m_pendingOrder.size()); ++old) {
      if (r < removedDevice.size() && removedDevice[r] == old) {
        ++r;
        continue;
      }
      const int mirrorOld = m_pendingOrder[static_cast<size_t>(old)];
      composed.push_back(mirrorOld -
                         static_cast<int>(std::lower_bound(removedMirror.begin(), removedMirror.end(), mirrorOld) - removedMirror.begin()));
    }
    for (int k = firstAdded; k < w.size(); ++k) composed.push_back(k);
    m_pendingOrder.swap(composed);
  }
  m_slotOfId.clear();
  if (m_vesselSlot >= 0) m_vesselSlot = slotOfId()[static_cast<size_t>(m_vesselId)];
}

// The resident kernel's breaks in this world (CudaBatch::followDeviceEdits): the bodies of ids
// `removed` (the case's own; ids unknown here were made and broken within the run) leave the
// mirror, the rows of `added` are appended, as the device has already done it.
void CudaStepper::followDeviceEdit(const std::vector<std::int64_t>& removed, const World& added, std::int64_t nextId) {
  World& w = world();
  const std::vector<int>& slotOf = slotOfId();
  std::vector<int> removedDevice, removedMirror;
  for (const std::int64_t id : removed) {
    const int k = id >= 0 && id < static_cast<std::int64_t>(slotOf.size()) ? slotOf[static_cast<size_t>(id)] : -1;
    if (k < 0) continue;
    removedDevice.push_back(k);
    removedMirror.push_back(mirrorSlot(k));
  }
  std::sort(removedDevice.begin(), removedDevice.end());
  std::sort(removedMirror.begin(), removedMirror.end());
  std::vector<char> remove(static_cast<size_t>(w.size()), 0);
  for (const int i : removedMirror) remove[static_cast<size_t>(i)] = 1;
  w.removeBodies(remove);
  const int firstAdded = w.size();
  for (int k = 0; k < added.size(); ++k) {
    const size_t r = static_cast<size_t>(k);
    w.id.push_back(added.id[r]), w.kind.push_back(added.kind[r]), w.vertexCount.push_back(added.vertexCount[r]);
    w.localVertices.insert(w.localVertices.end(), added.localVertices.begin() + static_cast<std::ptrdiff_t>(r * kMaxVertices),
                           added.localVertices.begin() + static_cast<std::ptrdiff_t>((r + 1) * kMaxVertices));
    for (auto real : {&World::x, &World::y, &World::angle, &World::vx, &World::vy, &World::omega, &World::area, &World::thickness,
                      &World::mass, &World::invMass, &World::invInertia, &World::gyration2, &World::gyrationX2, &World::gyrationY2,
                      &World::principalAngle, &World::radius})
      (w.*real).push_back((added.*real)[r]);
  }
  w.nextId = std::max(w.nextId, nextId);
  followEdit(removedDevice, removedMirror, firstAdded);
}

void CudaStepper::flushPendingOrder() {
  if (m_pendingOrder.empty()) return;
  world().permute(m_pendingOrder);
  m_pendingOrder.clear();
}

void CudaStepper::downloadState() {
  if (m_hostCurrent) return;
  if (deviceAhead()) throw std::logic_error("CUDA backend: the world was asked for in the middle of a copy-back batch");
  flushPendingOrder();
  CudaBatch& batch = *m_batch;
  if (batch.worlds() == 1) {
    batch.device().download(world());
  } else {
    const std::vector<int>& shared = batch.slotsOfWorld(m_world);
    std::vector<int> rows(shared.size());
    for (size_t k = 0; k < rows.size(); ++k) rows[k] = static_cast<int>(k);
    batch.device().downloadKinematics(shared, rows, world());
  }
  m_hostCurrent = true;
}

bool CudaStepper::deviceAhead() const { return m_taken < m_batch->resultFirst() + static_cast<long>(m_batch->result().steps.size()); }

const World& CudaStepper::hostWorld() {
  // Batches end where the runner needs the state (frames, the last step): downloadState refuses a
  // caller that asks elsewhere, who would get a later state than the step it is at.
  downloadState();
  return world();
}

VesselSample CudaStepper::vessel() {
  if (m_vesselSlot < 0) return VesselSample{false, {0, 0}, 0, {0, 0}};
  if (m_hostCurrent) {
    const World& w = world();
    return VesselSample{true, w.position(m_vesselSlot), w.angle[m_vesselSlot], w.velocity(m_vesselSlot)};
  }
  return m_vessel;
}

void CudaStepper::step() {
  CudaBatch& batch = *m_batch;
  batch.ensureStep(m_step);
  const cuda::DeviceBatchResult& result = batch.result();
  const size_t k = static_cast<size_t>(m_step - batch.resultFirst());
  const cuda::StepRecord& r = result.steps[k];
  const cuda::WorldStepRecord& mine = result.worldSteps[k * static_cast<size_t>(result.worlds) + static_cast<size_t>(m_world)];
  m_taken = m_step + 1;
  m_candidateCount = r.candidates;
  m_contactCount = mine.contacts;

  // Records: the device appends in any order; the CPU's order is by event, then by contact, which
  // each row's tag gives (a contact's index orders this world's contacts as its run alone does).
  // With several worlds, the batch has indexed each step's rows by their tag's world
  // (CudaBatch::rowsOf); the events saw the case's own body ids, so the rows need no translation.
  {
    Stopwatch clock;
    m_records.clear();
    std::vector<int> rows;
    for (int q = 0; q < m_cpu->recordStreams().count(); ++q) {
      const size_t stride = static_cast<size_t>(m_cpu->recordStreams().info(q).stride);
      const unsigned char* all = result.records[q].data();
      auto tagOf = [&](int row) {
        RecordTag t;
        std::memcpy(&t, all + static_cast<size_t>(row) * stride, sizeof t);
        return t;
      };
      const auto [first, last] = batch.rowsOf(q, k, m_world);
      rows.assign(first, last);
      std::stable_sort(rows.begin(), rows.end(), [&](int x, int y) {
        const RecordTag a = tagOf(x), b = tagOf(y);
        return a.event != b.event ? a.event < b.event : a.contact < b.contact;
      });
      for (int row : rows) m_records.append(q, all + static_cast<size_t>(row) * stride, 1);
    }
    deliverLogs(m_records);
    batch.times.ordering += clock.lap();
  }
  m_vesselIceForce = forceOfImpulse(mine.vesselImpulse, scenario().dt);
  if (m_vesselSlot >= 0) m_vessel = VesselSample{true, mine.vesselPosition, mine.vesselAngle, mine.vesselVelocity};

  // 6. Topology, only in a step whose rows a topology event reads (the device stopped the batch there).
  bool topology = false;
  for (const EnabledEvent& e : m_cpu->events())
    if (e.phase == EventPhase::Topology)
      for (int q : e.instance->streamsRead()) topology = topology || m_records.rowCount(q) > 0;
  // The resident kernel may have run it already (resident_kernel.cuh breakFloes): then the
  // device's count of it is this step's, and the mirror followed after the run (followDeviceEdit).
  if (mine.topologyOnDevice) {
    m_rubbleMass += mine.rubbleMass;
    m_floesBroken += mine.floesBroken;
  } else if (topology) {
    runTopology();
  }

  const long done = m_step++;
  m_time = stepTime(m_step, scenario().dt);
  batch.finishedStep(done);  // the last case of the step: edits on the device, the re-sort when due
}

// A device re-sort: this world's device slot k now holds its old device slot order[k].
void CudaStepper::followReorder(const std::vector<int>& order) {
  m_slotOfId.clear();
  if (m_pendingOrder.empty()) {
    m_pendingOrder = order;
  } else {
    std::vector<int> composed(order.size());
    for (size_t k = 0; k < order.size(); ++k) composed[k] = m_pendingOrder[static_cast<size_t>(order[k])];
    m_pendingOrder.swap(composed);
  }
  m_hostCurrent = false;
  if (m_vesselSlot >= 0)
    for (size_t k = 0; k < order.size(); ++k)
      if (order[k] == m_vesselSlot) {
        m_vesselSlot = static_cast<int>(k);
        break;
      }
}

// The backend's entry: listed by `gem info`, chosen by --backend cuda and by backend = "auto".
static const bool kRegistered = [] {
  registerBackend(BackendEntry{"cuda", [] { return cudaAvailable(); }, [] { return cudaDeviceName(); },
                               [](const Scenario& s) -> std::unique_ptr<Stepper> { return std::make_unique<CudaStepper>(s); },
                               useCudaDeviceForWorker, CudaStepper::batchKey,
                               [](const std::vector<const Scenario*>& scenarios) {
                                 std::vector<std::unique_ptr<Stepper>> steppers;
                                 for (auto& s : CudaStepper::together(scenarios)) steppers.push_back(std::move(s));
                                 return steppers;
                               },
                               deviceCount});
  return true;
}();

}  // namespace gem
