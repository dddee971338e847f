// The CUDA backend's host side: set-up from the scenario (through the CPU Simulation, which parses
// and checks every event), record ordering, the topology phase and the periodic re-sort.
#include "framework/cuda/cuda_simulation.hpp"

#include <cuda_runtime.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "framework/cuda/cuda_check.hpp"
#include "framework/cuda/device_world.hpp"
#include "framework/log_channel.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/stepper.hpp"

namespace gem {

namespace {
// Wall time in parts: lap() gives the seconds since the last lap (or since it was made).
class Stopwatch {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - m_last).count();
    m_last = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point m_last = std::chrono::steady_clock::now();
};
}  // namespace

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

// Simulations alive on each device in this process (a sweep runs several at once).
static std::atomic<int> g_liveOnDevice[64];
static std::atomic<int>& liveOn(int device) { return g_liveOnDevice[static_cast<unsigned>(device) % 64]; }

int CudaSimulation::bindThreadToDevice() {
  int device = 0;
  if (t_workerDevice >= 0) GEM_CUDA_CHECK(cudaSetDevice(t_workerDevice));
  GEM_CUDA_CHECK(cudaGetDevice(&device));
  return device;
}

World& CudaSimulation::world() { return m_cpu->world(); }
const Scenario& CudaSimulation::scenario() const { return m_cpu->scenario(); }

// The scenario's broadphase on the device, found by name and origin as the events' drivers are: a
// plugin's broadphase runs on the device only with its own plugin's device part. nullptr is the
// step's built-in grid (uniform_grid).
static std::unique_ptr<cuda::CudaBroadphase> deviceBroadphase(const Scenario& scenario) {
  const std::string& name = scenario.broadphase;
  const std::string origin = Registry::global().broadphase(name).origin;
  const cuda::CudaBroadphaseFactory* factory = cuda::findCudaBroadphase(name, origin);
  if (!factory && origin != "built-in")
    throw BackendUnsupported("broadphase \"" + name + "\" comes from a plugin (" + origin +
                             ") that has no CUDA part for it (a .cu with GEM_REGISTER_CUDA_BROADPHASE, built by "
                             "gem_add_plugin's CUDA_SOURCES); run it with --backend cpu");
  if (!factory) throw BackendUnsupported("broadphase \"" + name + "\" has no CUDA part (broadphase/" + name + ".cu is missing)");
  return (*factory)(scenario.broadphaseSettings);
}

long CudaSimulation::broadphaseRebuilds() const {
  const cuda::CudaBroadphase* b = m_device->broadphase();
  return b ? b->rebuilds() : 0;
}

CudaSimulation::CudaSimulation(const Scenario& scenario)
    : m_deviceOrdinal(bindThreadToDevice()),
      m_cpu(std::make_unique<Simulation>(scenario)),
      m_device(std::make_unique<cuda::DeviceWorld>()),
      m_batch(std::make_unique<cuda::DeviceBatchResult>()),
      m_deviceName(cudaDeviceName()) {
  m_device->configure(scenario.copyBackEvery, scenario.cudaBlockSize);
  // The CPU simulation parsed every event (strictly) and sorted the world along the curve; its
  // instances give the Params the device drivers are made from, in the same order.
  for (const EnabledEvent& e : m_cpu->events()) {
    if (e.phase == EventPhase::Topology) continue;  // runs on the host
    // Device drivers are found by name and origin: the registry entry's (built-in, or the plugin
    // that registered it). A plugin's event runs only with its own plugin's driver, never with a
    // built-in's of the same name (that would read its Params wrongly).
    const EventEntry* entry = Registry::global().findEvent(e.name);
    const std::string origin = entry ? entry->origin : std::string("built-in");
    const cuda::CudaEventFactory* factory = cuda::findCudaEvent(e.name, origin);
    if (!factory && origin != "built-in")
      throw BackendUnsupported("event \"" + e.name + "\" comes from a plugin (" + origin +
                               ") that has no CUDA driver for it (a .cu with GEM_REGISTER_CUDA_*_EVENT, built by "
                               "gem_add_plugin's CUDA_SOURCES); run it with --backend cpu");
    if (!factory) throw BackendUnsupported("event \"" + e.name + "\" has no CUDA driver (events/" + e.name + ".cu is missing)");
    auto driver = (*factory)(e.instance->params());
    if (e.phase == EventPhase::Pair) m_device->addPairEvent(std::move(driver));
    else if (e.phase == EventPhase::Solo) m_device->addSoloEvent(std::move(driver));
    else m_device->addMotionEvent(std::move(driver));
  }
  m_device->setBroadphase(deviceBroadphase(scenario));
  const World& w = world();
  for (int i = 0; i < w.size(); ++i)
    if (w.kind[i] == BodyKind::Vessel) m_vesselId = w.id[i];
  upload();
  ++liveOn(m_deviceOrdinal);  // last: a constructor that threw has no destructor to count it out
}

