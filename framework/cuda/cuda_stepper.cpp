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
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "framework/api/cuda_check.hpp"
#include "framework/cuda/device_step.hpp"
#include "framework/api/log_channel.hpp"
#include "framework/api/registry.hpp"
#include "framework/step/phases.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/step/stepper.hpp"

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

int CudaStepper::bindThreadToDevice() {
  int device = 0;
  if (t_workerDevice >= 0) GEM_CUDA_CHECK(cudaSetDevice(t_workerDevice));
  GEM_CUDA_CHECK(cudaGetDevice(&device));
  return device;
}

World& CudaStepper::world() { return m_cpu->world(); }
const Scenario& CudaStepper::scenario() const { return m_cpu->scenario(); }

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
  // Every setting the scenario gave must be honoured by the device part, or the run is refused.
  const std::vector<std::string> honoured = cuda::cudaBroadphaseSettings(name, origin);
  for (const std::string& key : scenario.broadphaseSettings.given)
    if (std::find(honoured.begin(), honoured.end(), key) == honoured.end())
      throw BackendUnsupported("broadphase \"" + name + "\": its CUDA part does not honour the setting " + key +
                               " ([broadphase." + name + "] or [simulation]); leave it out, or run with --backend cpu");
  return (*factory)(scenario.broadphaseSettings);
}

// The device state of one run, or of several cases run together (a world each). It owns the
// device and the step loop; each case (a CudaStepper) keeps its own host mirror and hands out
// its own world's records. With several worlds, body ids on the device are the case's own plus
// world x idStride (unique over the state, so contacts' onset keys never mix worlds), and a
// world's device slots are the state's slots of that world in ascending order.
class CudaBatch {
 public:
  CudaBatch(std::vector<CudaStepper*> members, int deviceOrdinal);
  ~CudaBatch();

  int worlds() const { return static_cast<int>(m_members.size()); }
  cuda::DeviceStep& device() { return *m_device; }
  const cuda::DeviceBatchResult& result() const { return *m_result; }
  long resultFirst() const { return m_resultFirst; }  // step index of result().steps[0]
  std::int64_t idOffset(int world) const { return static_cast<std::int64_t>(world) * m_idStride; }
  int worldOfId(std::int64_t id) const { return static_cast<int>(id / m_idStride); }
  // World w's device slot `local` in the shared state.
  int sharedSlot(int world, int local) {
    return worlds() == 1 ? local : slotsOfWorld(world)[static_cast<size_t>(local)];
  }
  const std::vector<int>& slotsOfWorld(int world);

  // The host mirrors to the device (set-up; a strategy that could not follow a re-sort).
  void uploadAll();
  // Step `step` of every case is on the host (a case asking for it runs the next batch of steps).
  void ensureStep(long step);
  // A case's topology edit: its device slots removedLocal leave, its mirror's rows from
  // [firstAdded..] are appended (applied once every case is done with the step).
  void addEdit(int world, const std::vector<int>& removedLocal, const World& mirror, int firstAdded);
  // A case finished its step: the last one of a step applies the edits and re-sorts when due.
  void finishedStep(long step);
  std::vector<int> vesselDofs() const;

  struct HostTimes {
    long batches = 0, topologies = 0, resorts = 0;
    double batch = 0, fetch = 0, events = 0, edit = 0, bookkeeping = 0, resort = 0, ordering = 0;
  } times;  // host wall time by part (GEM_CUDA_TIMING=1 prints it when the state goes), s

 private:
  void runBatch(long step);
  void applyEdits();
  void reSortAlongCurve();

