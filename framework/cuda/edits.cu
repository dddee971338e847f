// Topology edits and the re-sort along the curve, replayed on the device: the kept rows permuted
// in place, the new bodies' rows uploaded, and the few bodies the host's topology phase reads.
#include <cub/device/device_radix_sort.cuh>

#include <algorithm>
#include <cstddef>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "framework/api/cuda_check.hpp"
#include "framework/cuda/device_state.cuh"
#include "framework/cuda/device_step.hpp"
#include "framework/cuda/step_phases.cuh"
#include "framework/step/phases.hpp"

namespace gem::cuda {

namespace {

// Per world: the box of its bodies' centroids (min x, min y, max x, max y), as ordered bits.
__global__ void curveBoundsInitKernel(int worlds, unsigned long long* bounds) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k < 4 * worlds) bounds[k] = k % 4 < 2 ? ~0ull : 0ull;
}
__global__ void curveBoundsKernel(int n, const Real* x, const Real* y, const int* world, unsigned long long* bounds) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  unsigned long long* b = bounds + 4 * world[i];
  const unsigned long long bx = orderedRealBits(x[i]), by = orderedRealBits(y[i]);
  atomicMin(b + 0, bx), atomicMin(b + 1, by), atomicMax(b + 2, bx), atomicMax(b + 3, by);
}

// Key (world, curve key within the world's box): worlds in order, each along its own curve.
__global__ void curveKeyKernel(int n, const Real* x, const Real* y, const int* world, const unsigned long long* bounds,
                               unsigned long long* key, int* slot) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const unsigned long long* b = bounds + 4 * world[i];
  const Real x0 = fromOrderedRealBits(b[0]), y0 = fromOrderedRealBits(b[1]);
  const Real scale = curveScale(x0, y0, fromOrderedRealBits(b[2]), fromOrderedRealBits(b[3]));
  key[i] = (static_cast<unsigned long long>(world[i]) << 32) | curveKey(x[i], y[i], x0, y0, scale);
  slot[i] = i;
}

template <class T>
__global__ void gatherRowsKernel(int n, int width, const int* order, const T* from, T* to) {
  const size_t k = static_cast<size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (k >= static_cast<size_t>(n) * width) return;
  const size_t row = k / width, column = k % width;
  to[k] = from[static_cast<size_t>(order[row]) * width + column];
}

// Row k of the buffer becomes old row order[k], for k < n (a permutation of the n rows, or the
// kept rows of `from` rows after a topology edit). The buffer then has room for `room` rows.
template <class T>
void permuteOnDevice(GraphArray<T>& buffer, int n, int width, const int* order, ReorderScratch& scratch, cudaStream_t s, int from = -1,
                     int room = -1) {
  const size_t rows = static_cast<size_t>(from < 0 ? n : from), count = static_cast<size_t>(n) * width;
  scratch.ensure(std::max<size_t>(rows * width, 1) * sizeof(T));
  T* copy = reinterpret_cast<T*>(scratch.get());
  GEM_CUDA_CHECK(cudaMemcpyAsync(copy, buffer.get(), rows * width * sizeof(T), cudaMemcpyDeviceToDevice, s));
  if (room > n) {
    GEM_CUDA_CHECK(cudaStreamSynchronize(s));  // ensure() may free the buffer the copy reads
    buffer.ensure(static_cast<size_t>(room) * width);
  }
  if (count > 0) {
    gatherRowsKernel<T><<<static_cast<unsigned>((count + kBlock - 1) / kBlock), kBlock, 0, s>>>(n, width, order, copy, buffer.get());
    GEM_CUDA_CHECK_LAUNCH();
  }
  GEM_CUDA_CHECK(cudaStreamSynchronize(s));  // the scratch is reused by the next array
}

// order[k] = the k-th slot not in `removed` (ascending): the gather of a stable compaction.
__global__ void keptOrderKernel(int n, const int* removed, int removedCount, int* order) {
  const int slot = blockIdx.x * blockDim.x + threadIdx.x;
  if (slot >= n) return;
  int lo = 0, hi = removedCount;  // removed slots below `slot`
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (removed[mid] < slot)
      lo = mid + 1;
    else
      hi = mid;
  }
  if (lo < removedCount && removed[lo] == slot) return;
  order[slot - lo] = slot;
}