CudaSimulation::~CudaSimulation() {
  --liveOn(m_deviceOrdinal);
  // GEM_CUDA_TIMING=1: where the host's wall time went (the device's kernels are ncu's to split).
  const char* timing = std::getenv("GEM_CUDA_TIMING");
  if (!timing || timing[0] != '1') return;
  const HostTimes& t = m_times;
  std::fprintf(stderr,
               "gem cuda timing, %ld steps, %d bodies: batches %ld in %.3f s (device steps, copy-back); topology %ld in %.3f s "
               "(fetch %.3f, events %.3f, device edit %.3f, bookkeeping %.3f); re-sorts %ld in %.3f s; record ordering %.3f s\n",
               m_step, world().size(), t.batches, t.batch, t.topologies, t.fetch + t.events + t.edit + t.bookkeeping, t.fetch, t.events,
               t.edit, t.bookkeeping, t.resorts, t.resort, t.ordering);
}

void CudaSimulation::upload() {
  const World& w = world();
  m_vesselSlot = -1;
  for (int i = 0; i < w.size(); ++i)
    if (w.id[i] == m_vesselId) m_vesselSlot = i;
  m_device->upload(w, scenario().vessel.dof, m_vesselSlot);
  m_slotOfId.clear();
  m_hostCurrent = true;
}

int CudaSimulation::mirrorSlot(int deviceSlot) const {
  return m_pendingOrder.empty() ? deviceSlot : m_pendingOrder[static_cast<size_t>(deviceSlot)];
}

// Device slot by body id (ids are dense: never reused, a few new ones per break): one pass over
// the mirror's ids per world order, not per step (at 10^6 floes a pass per step was most of a step).
const std::vector<int>& CudaSimulation::slotOfId() {
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
// (DeviceWorld::editBodies): the world's arrays never cross the bus, only the few new bodies do.
void CudaSimulation::runTopology() {
  Stopwatch clock;
  ++m_times.topologies;
  World& w = world();
  const std::vector<int>& slotOf = slotOfId();
  std::vector<int> deviceSlots, hostSlots;
  for (const BreakRequest& b : m_breaks) {
    const int k = b.floeId < static_cast<std::int64_t>(slotOf.size()) ? slotOf[static_cast<size_t>(b.floeId)] : -1;
    if (k < 0 || std::find(deviceSlots.begin(), deviceSlots.end(), k) != deviceSlots.end()) continue;
    deviceSlots.push_back(k);
    hostSlots.push_back(mirrorSlot(k));
  }
  if (m_topologyThroughHost) {
    downloadState();  // the reference path (tests): the whole world round trips
  } else {
    m_device->downloadKinematics(deviceSlots, hostSlots, w);
  }
  m_times.fetch += clock.lap();

  const std::vector<std::int64_t> idsBefore = w.id;
  const std::int64_t nextIdBefore = w.nextId;
  TopologyData topology{&w, m_breaks.data(), static_cast<int>(m_breaks.size()), m_time};
  for (const EnabledEvent& e : m_cpu->events())
    if (e.phase == EventPhase::Topology) e.instance->runTopology(topology);
  m_rubbleMass += topology.rubbleMass;
  m_floesBroken += topology.floesBroken;
  m_times.events += clock.lap();
  if (!topology.changed) return;
  if (m_topologyThroughHost) {
    upload();
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
    throw std::logic_error("CUDA backend: a topology event reordered the bodies (only World::removeBodies and World::addBody may change them)");
  std::sort(removedDevice.begin(), removedDevice.end());
  m_times.bookkeeping += clock.lap();
  const bool broadphaseFollowed = m_device->editBodies(removedDevice, w, firstAdded, scenario().vessel.dof);
  m_times.edit += clock.lap();

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
      composed.push_back(mirrorOld - static_cast<int>(std::lower_bound(removedMirror.begin(), removedMirror.end(), mirrorOld) -
                                                      removedMirror.begin()));
    }
    for (int k = firstAdded; k < w.size(); ++k) composed.push_back(k);
    m_pendingOrder.swap(composed);
  }
  if (!broadphaseFollowed) {
    // A strategy that cannot follow the edit on the device (a plugin's, say) rebuilds from the
    // mirror, which must then be in the device's order.
    if (!m_pendingOrder.empty()) w.permute(m_pendingOrder);
    m_pendingOrder.clear();
    m_device->uploadBroadphase(w);
  }
  m_slotOfId.clear();
  if (m_vesselSlot >= 0) m_vesselSlot = slotOfId()[static_cast<size_t>(m_vesselId)];
  m_times.bookkeeping += clock.lap();
}

