// The CUDA backend's device state and step loop, shared by the cases run together (CudaBatch):
// set-up, batches of steps, topology edits replayed together, the periodic re-sort.
#include "framework/cuda/cuda_batch.hpp"

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
#include "framework/cuda/device_step.hpp"
#include "framework/cuda/resident.cuh"
#include "framework/api/log_channel.hpp"
#include "framework/api/registry.hpp"
#include "framework/step/phases.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/step/stepper.hpp"

namespace gem {

// Runs alive on each device in this process (a sweep runs several at once).
static std::atomic<int> g_liveOnDevice[64];
std::atomic<int>& liveOn(int device) { return g_liveOnDevice[static_cast<unsigned>(device) % 64]; }

// The scenario's broadphase on the device, found by name and origin as the events' drivers are: a
// plugin's broadphase runs on the device only with its own plugin's device part. nullptr is the
// step's built-in grid (uniform_grid).
std::unique_ptr<cuda::CudaBroadphase> deviceBroadphase(const Scenario& scenario) {
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
      throw BackendUnsupported("broadphase \"" + name + "\": its CUDA part does not honour the setting " + key + " ([broadphase." + name +
                               "] or [simulation]); leave it out, or run with --backend cpu");
  return (*factory)(scenario.broadphaseSettings);
}

namespace {

// simulation.cuda_driver = "auto" (docs/performance.md "CUDA drivers" has the measurements): the
// resident driver for several worlds of up to this many bodies each (a sweep's cases: the 70-run
// load study steps in 1.4 s of device time against 2.1 s device-wide), the device-wide driver for
// one world (on an H200 the 824-floe field takes 0.21 ms a step device-wide, 0.38 ms resident).
constexpr int kResidentAutoMostBodies = 4096;

// The resident kernel's program for these events, and each world's row of their Params; or why the
// kernel cannot run them (an event it does not hold: a plugin's).
std::string residentProgramOf(const std::vector<const CpuStepper*>& members, cuda::ResidentProgram& program,
                              std::vector<unsigned char>& params, int& stride) {
  // The resident kernel finds its own pairs (the contacts every built-in strategy gives, as the
  // broadphase-equivalence tests check); a plugin's strategy may mean to give others.
  const std::string& broadphase = members.front()->scenario().broadphase;
  const std::string origin = Registry::global().broadphase(broadphase).origin;
  if (origin != "built-in")
    return "broadphase \"" + broadphase + "\" comes from a plugin (" + origin + "), and the resident kernel finds its pairs itself";
  const std::vector<EnabledEvent>& events = members.front()->events();
  struct Placed {
    size_t event, size;
    int offset;
  };
  std::vector<Placed> placed;
  int offset = 0;
  // The topology phase runs in the kernel when it holds the scenario's one topology event
  // (flexural_breaking); otherwise a step with its rows ends the launch for the host's phase.
  int topologyEvents = 0;
  for (const EnabledEvent& event : events) topologyEvents += event.phase == EventPhase::Topology;
  for (size_t e = 0; e < events.size(); ++e) {
    const EnabledEvent& event = events[e];
    const EventEntry* entry = Registry::global().findEvent(event.name);
    const bool builtIn = !entry || entry->origin == "built-in";
    if (event.phase == EventPhase::Topology) {
      size_t size = 0;
      const std::vector<int> streams = event.instance->streamsRead();
      if (topologyEvents == 1 && builtIn && streams.size() == 1 && cuda::residentTopologyEvent(event.name, &size)) {
        program.breakingOffset = offset;
        program.breakingStream = streams.front();
        placed.push_back(Placed{e, size, offset});
        offset += static_cast<int>((size + 15) / 16 * 16);
      }
      continue;
    }
    if (!builtIn)
      return "event \"" + event.name + "\" comes from a plugin (" + entry->origin +
             "), and the resident kernel holds GEM's own events only";
    const cuda::ResidentPhase phase = event.phase == EventPhase::Pair   ? cuda::kResidentPair
                                      : event.phase == EventPhase::Solo ? cuda::kResidentSolo
                                                                        : cuda::kResidentMotion;
    size_t size = 0;
    const int kind = cuda::residentEventKind(event.name, phase, &size);
    if (kind < 0) return "event \"" + event.name + "\" is not in the resident kernel (framework/cuda/resident_events.cu)";
    int& count = phase == cuda::kResidentPair ? program.pairCount : phase == cuda::kResidentSolo ? program.soloCount : program.motionCount;
    cuda::ResidentEventCall* calls = phase == cuda::kResidentPair   ? program.pair
                                     : phase == cuda::kResidentSolo ? program.solo
                                                                    : program.motion;
    if (count == cuda::kResidentMaxEvents) return fmt::format("more than {} events of one phase", cuda::kResidentMaxEvents);
    calls[count++] = cuda::ResidentEventCall{kind, offset};
    placed.push_back(Placed{e, size, offset});
    offset += static_cast<int>((size + 15) / 16 * 16);
  }
  stride = std::max(offset, 16);
  params.assign(members.size() * static_cast<size_t>(stride), 0);
  for (size_t w = 0; w < members.size(); ++w)
    for (const Placed& p : placed)
      std::memcpy(params.data() + w * static_cast<size_t>(stride) + static_cast<size_t>(p.offset),
                  members[w]->events()[p.event].instance->params(), p.size);
  return "";
}

// Rows [first, end) of `from` appended to `to`, ids shifted by idOffset.
void appendRows(World& to, const World& from, int first, int end, std::int64_t idOffset) {
  const size_t f = static_cast<size_t>(first), e = static_cast<size_t>(end);
  for (size_t i = f; i < e; ++i) to.id.push_back(from.id[i] + idOffset);
  to.kind.insert(to.kind.end(), from.kind.begin() + first, from.kind.begin() + end);
  to.vertexCount.insert(to.vertexCount.end(), from.vertexCount.begin() + first, from.vertexCount.begin() + end);
  to.localVertices.insert(to.localVertices.end(), from.localVertices.begin() + static_cast<std::ptrdiff_t>(f * kMaxVertices),
                          from.localVertices.begin() + static_cast<std::ptrdiff_t>(e * kMaxVertices));
  std::vector<Real> World::*reals[] = {&World::x,          &World::y,          &World::angle,          &World::vx,
                                       &World::vy,         &World::omega,      &World::area,           &World::thickness,
                                       &World::mass,       &World::invMass,    &World::invInertia,     &World::gyration2,
                                       &World::gyrationX2, &World::gyrationY2, &World::principalAngle, &World::radius};
  for (auto r : reals) (to.*r).insert((to.*r).end(), (from.*r).begin() + first, (from.*r).begin() + end);
}
void appendRows(World& to, const World& from, int first, std::int64_t idOffset) { appendRows(to, from, first, from.size(), idOffset); }

}  // namespace

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
    if (event.phase == EventPhase::Pair)
      m_device->addPairEvent(std::move(driver));
    else if (event.phase == EventPhase::Solo)
      m_device->addSoloEvent(std::move(driver));
    else
      m_device->addMotionEvent(std::move(driver));
  }
  if (worlds() > 1) {
    // Room for each world's ids, new floes from breaks included: a power of two past 4x the most.
    std::int64_t most = 1;
    for (CudaStepper* m : m_members) most = std::max(most, m->world().nextId);
    m_idStride = 1024;
    while (m_idStride < 4 * most) m_idStride *= 2;
    if (static_cast<std::int64_t>(worlds()) * m_idStride > (std::int64_t(1) << 31))
      throw BackendUnsupported(
          fmt::format("{} cases of up to {} bodies are too many for one device state; run fewer together", worlds(), most));
  }
  // The driver: resident (a block per world) or device-wide (kernels over the whole state).
  cuda::ResidentProgram program;
  std::vector<unsigned char> params;
  int stride = 0;
  std::vector<const CpuStepper*> cpus;
  for (const CudaStepper* m : m_members) cpus.push_back(m->m_cpu.get());
  const std::string notResident = residentProgramOf(cpus, program, params, stride);
  int most = 0;
  for (CudaStepper* m : m_members) most = std::max(most, m->world().size());
  bool resident = false;
  // GEM_CUDA_DRIVER=resident|device stands in for "auto" (the sanitizer runs check each driver on
  // the same tests, scripts/stage-gpu.sh).
  std::string asked = s.cudaDriver;
  if (const char* env = std::getenv("GEM_CUDA_DRIVER");
      env && asked == "auto" && (std::string(env) == "resident" || std::string(env) == "device"))
    asked = env;
  if (asked == "resident") {
    if (!notResident.empty())
      throw BackendUnsupported("simulation.cuda_driver = \"resident\": " + notResident + "; use \"device\" or \"auto\"");
    resident = true;
  } else if (asked == "auto") {
    // Several worlds with a broadphase other than the device-wide driver's grid can only share a
    // device resident (batchKey let them in together).
    resident = notResident.empty() && worlds() > 1 && (most <= kResidentAutoMostBodies || s.broadphase != "uniform_grid");
  }
  if (resident) {
    m_device->useResident(program, params, stride, s.mortonSort);
  } else {
    m_device->setBroadphase(deviceBroadphase(s));
  }
  m_device->setGridCell(s.broadphase == "uniform_grid" ? s.broadphaseSettings.cellSize : 0);
  m_device->setIdStride(m_idStride);
  // The record streams, as the events opened them (the same in every case: the same events parsed
  // them in the same order); a row of a stream that a topology event reads ends the batch.
  const RecordStreams& streams = first.m_cpu->recordStreams();
  for (const CudaStepper* m : m_members)
    if (m->m_cpu->recordStreams().count() != streams.count())
      throw BackendUnsupported("cases run together on one device must open the same record streams");
  std::vector<int> strides;
  for (int q = 0; q < streams.count(); ++q) strides.push_back(streams.info(q).stride);
  unsigned halt = 0;
  for (const EnabledEvent& event : events)
    if (event.phase == EventPhase::Topology)
      for (int q : event.instance->streamsRead())
        if (q >= 0) halt |= 1u << q;
  m_device->setRecordStreams(strides, halt);
  if (worlds() > 1 && !resident && s.broadphase != "uniform_grid")
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
    for (int k = 0; k < static_cast<int>(worldOf.size()); ++k)
      m_slotsOfWorld[static_cast<size_t>(worldOf[static_cast<size_t>(k)])].push_back(k);
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