  std::vector<CudaStepper*> m_members;
  int m_deviceOrdinal;
  std::unique_ptr<cuda::DeviceStep> m_device;
  std::unique_ptr<cuda::DeviceBatchResult> m_result;
  long m_resultFirst = 0;
  std::int64_t m_idStride = std::int64_t(1) << 62;  // one world: the ids as they are
  std::vector<std::vector<int>> m_slotsOfWorld;      // empty: stale
  int m_finished = 0;                                // cases done with the current step
  long m_stepsDone = 0;
  // The step's edits, applied together: shared slots, and the new bodies with their worlds.
  std::vector<int> m_removed;
  World m_added;
  std::vector<int> m_addedWorlds;
  bool m_edited = false;
};

namespace {

// Rows [first, from.size()) of `from` appended to `to`, ids shifted by idOffset.
void appendRows(World& to, const World& from, int first, std::int64_t idOffset) {
  const size_t f = static_cast<size_t>(first);
  for (size_t i = f; i < from.id.size(); ++i) to.id.push_back(from.id[i] + idOffset);
  to.kind.insert(to.kind.end(), from.kind.begin() + first, from.kind.end());
  to.vertexCount.insert(to.vertexCount.end(), from.vertexCount.begin() + first, from.vertexCount.end());
  to.localVertices.insert(to.localVertices.end(), from.localVertices.begin() + static_cast<std::ptrdiff_t>(f * kMaxVertices),
                          from.localVertices.end());
  std::vector<Real> World::*reals[] = {&World::x, &World::y, &World::angle, &World::vx, &World::vy, &World::omega,
                                       &World::area, &World::thickness, &World::mass, &World::invMass, &World::invInertia,
                                       &World::gyration2, &World::gyrationX2, &World::gyrationY2, &World::principalAngle,
                                       &World::radius};
  for (auto r : reals) (to.*r).insert((to.*r).end(), (from.*r).begin() + first, (from.*r).end());
}

}  // namespace

std::string CudaStepper::batchKey(const Scenario& s) {
  if (s.broadphase != "uniform_grid") return "";
  std::string key = fmt::format("dt={} steps={} copy_back_every={} block={} morton={} frames={} vessel_dof={} cell={}", s.dt, s.steps,
                                s.copyBackEvery, s.cudaBlockSize, s.mortonSort, s.output.frameEvery, s.vessel.dof, s.broadphaseSettings.cellSize);
  for (const auto& [name, setting] : s.events) key += fmt::format(" {}={}", name, setting.enabled);
  for (const PluginSpec& p : s.plugins) key += fmt::format(" plugin={}{}", p.path.string(), p.override ? "!" : "");
  return key;
}