void CudaSimulation::downloadState() {
  if (m_hostCurrent) return;
  if (deviceAhead()) throw std::logic_error("CUDA backend: the world was asked for in the middle of a copy-back batch");
  if (!m_pendingOrder.empty()) {
    world().permute(m_pendingOrder);
    m_pendingOrder.clear();
  }
  m_device->download(world());
  m_hostCurrent = true;
}

bool CudaSimulation::deviceAhead() const { return m_batchNext < m_batch->steps.size(); }

const World& CudaSimulation::hostWorld() {
  // Batches end where the runner needs the state (frames, the last step): downloadState refuses a
  // caller that asks elsewhere, who would get a later state than the step it is at.
  downloadState();
  return world();
}

VesselSample CudaSimulation::vessel() {
  if (m_vesselSlot < 0) return VesselSample{false, {0, 0}, 0, {0, 0}};
  if (m_hostCurrent) {
    const World& w = world();
    return VesselSample{true, w.position(m_vesselSlot), w.angle[m_vesselSlot], w.velocity(m_vesselSlot)};
  }
  return m_vessel;
}

// Up to copy_back_every steps, ending where the host needs the state: the next frame, the next
// re-sort along the curve (every 200 steps), the scenario's last step.
void CudaSimulation::runBatch() {
  const Scenario& s = scenario();
  // Alone on its device, a batch is copy_back_every steps in one launch. Sharing it (a sweep's
  // other cases), a batch is one step: the device-side loops of concurrent graphs do not overlap
  // (an H200 took 23 s for the 70-run load study with 16-step loops, 8.5 s with single steps).
  // The results are the same either way (CopyBackIntervalChangesNothing).
  const long every = liveOn(m_deviceOrdinal).load() > 1 ? 1 : s.copyBackEvery;
  long end = m_step + every;
  auto stopAtMultipleOf = [&](long every) {
    if (every > 0) end = std::min(end, (m_step / every + 1) * every);
  };
  if (s.output.frameEvery > 0) stopAtMultipleOf(s.output.frameEvery);
  if (s.mortonSort) stopAtMultipleOf(200);
  if (m_step < s.steps) end = std::min(end, s.steps);
  Stopwatch clock;
  m_device->run(m_step, s.dt, static_cast<int>(end - m_step), *m_batch);
  m_times.batch += clock.lap();
  ++m_times.batches;
  m_batchNext = 0;
  m_hostCurrent = false;
}