// Up to the next multiple of copy_back_every steps (after a batch that a break ended early too, so
// that batches end at steps a caller can know: every copy_back_every-th), and before that where the
// host needs the state: the next frame, the next re-sort along the curve (every kResortPeriod steps;
// the resident kernel re-sorts itself), the next checkpoint, the scenario's last step.
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
  stopAtMultipleOf(every);
  if (s.output.frameEvery > 0) stopAtMultipleOf(s.output.frameEvery);
  if (s.mortonSort && !m_device->resident()) stopAtMultipleOf(kResortPeriod);  // the resident kernel re-sorts itself
  stopAtMultipleOf(s.output.checkpointEverySteps);                             // a checkpoint needs the state on the host
  if (step < s.steps) end = std::min(end, s.steps);
  Stopwatch clock;
  if (m_device->resident()) {
    // New bodies of breaks in the resident kernel take each case's next ids.
    std::vector<std::int64_t> nextIds;
    for (const CudaStepper* m : m_members) nextIds.push_back(m->m_cpu->world().nextId);
    m_device->setNextIds(nextIds);
  }
  m_device->run(step, s.dt, static_cast<int>(end - step), *m_result);
  if (!m_result->edits.empty()) followDeviceEdits();
  if (!m_result->order.empty()) followOrder(m_result->order, m_result->worldBefore);
  m_resultFirst = step;
  times.batch += clock.lap();
  ++times.batches;
  indexRows();
  for (CudaStepper* m : m_members) m->m_hostCurrent = false;
}