CudaBatch::CudaBatch(std::vector<CudaStepper*> members, int deviceOrdinal)
    : m_members(std::move(members)),
      m_deviceOrdinal(deviceOrdinal),
      m_device(std::make_unique<cuda::DeviceStep>()),
      m_result(std::make_unique<cuda::DeviceBatchResult>()) {
  const CudaStepper& first = *m_members.front();
  const Scenario& s = first.scenario();
  m_device->configure(s.copyBackEvery, s.cudaBlockSize);
  // The CPU simulations parsed every event (strictly) and sorted their worlds along the curve; their
  // instances give the Params the device drivers are made from, in the same order, a set per world.
  const std::vector<EnabledEvent>& events = first.m_cpu->events();
  for (const CudaStepper* m : m_members) {
    const std::vector<EnabledEvent>& own = m->m_cpu->events();
    bool same = own.size() == events.size();
    for (size_t e = 0; same && e < own.size(); ++e) same = own[e].name == events[e].name && own[e].phase == events[e].phase;
    if (!same) throw BackendUnsupported("cases run together on one device must enable the same events");
  }
  for (size_t e = 0; e < events.size(); ++e) {
    const EnabledEvent& event = events[e];
    if (event.phase == EventPhase::Topology) continue;  // runs on the host
    // Device drivers are found by name and origin: the registry entry's (built-in, or the plugin
    // that registered it). A plugin's event runs only with its own plugin's driver, never with a
    // built-in's of the same name (that would read its Params wrongly).
    const EventEntry* entry = Registry::global().findEvent(event.name);
    const std::string origin = entry ? entry->origin : std::string("built-in");
    const cuda::CudaEventFactory* factory = cuda::findCudaEvent(event.name, origin);
    if (!factory && origin != "built-in")
      throw BackendUnsupported("event \"" + event.name + "\" comes from a plugin (" + origin +
                               ") that has no CUDA driver for it (a .cu with GEM_REGISTER_CUDA_*_EVENT, built by "
                               "gem_add_plugin's CUDA_SOURCES); run it with --backend cpu");
    if (!factory) throw BackendUnsupported("event \"" + event.name + "\" has no CUDA driver (events/" + event.name + ".cu is missing)");
    std::vector<const void*> params;
    for (const CudaStepper* m : m_members) params.push_back(m->m_cpu->events()[e].instance->params());
    auto driver = (*factory)(params.data(), worlds());
    if (event.phase == EventPhase::Pair) m_device->addPairEvent(std::move(driver));
    else if (event.phase == EventPhase::Solo) m_device->addSoloEvent(std::move(driver));
    else m_device->addMotionEvent(std::move(driver));
  }
  if (worlds() > 1) {
    // Room for each world's ids, new floes from breaks included: a power of two past 4x the most.
    std::int64_t most = 1;
    for (CudaStepper* m : m_members) most = std::max(most, m->world().nextId);
    m_idStride = 1024;
    while (m_idStride < 4 * most) m_idStride *= 2;
    if (static_cast<std::int64_t>(worlds()) * m_idStride > (std::int64_t(1) << 31))
      throw BackendUnsupported(fmt::format("{} cases of up to {} bodies are too many for one device state; run fewer together", worlds(), most));
  }
  m_device->setBroadphase(deviceBroadphase(s));
  m_device->setGridCell(s.broadphase == "uniform_grid" ? s.broadphaseSettings.cellSize : 0);
  if (worlds() > 1 && m_device->broadphase())
    throw BackendUnsupported("cases run together on one device need the uniform_grid broadphase (it keeps their worlds apart)");
  for (CudaStepper* m : m_members) m->locateVessel();
  uploadAll();
  ++liveOn(m_deviceOrdinal);  // last: a constructor that threw has no destructor to count it out
}

CudaBatch::~CudaBatch() {
  --liveOn(m_deviceOrdinal);
  // GEM_CUDA_TIMING=1: where the host's wall time went (the device's kernels are ncu's to split).
  const char* timing = std::getenv("GEM_CUDA_TIMING");
  if (!timing || timing[0] != '1') return;
  const HostTimes& t = times;
  const int bodies = static_cast<int>(m_device->worldOfSlots().size());  // the cases may be gone already
  const auto [captures, captureSeconds] = m_device->captures();
  std::fprintf(stderr,
               "gem cuda timing, %ld steps, %d bodies in %d case%s: batches %ld in %.3f s (device steps, copy-back; of it, %ld graph "
               "captures in %.3f s); topology %ld in %.3f s (fetch %.3f, events %.3f, device edit %.3f, bookkeeping %.3f); re-sorts %ld "
               "in %.3f s; record ordering %.3f s\n",
               m_stepsDone, bodies, worlds(), worlds() == 1 ? "" : "s", t.batches, t.batch, captures, captureSeconds, t.topologies,
               t.fetch + t.events + t.edit + t.bookkeeping, t.fetch, t.events, t.edit, t.bookkeeping, t.resorts, t.resort, t.ordering);
}

std::vector<int> CudaBatch::vesselDofs() const {
  std::vector<int> dofs;
  for (const CudaStepper* m : m_members) dofs.push_back(m->scenario().vessel.dof);
  return dofs;
}

const std::vector<int>& CudaBatch::slotsOfWorld(int world) {
  if (m_slotsOfWorld.empty()) {
    m_slotsOfWorld.assign(static_cast<size_t>(worlds()), {});
    const std::vector<int>& worldOf = m_device->worldOfSlots();
    for (int k = 0; k < static_cast<int>(worldOf.size()); ++k) m_slotsOfWorld[static_cast<size_t>(worldOf[static_cast<size_t>(k)])].push_back(k);
  }
  return m_slotsOfWorld[static_cast<size_t>(world)];
}