// Kinematics of a few bodies, for the host's topology phase.
__global__ void gatherKinematicsKernel(int count, const int* slots, const Real* x, const Real* y, const Real* angle, const Real* vx,
                                       const Real* vy, const Real* omega, Real* out) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= count) return;
  const int i = slots[k];
  Real* row = out + 6 * k;
  row[0] = x[i], row[1] = y[i], row[2] = angle[i], row[3] = vx[i], row[4] = vy[i], row[5] = omega[i];
}

}  // namespace

std::vector<int> DeviceStep::reorderAlongCurve(bool* broadphaseFollowed) {
  DeviceState& d = *m_state;
  const int n = d.n;
  *broadphaseFollowed = true;
  std::vector<int> order(static_cast<size_t>(n));
  if (n < 2) {
    for (int i = 0; i < n; ++i) order[static_cast<size_t>(i)] = i;
    return order;
  }
  cudaStream_t s = d.stream;
  ReorderScratch& sortScratch = d.sortScratch;
  // Each world's centroid box: exact (min and max round nothing), as the host's loop.
  GraphArray<unsigned long long>& bounds = d.resortBounds;
  bounds.ensure(4 * static_cast<size_t>(d.worlds));
  awaitHostCopies();
  curveBoundsInitKernel<<<blocksFor(4 * d.worlds), kBlock, 0, s>>>(d.worlds, bounds.get());
  GEM_CUDA_CHECK_LAUNCH();
  curveBoundsKernel<<<blocksFor(n), kBlock, 0, s>>>(n, d.x.get(), d.y.get(), d.world.get(), bounds.get());
  GEM_CUDA_CHECK_LAUNCH();
  // Keys, then a stable radix sort: ties keep slot order, as the host's sort of (key, slot) pairs.
  GraphArray<unsigned long long>& keys = d.resortKeys;
  GraphArray<unsigned long long>& sortedKeys = d.resortKeysSorted;
  GraphArray<int>& slots = d.resortSlots;
  GraphArray<int>& sortedSlots = d.resortSlotsSorted;
  keys.ensure(n), sortedKeys.ensure(n), slots.ensure(n), sortedSlots.ensure(n);
  curveKeyKernel<<<blocksFor(n), kBlock, 0, s>>>(n, d.x.get(), d.y.get(), d.world.get(), bounds.get(), keys.get(), slots.get());
  GEM_CUDA_CHECK_LAUNCH();
  const int keyBits = 32 + (d.worlds > 1 ? bitsFor(static_cast<unsigned long long>(d.worlds - 1)) : 0);
  size_t bytes = 0;
  GEM_CUDA_CHECK(
      cub::DeviceRadixSort::SortPairs(nullptr, bytes, keys.get(), sortedKeys.get(), slots.get(), sortedSlots.get(), n, 0, keyBits, s));
  sortScratch.ensure(bytes);
  void* temp = sortScratch.get();
  GEM_CUDA_CHECK(
      cub::DeviceRadixSort::SortPairs(temp, bytes, keys.get(), sortedKeys.get(), slots.get(), sortedSlots.get(), n, 0, keyBits, s));
  // The download goes on the legacy stream, which does not wait for the sort on the state's
  // non-blocking stream: wait here, or the order read back may be the sort's half-written output.
  GEM_CUDA_CHECK(cudaStreamSynchronize(s));
  sortedSlots.download(order.data(), static_cast<size_t>(n));
  permuteDeviceState(d, sortedSlots.get(), order);
  if (d.broadphase) *broadphaseFollowed = d.broadphase->reorder(sortedSlots.get(), n, s);
  return order;
}

void permuteDeviceState(DeviceState& d, const int* o, const std::vector<int>& order) {
  const int n = d.n;
  cudaStream_t s = d.stream;
  ReorderScratch& scratch = d.permuteScratch;
  permuteOnDevice(d.id, n, 1, o, scratch, s), permuteOnDevice(d.kind, n, 1, o, scratch, s);
  permuteOnDevice(d.world, n, 1, o, scratch, s);
  permuteOnDevice(d.vertexCount, n, 1, o, scratch, s), permuteOnDevice(d.dof, n, 1, o, scratch, s);
  permuteOnDevice(d.local, n, kMaxVertices, o, scratch, s), permuteOnDevice(d.isLarge, n, 1, o, scratch, s);
  for (GraphArray<Real>* r : {&d.x, &d.y, &d.angle, &d.vx, &d.vy, &d.omega, &d.radius, &d.area, &d.thickness, &d.mass, &d.invMass,
                              &d.invInertia, &d.gyration2, &d.gyrationX2, &d.gyrationY2, &d.principalAngle})
    permuteOnDevice(*r, n, 1, o, scratch, s);

  // The large bodies' and the vessels' new slots, the worlds' (their count is unchanged: the graph
  // stays valid).
  std::vector<unsigned char> isLarge(static_cast<size_t>(n));
  d.isLarge.download(isLarge.data(), static_cast<size_t>(n));
  std::vector<int> newSlot(static_cast<size_t>(n)), worldBefore = d.worldHost;
  d.largeHost.clear();
  for (int k = 0; k < n; ++k) {
    if (isLarge[static_cast<size_t>(k)]) d.largeHost.push_back(k);
    newSlot[static_cast<size_t>(order[static_cast<size_t>(k)])] = k;
    d.worldHost[static_cast<size_t>(k)] = worldBefore[static_cast<size_t>(order[static_cast<size_t>(k)])];
  }
  for (int& v : d.vesselHost)
    if (v >= 0) v = newSlot[static_cast<size_t>(v)];
  d.large.upload(d.largeHost.data(), d.largeHost.size());
  uploadVessels(d);
}