void CudaSimulation::step() {
  if (!deviceAhead()) runBatch();
  const cuda::DeviceBatchResult& batch = *m_batch;
  const cuda::StepRecord& r = batch.steps[m_batchNext];
  const cuda::StepRecord before = m_batchNext > 0 ? batch.steps[m_batchNext - 1] : cuda::StepRecord{};
  ++m_batchNext;
  m_candidateCount = r.candidates;
  m_contactCount = r.contacts;

  // Records: the device appends in any order; the CPU's order is contact order, sorted by slot
  // pair (a, b). Impacts and breaks have the vessel as one side, so ascending floe slot is that
  // order; logs are sorted by the slots of both bodies. Slots do not change within a batch.
  m_impacts.assign(batch.impacts.begin() + before.impactEnd, batch.impacts.begin() + r.impactEnd);
  m_breaks.assign(batch.breaks.begin() + before.breakEnd, batch.breaks.begin() + r.breakEnd);
  m_logs.assign(batch.logs.begin() + before.logEnd, batch.logs.begin() + r.logEnd);
  if (m_impacts.size() > 1 || m_breaks.size() > 1 || !m_logs.empty()) {
    Stopwatch clock;
    const std::vector<int>& slots = slotOfId();
    auto slotOf = [&slots](std::int64_t id) { return slots.at(static_cast<size_t>(id)); };
    std::stable_sort(m_impacts.begin(), m_impacts.end(),
                     [&](const ImpactRecord& a, const ImpactRecord& b) { return slotOf(a.floeId) < slotOf(b.floeId); });
    std::stable_sort(m_breaks.begin(), m_breaks.end(),
                     [&](const BreakRequest& a, const BreakRequest& b) { return slotOf(a.floeId) < slotOf(b.floeId); });
    auto pairOf = [&](const LogRecord& x) {
      const int a = slotOf(x.idA), b = slotOf(x.idB);
      return std::pair<int, int>{std::min(a, b), std::max(a, b)};
    };
    std::stable_sort(m_logs.begin(), m_logs.end(), [&](const LogRecord& a, const LogRecord& b) { return pairOf(a) < pairOf(b); });
    deliverLogs(m_logs.data(), static_cast<int>(m_logs.size()));
    m_times.ordering += clock.lap();
  }
  m_vesselIceForce = (Real(1) / scenario().dt) * r.vesselImpulse;
  if (m_vesselSlot >= 0) m_vessel = VesselSample{true, r.vesselPosition, r.vesselAngle, r.vesselVelocity};

  // 6. Topology, only in a step that asked for a break (the device stopped the batch there).
  if (!m_breaks.empty()) runTopology();

  ++m_step;
  m_time = static_cast<Real>(m_step) * scenario().dt;
  if (scenario().mortonSort && m_step % 200 == 0) {
    Stopwatch clock;
    reSortAlongCurve();
    m_times.resort += clock.lap();
    ++m_times.resorts;
  }
}

// Every 200 steps (DESIGN.md "Speed habits": neighbours in space become neighbours in memory).
void CudaSimulation::reSortAlongCurve() {
  // On the device, bit for bit as the host's World::curveOrder + World::permute; the mirror follows
  // lazily (m_pendingOrder). At 10^6 floes a round trip through the host (download, sort, permute,
  // upload, re-capture) cost more than the 200 steps it serves.
  bool followed = true;
  const std::vector<int> order = m_device->reorderAlongCurve(&followed);
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
  if (!followed) {
    // A device broadphase that keeps per-body storage but cannot permute it (a plugin's, say)
    // rebuilds from the whole world, in the new order.
    downloadState();
    upload();
  }
}

// The backend's entry: listed by `gem info`, chosen by --backend cuda and by backend = "auto".
static const bool kRegistered = [] {
  registerBackend(BackendEntry{"cuda", [] { return cudaAvailable(); }, [] { return cudaDeviceName(); },
                               [](const Scenario& s) -> std::unique_ptr<Stepper> { return std::make_unique<CudaSimulation>(s); },
                               useCudaDeviceForWorker});
  return true;
}();

}  // namespace gem