void CudaBatch::uploadAll() {
  if (worlds() == 1) {
    CudaStepper& m = *m_members.front();
    m_device->upload(m.world(), m.scenario().vessel.dof, m.m_vesselSlot);
  } else {
    // The worlds one after the other, each in its own order.
    World all;
    std::vector<int> worldOf, vesselSlots;
    for (int w = 0; w < worlds(); ++w) {
      const CudaStepper& m = *m_members[static_cast<size_t>(w)];
      const int base = all.size();
      appendRows(all, m.m_cpu->world(), 0, idOffset(w));
      worldOf.insert(worldOf.end(), static_cast<size_t>(all.size() - base), w);
      vesselSlots.push_back(m.m_vesselSlot >= 0 ? base + m.m_vesselSlot : -1);
    }
    all.nextId = static_cast<std::int64_t>(worlds()) * m_idStride;
    m_device->upload(all, worldOf, vesselSlots, vesselDofs());
  }
  m_slotsOfWorld.clear();
  for (CudaStepper* m : m_members) {
    m->m_slotOfId.clear();
    m->m_hostCurrent = true;
  }
}

void CudaBatch::ensureStep(long step) {
  if (step >= m_resultFirst && step < m_resultFirst + static_cast<long>(m_result->steps.size())) return;
  for (const CudaStepper* m : m_members)
    if (m->m_step != step) throw std::logic_error("CUDA backend: the cases of one device state must be stepped together");
  runBatch(step);
}

// Up to copy_back_every steps, ending where the host needs the state: the next frame, the next
// re-sort along the curve (every kResortPeriod steps), the scenario's last step.
void CudaBatch::runBatch(long step) {
  const Scenario& s = m_members.front()->scenario();
  // Alone on its device, a batch is copy_back_every steps in one launch. Sharing it (a sweep's
  // other cases), a batch is one step: the device-side loops of concurrent graphs do not overlap
  // (an H200 took 23 s for the 70-run load study with 16-step loops, 8.5 s with single steps).
  // The results are the same either way (CopyBackIntervalChangesNothing).
  const long every = liveOn(m_deviceOrdinal).load() > 1 ? 1 : s.copyBackEvery;
  long end = step + every;
  auto stopAtMultipleOf = [&](long every) {
    if (every > 0) end = std::min(end, (step / every + 1) * every);
  };
  if (s.output.frameEvery > 0) stopAtMultipleOf(s.output.frameEvery);
  if (s.mortonSort) stopAtMultipleOf(kResortPeriod);
  if (step < s.steps) end = std::min(end, s.steps);
  Stopwatch clock;
  m_device->run(step, s.dt, static_cast<int>(end - step), *m_result);
  m_resultFirst = step;
  times.batch += clock.lap();
  ++times.batches;
  for (CudaStepper* m : m_members) m->m_hostCurrent = false;
}

void CudaBatch::addEdit(int world, const std::vector<int>& removedLocal, const World& mirror, int firstAdded) {
  for (int local : removedLocal) m_removed.push_back(sharedSlot(world, local));
  appendRows(m_added, mirror, firstAdded, idOffset(world));
  m_addedWorlds.insert(m_addedWorlds.end(), static_cast<size_t>(mirror.size() - firstAdded), world);
  m_added.nextId = worlds() == 1 ? mirror.nextId : static_cast<std::int64_t>(worlds()) * m_idStride;
  if (worlds() > 1 && mirror.nextId > m_idStride)
    throw std::runtime_error(fmt::format("CUDA backend: a case made more than {} bodies, the room for its ids in a shared device state", m_idStride));
  m_edited = true;
}