// The resident kernel broke floes during the run and left the device state dense (runResident):
// each case's mirror follows, as its own topology phase would have left it (World::removeBodies,
// then the new bodies appended), with the shapes and mass properties the device made.
void CudaBatch::followDeviceEdits() {
  const cuda::DeviceBodyEdits& edits = m_result->edits;
  for (int w = 0; w < worlds(); ++w) {
    CudaStepper& m = *m_members[static_cast<size_t>(w)];
    std::vector<std::int64_t> removed;
    for (std::int64_t id : edits.removedIds)
      if (worldOfId(id) == w) removed.push_back(id - idOffset(w));
    World added;
    for (int k = 0; k < edits.added.size(); ++k)
      if (edits.addedWorlds.empty() || edits.addedWorlds[static_cast<size_t>(k)] == w)
        appendRows(added, edits.added, k, k + 1, -idOffset(w));
    m.followDeviceEdit(removed, added, edits.nextIds.at(static_cast<size_t>(w)));
  }
  m_slotsOfWorld.clear();
}

void CudaBatch::indexRows() {
  const cuda::DeviceBatchResult& r = *m_result;
  const size_t cells = r.steps.size() * static_cast<size_t>(worlds());
  const RecordStreams& streams = m_members.front()->m_cpu->recordStreams();
  for (int q = 0; q < streams.count(); ++q) {
    const size_t stride = static_cast<size_t>(streams.info(q).stride);
    const unsigned char* all = r.records[q].data();
    std::vector<int>& offsets = m_rowOffsets[q];
    std::vector<int>& rows = m_rows[q];
    offsets.assign(cells + 1, 0);
    auto worldOf = [&](int row) {
      RecordTag t;
      std::memcpy(&t, all + static_cast<size_t>(row) * stride, sizeof t);
      return t.world;
    };
    // A counting sort of the rows by (step, world), keeping their device order within each.
    for (size_t k = 0; k < r.steps.size(); ++k)
      for (int row = k ? r.steps[k - 1].recordEnd[q] : 0; row < r.steps[k].recordEnd[q]; ++row)
        ++offsets[k * static_cast<size_t>(worlds()) + static_cast<size_t>(worldOf(row)) + 1];
    for (size_t c = 0; c < cells; ++c) offsets[c + 1] += offsets[c];
    rows.assign(static_cast<size_t>(offsets[cells]), 0);
    std::vector<int> at(offsets.begin(), offsets.end() - 1);
    for (size_t k = 0; k < r.steps.size(); ++k)
      for (int row = k ? r.steps[k - 1].recordEnd[q] : 0; row < r.steps[k].recordEnd[q]; ++row)
        rows[static_cast<size_t>(at[k * static_cast<size_t>(worlds()) + static_cast<size_t>(worldOf(row))]++)] = row;
  }
}