void DeviceStep::downloadKinematics(const std::vector<int>& deviceSlots, const std::vector<int>& hostSlots, World& w) const {
  DeviceState& d = *m_state;
  const int count = static_cast<int>(deviceSlots.size());
  if (count == 0) return;
  GraphArray<int>& slots = d.fetchSlots;
  GraphArray<Real>& rows = d.fetchRows;
  slots.upload(deviceSlots.data(), deviceSlots.size());
  rows.ensure(6 * deviceSlots.size());
  awaitHostCopies();  // slots: the kernel's indices
  gatherKinematicsKernel<<<blocksFor(count), kBlock, 0, d.stream>>>(count, slots.get(), d.x.get(), d.y.get(), d.angle.get(), d.vx.get(),
                                                                    d.vy.get(), d.omega.get(), rows.get());
  GEM_CUDA_CHECK_LAUNCH();
  GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
  std::vector<Real> values(6 * deviceSlots.size());
  rows.download(values.data(), values.size());
  for (int k = 0; k < count; ++k) {
    const int i = hostSlots[static_cast<size_t>(k)];
    const Real* row = &values[6 * static_cast<size_t>(k)];
    w.x[i] = row[0], w.y[i] = row[1], w.angle[i] = row[2], w.vx[i] = row[3], w.vy[i] = row[4], w.omega[i] = row[5];
  }
}

bool DeviceStep::editBodies(const std::vector<int>& removedSlots, const World& from, int firstAdded, const std::vector<int>& addedWorlds,
                            const std::vector<int>& vesselDofs) {
  return editDeviceBodies(*m_state, removedSlots, from, firstAdded, addedWorlds, vesselDofs);
}