void CudaBatch::finishedStep(long step) {
  if (++m_finished < worlds()) return;
  m_finished = 0;
  m_stepsDone = step + 1;
  applyEdits();
  if (m_members.front()->scenario().mortonSort && isResortStep(step + 1)) {
    Stopwatch clock;
    reSortAlongCurve();
    times.resort += clock.lap();
    ++times.resorts;
  }
}

void CudaBatch::applyEdits() {
  if (!m_edited) return;
  Stopwatch clock;
  std::sort(m_removed.begin(), m_removed.end());
  const bool followed = m_device->editBodies(m_removed, m_added, 0, worlds() == 1 ? std::vector<int>{} : m_addedWorlds, vesselDofs());
  m_removed.clear();
  m_added = World{};
  m_addedWorlds.clear();
  m_edited = false;
  m_slotsOfWorld.clear();
  times.edit += clock.lap();
  if (!followed) {
    // A strategy that cannot follow the edit on the device (a plugin's, say; one world only)
    // rebuilds from the mirror, which must then be in the device's order.
    CudaStepper& m = *m_members.front();
    m.flushPendingOrder();
    m_device->uploadBroadphase(m.world());
  }
  times.bookkeeping += clock.lap();
}

// Every kResortPeriod steps (docs/architecture.md "Speed habits": neighbours in space become neighbours in memory).
void CudaBatch::reSortAlongCurve() {
  // On the device, bit for bit as the host's World::curveOrder + World::permute, world by world;
  // the mirrors follow lazily (m_pendingOrder). At 10^6 floes a round trip through the host
  // (download, sort, permute, upload, re-capture) cost more than the kResortPeriod steps it serves.
  const std::vector<int> worldBefore = m_device->worldOfSlots();
  bool followed = true;
  const std::vector<int> order = m_device->reorderAlongCurve(&followed);
  m_slotsOfWorld.clear();
  if (worlds() == 1) {
    m_members.front()->followReorder(order);
  } else {
    // Each world's share of the order, in its own slots: the rank of a shared slot among its world's.
    std::vector<int> localOf(worldBefore.size()), seen(static_cast<size_t>(worlds()), 0);
    for (size_t k = 0; k < worldBefore.size(); ++k) localOf[k] = seen[static_cast<size_t>(worldBefore[k])]++;
    std::vector<std::vector<int>> local(static_cast<size_t>(worlds()));
    for (int old : order) local[static_cast<size_t>(worldBefore[static_cast<size_t>(old)])].push_back(localOf[static_cast<size_t>(old)]);
    for (int w = 0; w < worlds(); ++w) m_members[static_cast<size_t>(w)]->followReorder(local[static_cast<size_t>(w)]);
  }
  if (!followed) {
    // A device broadphase that keeps per-body storage but cannot permute it (a plugin's, say; one
    // world only) rebuilds from the whole world, in the new order.
    for (CudaStepper* m : m_members) m->downloadState();
    uploadAll();
  }
}

long CudaStepper::broadphaseRebuilds() const {
  const cuda::CudaBroadphase* b = m_batch->device().broadphase();
  return b ? b->rebuilds() : 0;
}

int CudaStepper::casesOnDevice() const { return m_batch->worlds(); }