std::pair<const int*, const int*> CudaBatch::rowsOf(int q, size_t k, int w) const {
  const size_t cell = k * static_cast<size_t>(worlds()) + static_cast<size_t>(w);
  const std::vector<int>& offsets = m_rowOffsets[q];
  const int* rows = m_rows[q].data();
  return {rows + offsets[cell], rows + offsets[cell + 1]};
}

void CudaBatch::addEdit(int world, const std::vector<int>& removedLocal, const World& mirror, int firstAdded) {
  for (int local : removedLocal) m_removed.push_back(sharedSlot(world, local));
  appendRows(m_added, mirror, firstAdded, idOffset(world));
  m_addedWorlds.insert(m_addedWorlds.end(), static_cast<size_t>(mirror.size() - firstAdded), world);
  m_added.nextId = worlds() == 1 ? mirror.nextId : static_cast<std::int64_t>(worlds()) * m_idStride;
  if (worlds() > 1 && mirror.nextId > m_idStride)
    throw std::runtime_error(
        fmt::format("CUDA backend: a case made more than {} bodies, the room for its ids in a shared device state", m_idStride));
  m_edited = true;
}

void CudaBatch::finishedStep(long step) {
  if (++m_finished < worlds()) return;
  m_finished = 0;
  m_stepsDone = step + 1;
  applyEdits();
  // The resident kernel re-sorted itself, unless the host's topology phase took this step (then
  // every world is re-sorted here; the kernel's re-sort of the others gives the same order again).
  const bool sortedOnDevice =
      m_device->resident() && !(m_result->hostTopology && step + 1 == m_resultFirst + static_cast<long>(m_result->steps.size()));
  if (m_members.front()->scenario().mortonSort && isResortStep(step + 1) && !sortedOnDevice) {
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

// A permutation of the device state (new slot k holds slot order[k], whose world was
// worldBefore[order[k]]) in each case's mirror bookkeeping.
void CudaBatch::followOrder(const std::vector<int>& order, const std::vector<int>& worldBefore) {
  m_slotsOfWorld.clear();
  if (worlds() == 1) {
    m_members.front()->followReorder(order);
    return;
  }
  // Each world's share of the order, in its own slots: the rank of a shared slot among its world's.
  std::vector<int> localOf(worldBefore.size()), seen(static_cast<size_t>(worlds()), 0);
  for (size_t k = 0; k < worldBefore.size(); ++k) localOf[k] = seen[static_cast<size_t>(worldBefore[k])]++;
  std::vector<std::vector<int>> local(static_cast<size_t>(worlds()));
  for (int old : order) local[static_cast<size_t>(worldBefore[static_cast<size_t>(old)])].push_back(localOf[static_cast<size_t>(old)]);
  for (int w = 0; w < worlds(); ++w) m_members[static_cast<size_t>(w)]->followReorder(local[static_cast<size_t>(w)]);
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
  followOrder(order, worldBefore);
  if (!followed) {
    // A device broadphase that keeps per-body storage but cannot permute it (a plugin's, say; one
    // world only) rebuilds from the whole world, in the new order.
    for (CudaStepper* m : m_members) m->downloadState();
    uploadAll();
  }
}

}  // namespace gem