bool editDeviceBodies(DeviceState& d, const std::vector<int>& removedSlots, const World& from, int firstAdded,
                      const std::vector<int>& addedWorlds, const std::vector<int>& vesselDofs) {
  const int before = d.n, removedCount = static_cast<int>(removedSlots.size());
  const int kept = before - removedCount, added = from.size() - firstAdded, n = kept + added;
  if (kept < 0 || added < 0 || (!addedWorlds.empty() && addedWorlds.size() != static_cast<size_t>(added)) ||
      vesselDofs.size() != static_cast<size_t>(d.worlds))
    throw std::logic_error("DeviceStep::editBodies: the edit does not match the device's bodies");
  cudaStream_t s = d.stream;
  ReorderScratch& scratch = d.permuteScratch;

  // The kept rows, in their order (a stable compaction), with room for the new ones after them.
  GraphArray<int>& removed = d.editRemoved;
  GraphArray<int>& order = d.editOrder;
  removed.ensure(std::max<size_t>(removedSlots.size(), 1));
  removed.uploadAt(0, removedSlots.data(), removedSlots.size());
  order.ensure(static_cast<size_t>(std::max(kept, 1)));
  awaitHostCopies();  // removed: read by the kernel below
  keptOrderKernel<<<blocksFor(before), kBlock, 0, s>>>(before, removed.get(), removedCount, order.get());
  GEM_CUDA_CHECK_LAUNCH();
  const int* o = order.get();
  permuteOnDevice(d.id, kept, 1, o, scratch, s, before, n), permuteOnDevice(d.kind, kept, 1, o, scratch, s, before, n);
  permuteOnDevice(d.vertexCount, kept, 1, o, scratch, s, before, n), permuteOnDevice(d.dof, kept, 1, o, scratch, s, before, n);
  permuteOnDevice(d.local, kept, kMaxVertices, o, scratch, s, before, n), permuteOnDevice(d.isLarge, kept, 1, o, scratch, s, before, n);
  permuteOnDevice(d.world, kept, 1, o, scratch, s, before, n);
  GraphArray<Real>* reals[] = {
      &d.x,         &d.y,    &d.angle,   &d.vx,         &d.vy,        &d.omega,      &d.radius,     &d.area,
      &d.thickness, &d.mass, &d.invMass, &d.invInertia, &d.gyration2, &d.gyrationX2, &d.gyrationY2, &d.principalAngle};
  for (GraphArray<Real>* r : reals) permuteOnDevice(*r, kept, 1, o, scratch, s, before, n);

  // The new bodies' rows, as World::addBody made them on the host (a few per step): rows
  // from[firstAdded..] go to slots kept...
  const size_t at = static_cast<size_t>(kept), first = static_cast<size_t>(firstAdded), count = static_cast<size_t>(added);
  d.id.uploadAt(at, from.id.data() + first, count);
  d.kind.uploadAt(at, from.kind.data() + first, count);
  d.vertexCount.uploadAt(at, from.vertexCount.data() + first, count);
  d.local.uploadAt(at * kMaxVertices, from.localVertices.data() + first * kMaxVertices, count * kMaxVertices);
  const std::vector<Real>* hostReals[] = {&from.x,         &from.y,          &from.angle,      &from.vx,
                                          &from.vy,        &from.omega,      &from.radius,     &from.area,
                                          &from.thickness, &from.mass,       &from.invMass,    &from.invInertia,
                                          &from.gyration2, &from.gyrationX2, &from.gyrationY2, &from.principalAngle};
  for (size_t k = 0; k < std::size(reals); ++k) reals[k]->uploadAt(at, hostReals[k]->data() + first, count);
  std::vector<int> dof(count), worlds(count, 0);
  std::vector<unsigned char> isLarge(count);
  for (size_t k = 0; k < count; ++k) {
    if (!addedWorlds.empty()) worlds[k] = addedWorlds[k];
    dof[k] = degreesOfFreedom(from.kind[first + k], vesselDofs[static_cast<size_t>(worlds[k])]);
    isLarge[k] = 2 * from.radius[first + k] > d.cell;  // the cell stays: a smaller largest floe only makes it coarse
  }
  d.dof.uploadAt(at, dof.data(), count);
  d.isLarge.uploadAt(at, isLarge.data(), count);
  d.world.uploadAt(at, worlds.data(), count);

  // Slots past a removed body move down by the number removed before them.
  auto newSlot = [&](int slot) {
    return slot - static_cast<int>(std::lower_bound(removedSlots.begin(), removedSlots.end(), slot) - removedSlots.begin());
  };
  std::vector<int> large;
  for (int slot : d.largeHost)
    if (!std::binary_search(removedSlots.begin(), removedSlots.end(), slot)) large.push_back(newSlot(slot));
  for (size_t k = 0; k < count; ++k)
    if (isLarge[k]) large.push_back(kept + static_cast<int>(k));
  d.largeHost = large;
  d.large.upload(large.data(), large.size());
  d.largeCount = static_cast<int>(large.size());
  for (int& v : d.vesselHost) {
    if (v < 0) continue;
    if (std::binary_search(removedSlots.begin(), removedSlots.end(), v))
      throw std::logic_error("DeviceStep::editBodies: a topology event removed the vessel");
    v = newSlot(v);
  }
  uploadVessels(d);
  std::vector<int> worldAfter;
  worldAfter.reserve(static_cast<size_t>(n));
  for (int slot = 0, r = 0; slot < before; ++slot) {
    if (r < removedCount && removedSlots[static_cast<size_t>(r)] == slot) {
      ++r;
      continue;
    }
    worldAfter.push_back(d.worldHost[static_cast<size_t>(slot)]);
  }
  worldAfter.insert(worldAfter.end(), worlds.begin(), worlds.end());
  d.worldHost.swap(worldAfter);
  d.n = n;
  sizeForBodies(d, from.nextId);
  // A strategy's per-body storage follows the edit on the device, or (false) the caller uploads it.
  awaitHostCopies();  // the new bodies' rows, which the strategy's kernels read
  const bool followed = !d.broadphase || d.broadphase->edited(o, kept, from, firstAdded, s);
  d.dropGraph();  // n changed: the graph's launches were sized for the old count
  return followed;
}

}  // namespace gem::cuda