CudaStepper::CudaStepper(const Scenario& scenario, Member)
    : m_deviceOrdinal(bindThreadToDevice()), m_cpu(std::make_unique<CpuStepper>(scenario)), m_deviceName(cudaDeviceName()) {
  const World& w = world();
  for (int i = 0; i < w.size(); ++i)
    if (w.kind[i] == BodyKind::Vessel) m_vesselId = w.id[i];
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
      throw BackendUnsupported(own.empty() ? "scenario " + s->file.string() + " cannot share a device state (its broadphase is not uniform_grid)"
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
  for (const BreakRequest& b : m_breaks) {
    const int k = b.floeId < static_cast<std::int64_t>(slotOf.size()) ? slotOf[static_cast<size_t>(b.floeId)] : -1;
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
  TopologyData topology{&w, m_breaks.data(), static_cast<int>(m_breaks.size()), m_time};
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
    throw std::logic_error("CUDA backend: a topology event reordered the bodies (only World::removeBodies and World::addBody may change them)");
  std::sort(removedDevice.begin(), removedDevice.end());
  batch.times.bookkeeping += clock.lap();
  batch.addEdit(m_world, removedDevice, w, firstAdded);

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
  m_slotOfId.clear();
  if (m_vesselSlot >= 0) m_vesselSlot = slotOfId()[static_cast<size_t>(m_vesselId)];
  batch.times.bookkeeping += clock.lap();
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

bool CudaStepper::deviceAhead() const {
  return m_taken < m_batch->resultFirst() + static_cast<long>(m_batch->result().steps.size());
}

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
  const cuda::StepRecord before = k > 0 ? result.steps[k - 1] : cuda::StepRecord{};
  const cuda::WorldStepRecord& mine = result.worldSteps[k * static_cast<size_t>(result.worlds) + static_cast<size_t>(m_world)];
  m_taken = m_step + 1;
  m_candidateCount = r.candidates;
  m_contactCount = mine.contacts;

  // Records: the device appends in any order; the CPU's order is contact order, sorted by slot
  // pair (a, b). Impacts and breaks have the vessel as one side, so ascending floe slot is that
  // order; logs are sorted by the slots of both bodies. Slots do not change within a batch. With
  // several worlds, a record is this case's when its body ids are (and they become its own ids).
  m_impacts.assign(result.impacts.begin() + before.impactEnd, result.impacts.begin() + r.impactEnd);
  m_breaks.assign(result.breaks.begin() + before.breakEnd, result.breaks.begin() + r.breakEnd);
  m_logs.assign(result.logs.begin() + before.logEnd, result.logs.begin() + r.logEnd);
  if (batch.worlds() > 1) {
    auto other = [&](std::int64_t id) { return batch.worldOfId(id) != m_world; };
    const std::int64_t offset = batch.idOffset(m_world);
    m_impacts.erase(std::remove_if(m_impacts.begin(), m_impacts.end(), [&](const ImpactRecord& x) { return other(x.floeId); }), m_impacts.end());
    m_breaks.erase(std::remove_if(m_breaks.begin(), m_breaks.end(), [&](const BreakRequest& x) { return other(x.floeId); }), m_breaks.end());
    m_logs.erase(std::remove_if(m_logs.begin(), m_logs.end(), [&](const LogRecord& x) { return other(x.idA); }), m_logs.end());
    for (ImpactRecord& x : m_impacts) x.floeId -= offset;
    for (BreakRequest& x : m_breaks) x.floeId -= offset;
    for (LogRecord& x : m_logs) x.idA -= offset, x.idB -= offset;
  }
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
    batch.times.ordering += clock.lap();
  }
  m_vesselIceForce = forceOfImpulse(mine.vesselImpulse, scenario().dt);
  if (m_vesselSlot >= 0) m_vessel = VesselSample{true, mine.vesselPosition, mine.vesselAngle, mine.vesselVelocity};

  // 6. Topology, only in a step that asked for a break (the device stopped the batch there).
  if (!m_breaks.empty()) runTopology();

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
  registerBackend(BackendEntry{
      "cuda", [] { return cudaAvailable(); }, [] { return cudaDeviceName(); },
      [](const Scenario& s) -> std::unique_ptr<Stepper> { return std::make_unique<CudaStepper>(s); }, useCudaDeviceForWorker,
      CudaStepper::batchKey,
      [](const std::vector<const Scenario*>& scenarios) {
        std::vector<std::unique_ptr<Stepper>> steppers;
        for (auto& s : CudaStepper::together(scenarios)) steppers.push_back(std::move(s));
        return steppers;
      },
      deviceCount});
  return true;
}();

}  // namespace gem
