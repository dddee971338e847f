// DeviceState's side of DeviceStep: its construction, the world uploaded to the device and
// downloaded back, and the sizing of every per-body buffer that follows from n and the ids.
#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "framework/api/cuda_check.hpp"
#include "framework/cuda/device_state.cuh"
#include "framework/cuda/device_step.hpp"
#include "framework/cuda/step_phases.cuh"
#include "framework/step/phases.hpp"

namespace gem::cuda {

DeviceStep::DeviceStep() : m_state(std::make_unique<DeviceState>()) {}
DeviceStep::~DeviceStep() = default;
void DeviceStep::addPairEvent(std::unique_ptr<CudaEventDriver> driver) { m_state->pairEvents.push_back(std::move(driver)); }
void DeviceStep::addSoloEvent(std::unique_ptr<CudaEventDriver> driver) { m_state->soloEvents.push_back(std::move(driver)); }
void DeviceStep::addMotionEvent(std::unique_ptr<CudaEventDriver> driver) { m_state->motionEvents.push_back(std::move(driver)); }
void DeviceStep::setBroadphase(std::unique_ptr<CudaBroadphase> broadphase) {
  m_state->dropGraph();
  m_state->broadphase = std::move(broadphase);
}
const CudaBroadphase* DeviceStep::broadphase() const { return m_state->broadphase.get(); }
void DeviceStep::setGridCell(Real cellSize) {
  m_state->dropGraph();
  m_state->cellSetting = cellSize;
}
void DeviceStep::setRecordStreams(const std::vector<int>& strides, unsigned haltStreams) {
  DeviceState& d = *m_state;
  d.dropGraph();
  if (strides.size() > static_cast<size_t>(kMaxRecordStreams))
    throw std::invalid_argument("DeviceStep::setRecordStreams: too many streams");
  d.recordStreams = static_cast<int>(strides.size());
  for (int s = 0; s < kMaxRecordStreams; ++s) d.recordStride[s] = s < d.recordStreams ? strides[static_cast<size_t>(s)] : 0;
  d.haltStreams = haltStreams;
}
void DeviceStep::setIdStride(std::int64_t idStride) {
  m_state->dropGraph();
  m_state->idStride = idStride;
}

// What a captured graph baked in: when it is the same after an upload (a re-sort along the curve
// every kResortPeriod steps changes only the arrays' contents) the graph is kept, not captured again.
static auto bakedValues(const DeviceState& d) {
  return std::make_tuple(d.n, d.cell, d.tableSize, d.largeCount, d.idBits, d.capacity, d.worlds, graphArrayReallocations().load());
}

// Everything that follows from n and the ids: the hash table, the key widths, the per-step buffers.
void sizeForBodies(DeviceState& d, std::int64_t nextId) {
  const int n = d.n;
  d.slotBits = bitsFor(static_cast<unsigned long long>(n));
  d.tableBits = 6;
  while ((1u << d.tableBits) < 2u * static_cast<unsigned>(n) && d.tableBits < 30) ++d.tableBits;
  d.tableSize = 1u << d.tableBits;

  // Contact keys: (lo << idBits) | hi with room for new ids from breaks; widened (and the kept keys
  // re-keyed) when the ids outgrow it.
  const int bitsNeeded = bitsFor(static_cast<unsigned long long>(std::max<std::int64_t>(nextId, 1)));
  if (bitsNeeded > 32) throw std::runtime_error("CUDA backend: body ids past 2^32 are not supported");
  if (bitsNeeded > d.idBits) {
    const int newBits = std::min(32, bitsNeeded + 2);
    if (d.idBits > 0 && d.capacity > 0) rekeyContacts(d, newBits);  // contacts.cu
    d.idBits = newBits;
  }

  // Room for every id, the earlier values kept and the new ones 0 (a body's value before its first step).
  const size_t kept = d.contactImpulseOfId.capacity();
  if (d.contactImpulseOfId.ensureKeeping(static_cast<size_t>(std::max<std::int64_t>(nextId, 1)), kept) || kept == 0)
    GEM_CUDA_CHECK(cudaMemset(d.contactImpulseOfId.get() + kept, 0, (d.contactImpulseOfId.capacity() - kept) * sizeof(Real)));

  const size_t nn = std::max(n, 1);
  d.worldVertices.ensure(nn * kMaxVertices);
  d.boxes.ensure(nn), d.pairBodies.ensure(nn), d.soloBodies.ensure(nn), d.changes.ensure(nn), d.motionBodies.ensure(nn);
  d.cellKey.ensure(nn), d.cellKeySorted.ensure(nn), d.slot.ensure(nn), d.slotSorted.ensure(nn);
  d.cellStart.ensure(d.tableSize), d.cellEnd.ensure(d.tableSize);
  d.partnerCount.ensure(nn + 1), d.partnerOffset.ensure(nn + 1);
  d.largeChunk.ensure(static_cast<size_t>(std::max(d.largeCount, 1)) * static_cast<size_t>(largeChunks(n)));
  if (d.capacity == 0) {
    // Grows when a step needs more (that step is then run again). GEM_CUDA_CAPACITY sets the start,
    // so that a test can force the regrowth path.
    const char* start = std::getenv("GEM_CUDA_CAPACITY");
    d.capacity = start ? std::max(1, std::atoi(start)) : 4 * n + 256;
  }
}

int DeviceStep::worlds() const { return m_state->worlds; }

std::vector<Real> DeviceStep::contactImpulsesById(std::int64_t nextId) const {
  std::vector<Real> impulses(static_cast<size_t>(nextId));
  m_state->contactImpulseOfId.download(impulses.data(), impulses.size());
  return impulses;
}
const std::vector<int>& DeviceStep::worldOfSlots() const { return m_state->worldHost; }

// Each world's vessel slot, to the device.
void uploadVessels(DeviceState& d) { d.vessel.upload(d.vesselHost.data(), d.vesselHost.size()); }

void DeviceStep::upload(const World& w, const std::vector<int>& worldOf, const std::vector<int>& vesselSlots,
                        const std::vector<int>& vesselDofs) {
  DeviceState& d = *m_state;
  const int n = w.size(), worlds = static_cast<int>(vesselSlots.size());
  if (worlds < 1 || vesselDofs.size() != vesselSlots.size() || (!worldOf.empty() && worldOf.size() != static_cast<size_t>(n)))
    throw std::invalid_argument("DeviceStep::upload: one world at least, a vessel and its dof per world, a world per body");
  if (worlds != d.worlds) {
    d.worlds = worlds;
    d.setRing(d.ringSize, worlds);
  }
  const auto before = bakedValues(d);
  d.n = n;
  d.worldHost = worldOf.empty() ? std::vector<int>(static_cast<size_t>(n), 0) : worldOf;
  d.world.upload(d.worldHost.data(), d.worldHost.size());
  d.vesselHost = vesselSlots;
  uploadVessels(d);
  d.id.upload(w.id.data(), n);
  d.kind.upload(w.kind.data(), n);
  d.vertexCount.upload(w.vertexCount.data(), n);
  d.local.upload(w.localVertices.data(), static_cast<size_t>(n) * kMaxVertices);
  d.x.upload(w.x.data(), n), d.y.upload(w.y.data(), n), d.angle.upload(w.angle.data(), n);
  d.vx.upload(w.vx.data(), n), d.vy.upload(w.vy.data(), n), d.omega.upload(w.omega.data(), n);
  d.area.upload(w.area.data(), n), d.thickness.upload(w.thickness.data(), n), d.mass.upload(w.mass.data(), n);
  d.invMass.upload(w.invMass.data(), n), d.invInertia.upload(w.invInertia.data(), n);
  d.gyration2.upload(w.gyration2.data(), n), d.gyrationX2.upload(w.gyrationX2.data(), n);
  d.gyrationY2.upload(w.gyrationY2.data(), n), d.principalAngle.upload(w.principalAngle.data(), n);
  d.radius.upload(w.radius.data(), n);
  if (d.broadphase) d.broadphase->upload(w);

  // The grid cell is cell_size when set, else the largest floe diameter, so a floe's box spans at
  // most one cell; bodies larger than a cell (walls, the vessel) are "large" and tested against all.
  std::vector<int> dof(n);
  Real largestFloe = 0;
  for (int i = 0; i < n; ++i) {
    dof[i] = degreesOfFreedom(w.kind[i], vesselDofs[static_cast<size_t>(d.worldHost[static_cast<size_t>(i)])]);
    if (w.kind[i] == BodyKind::Floe) largestFloe = std::max(largestFloe, w.radius[i]);
  }
  d.cell = d.cellSetting > 0 ? d.cellSetting : (largestFloe > 0 ? 2 * largestFloe : Real(1));
  std::vector<unsigned char> isLarge(n);
  d.largeHost.clear();
  for (int i = 0; i < n; ++i) {
    isLarge[i] = 2 * w.radius[i] > d.cell;
    if (isLarge[i]) d.largeHost.push_back(i);
  }
  d.dof.upload(dof.data(), n);
  d.isLarge.upload(isLarge.data(), n);
  d.large.upload(d.largeHost.data(), d.largeHost.size());
  d.largeCount = static_cast<int>(d.largeHost.size());
  sizeForBodies(d, w.nextId);
  // A strategy's own storage (device_broadphase.hpp) may move in its upload(): always re-capture then.
  if (bakedValues(d) != before || d.broadphase) d.dropGraph();
}

void DeviceStep::uploadBroadphase(const World& w) {
  DeviceState& d = *m_state;
  if (!d.broadphase) return;
  d.broadphase->upload(w);
  d.dropGraph();
}

void DeviceStep::download(World& w) const {
  const DeviceState& d = *m_state;
  const int n = w.size();
  d.x.download(w.x.data(), n), d.y.download(w.y.data(), n), d.angle.download(w.angle.data(), n);
  d.vx.download(w.vx.data(), n), d.vy.download(w.vy.data(), n), d.omega.download(w.omega.data(), n);
}

}  // namespace gem::cuda
