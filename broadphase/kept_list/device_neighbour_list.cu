// The kept list's check and build kernels and its storage (device_neighbour_list.cuh says what each
// step does and why).
#include "broadphase/kept_list/device_neighbour_list.cuh"

#include <cub/device/device_radix_sort.cuh>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gem::cuda {

// 1. NeighbourList::update on the device: a listed body past half the skin becomes direct; past
// the room for direct bodies, or when the list is stale, the step rebuilds.
__global__ void listCheckKernel(ListView list, BroadphaseBodies b) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= b.n) return;
  if (!list.control->valid) {
    if (i == 0) list.control->rebuild = 1;
    return;
  }
  if (list.direct[i]) return;  // its pairs are found afresh every step
  const Real dx = b.x[i] - list.x0[i], dy = b.y[i] - list.y0[i];
  // A point at distance R from the centroid moves at most R |turn| under a turn (the turn wrapped
  // to [-pi, pi], as in NeighbourList::update).
  Real turn = fabs(b.angle[i] - list.angle0[i]);
  if (turn > kPi) turn = fabs(remainder(turn, Real(2) * kPi));
  if (sqrt(dx * dx + dy * dy) + b.radius[i] * turn <= list.limit) return;
  const int k = atomicAdd(&list.control->directCount, 1);
  if (k < list.directRoom) {
    list.directList[k] = i;
    list.direct[i] = 1;
  } else {
    list.control->rebuild = 1;
  }
}

// 2. The sweep's order: the low end of each body's x span.
__global__ void listSpanKernel(ListView list, BroadphaseBodies b) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= b.n) return;
  list.lo[i] = b.x[i] - max(list.floor / 2, list.half[i]);
  list.slot[i] = i;
}

// 3a. A rebuild's reference state, as NeighbourList::finish.
__global__ void listResetKernel(ListView list, BroadphaseBodies b) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= b.n || !list.control->rebuild) return;
  list.x0[i] = b.x[i];
  list.y0[i] = b.y[i];
  list.angle0[i] = b.angle[i];
  list.direct[i] = list.alwaysDirect[i];
  if (i == 0) {
    list.control->count = 0;
    list.control->directCount = list.alwaysDirectCount;
    list.control->valid = 1;
    ++list.control->rebuilds;
  }
}

// 3b. PairsWithinReach's rule (neighbour_list.hpp): |c_a - c_b| <= max(floor, h_a + h_b), found by walking forward
// from each body while the next span starts before this one ends. The always-direct bodies are
// left out (the direct pass covers them); each pair keeps (R_a + R_b)^2 for the filter.
__global__ void listSweepKernel(ListView list, BroadphaseBodies b) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= b.n || !list.control->rebuild) return;
  const int i = list.slotSorted[k];
  if (list.alwaysDirect[i]) return;
  const Real hi = b.x[i] + max(list.floor / 2, list.half[i]), xi = b.x[i], yi = b.y[i], hin = list.half[i], ri = b.radius[i];
  for (int q = k + 1; q < b.n && list.loSorted[q] <= hi; ++q) {
    const int j = list.slotSorted[q];
    if (list.alwaysDirect[j]) continue;
    const Real dx = xi - b.x[j], dy = yi - b.y[j], reach = max(list.floor, hin + list.half[j]);
    if (dx * dx + dy * dy > reach * reach) continue;
    const int at = atomicAdd(&list.control->count, 1);
    if (at >= list.capacity) continue;  // counted: the filter asks for a redo with more room
    const Real touch = ri + b.radius[j];
    list.pairs[at] = ListedPair{i < j ? i : j, i < j ? j : i, touch * touch};
  }
}

// The build proper (span, sort, reset, sweep): every step when launched one by one (each kernel
// checks the rebuild flag), only when the flag is set inside a captured step.
static void enqueueBuildSteps(const ListView& list, const BroadphaseBodies& bodies, void* temp, size_t tempBytes, cudaStream_t s) {
  const int n = bodies.n;
  listSpanKernel<<<blocksFor(n), kBlock, 0, s>>>(list, bodies);
  GEM_CUDA_CHECK_LAUNCH();
  GEM_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp, tempBytes, list.lo, list.loSorted, list.slot, list.slotSorted, n, 0,
                                                 static_cast<int>(sizeof(Real) * 8), s));
  listResetKernel<<<blocksFor(n), kBlock, 0, s>>>(list, bodies);
  GEM_CUDA_CHECK_LAUNCH();
  listSweepKernel<<<blocksFor(n), kBlock, 0, s>>>(list, bodies);
  GEM_CUDA_CHECK_LAUNCH();
}

// The IF node's condition: this step rebuilds.
__global__ void setRebuildConditionKernel(cudaGraphConditionalHandle handle, const ListControl* control) {
  cudaGraphSetConditional(handle, control->rebuild ? 1u : 0u);
}

void enqueueListBuild(const ListView& list, const BroadphaseBodies& bodies, void* temp, size_t tempBytes, cudaStream_t s,
                      cudaStream_t side) {
  const int n = bodies.n;
  GEM_CUDA_CHECK(cudaMemsetAsync(&list.control->rebuild, 0, sizeof(int), s));
  listCheckKernel<<<blocksFor(n), kBlock, 0, s>>>(list, bodies);
  GEM_CUDA_CHECK_LAUNCH();
  cudaStreamCaptureStatus status = cudaStreamCaptureStatusNone;
  cudaGraph_t graph = nullptr;
  GEM_CUDA_CHECK(cudaStreamGetCaptureInfo(s, &status, nullptr, &graph));
  if (status != cudaStreamCaptureStatusActive || !side) {
    enqueueBuildSteps(list, bodies, temp, tempBytes, s);
    return;
  }
  // Captured: the build sits in an IF node, so a step that keeps its list skips the span, the
  // sort of n keys and the sweep (17 us of a 824-floe step on an H200, and n-sized work at 10^6).
  cudaGraphConditionalHandle handle;
  GEM_CUDA_CHECK(cudaGraphConditionalHandleCreate(&handle, graph, 0, cudaGraphCondAssignDefault));
  setRebuildConditionKernel<<<1, 1, 0, s>>>(handle, list.control);
  GEM_CUDA_CHECK_LAUNCH();
  const cudaGraphNode_t* dependencies = nullptr;
  size_t dependencyCount = 0;
  GEM_CUDA_CHECK(cudaStreamGetCaptureInfo(s, &status, nullptr, &graph, &dependencies, nullptr, &dependencyCount));
  cudaGraphNodeParams params{};
  params.type = cudaGraphNodeTypeConditional;
  params.conditional.handle = handle;
  params.conditional.type = cudaGraphCondTypeIf;
  params.conditional.size = 1;
  cudaGraphNode_t node;
  GEM_CUDA_CHECK(cudaGraphAddNode(&node, graph, dependencies, nullptr, dependencyCount, &params));
  GEM_CUDA_CHECK(cudaStreamUpdateCaptureDependencies(s, &node, nullptr, 1, cudaStreamSetCaptureDependencies));
  cudaGraph_t body = params.conditional.phGraph_out[0];
  GEM_CUDA_CHECK(cudaStreamBeginCaptureToGraph(side, body, nullptr, nullptr, 0, cudaStreamCaptureModeThreadLocal));
  try {
    enqueueBuildSteps(list, bodies, temp, tempBytes, side);
  } catch (...) {
    cudaStreamEndCapture(side, &body);
    throw;
  }
  GEM_CUDA_CHECK(cudaStreamEndCapture(side, &body));
}

void DeviceNeighbourList::resize(int n) {
  m_n = n;
  if (!m_side) GEM_CUDA_CHECK(cudaStreamCreateWithFlags(&m_side, cudaStreamNonBlocking));
  const size_t nn = static_cast<size_t>(std::max(n, 1));
  m_direct.ensure(nn), m_x0.ensure(nn), m_y0.ensure(nn), m_angle0.ensure(nn);
  m_lo.ensure(nn), m_loSorted.ensure(nn), m_slot.ensure(nn), m_slotSorted.ensure(nn);
  if (m_capacity == 0) m_capacity = 8 * n + 1024;  // grows in reserve() when a build needs more
  m_pairs.ensure(static_cast<size_t>(m_capacity));
  size_t bytes = 0;
  GEM_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, bytes, m_lo.get(), m_loSorted.get(), m_slot.get(), m_slotSorted.get(), n, 0,
                                                 static_cast<int>(sizeof(Real) * 8)));
  m_temp.ensure(std::max<size_t>(bytes, 1));
  m_tempBytes = bytes;
  if (m_control.ensure(1)) GEM_CUDA_CHECK(cudaMemset(m_control.get(), 0, sizeof(ListControl)));
}

void DeviceNeighbourList::upload(const World& world, const std::vector<Real>& half, Real floor) {
  const int n = world.size();
  m_floor = floor;
  const size_t nn = static_cast<size_t>(std::max(n, 1));
  std::vector<unsigned char> always(nn, 0);
  std::vector<int> alwaysList;
  for (int i = 0; i < n; ++i)
    if (world.kind[i] != BodyKind::Floe) always[i] = 1, alwaysList.push_back(i);
  m_alwaysDirectCount = static_cast<int>(alwaysList.size());
  m_half.upload(half.data(), half.size());
  m_alwaysDirect.upload(always.data(), nn);
  m_directList.ensure(static_cast<size_t>(m_alwaysDirectCount + NeighbourList::kMaxDirect));
  if (!alwaysList.empty())
    GEM_CUDA_CHECK(cudaMemcpy(m_directList.get(), alwaysList.data(), alwaysList.size() * sizeof(int), cudaMemcpyHostToDevice));
  resize(n);
  markStale();  // slots may name other bodies now (NeighbourList::invalidate)
}

// The slots of the always-direct bodies after a re-sort (their order in the list does not matter:
// every candidate is sorted afterwards).
__global__ void alwaysDirectListKernel(int n, const unsigned char* always, int* list, int* found) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n && always[i]) list[atomicAdd(found, 1)] = i;
}

void DeviceNeighbourList::reorder(const int* order, int n, cudaStream_t s) {
  if (n != m_n) throw std::logic_error("DeviceNeighbourList::reorder: the body count changed (that takes an upload)");
  if (n == 0) return;
  const size_t nn = static_cast<size_t>(n);
  m_halfBefore.ensure(nn), m_alwaysBefore.ensure(nn), m_alwaysFound.ensure(1);
  GEM_CUDA_CHECK(cudaMemcpyAsync(m_halfBefore.get(), m_half.get(), nn * sizeof(Real), cudaMemcpyDeviceToDevice, s));
  GEM_CUDA_CHECK(cudaMemcpyAsync(m_alwaysBefore.get(), m_alwaysDirect.get(), nn, cudaMemcpyDeviceToDevice, s));
  gatherByOrderKernel<Real><<<blocksFor(n), kBlock, 0, s>>>(n, 1, order, m_halfBefore.get(), m_half.get());
  GEM_CUDA_CHECK_LAUNCH();
  gatherByOrderKernel<unsigned char><<<blocksFor(n), kBlock, 0, s>>>(n, 1, order, m_alwaysBefore.get(), m_alwaysDirect.get());
  GEM_CUDA_CHECK_LAUNCH();
  GEM_CUDA_CHECK(cudaMemsetAsync(m_alwaysFound.get(), 0, sizeof(int), s));
  alwaysDirectListKernel<<<blocksFor(n), kBlock, 0, s>>>(n, m_alwaysDirect.get(), m_directList.get(), m_alwaysFound.get());
  GEM_CUDA_CHECK_LAUNCH();
  GEM_CUDA_CHECK(cudaStreamSynchronize(s));
  markStale();  // slots name other bodies now (NeighbourList::invalidate)
}

void DeviceNeighbourList::edited(const int* keptOrder, int kept, const std::vector<Real>& addedHalf,
                                 const std::vector<unsigned char>& addedAlways, cudaStream_t s) {
  const size_t before = static_cast<size_t>(m_n), added = addedHalf.size(), n = static_cast<size_t>(kept) + added;
  m_halfBefore.ensure(std::max<size_t>(before, 1)), m_alwaysBefore.ensure(std::max<size_t>(before, 1)), m_alwaysFound.ensure(1);
  if (before) {
    GEM_CUDA_CHECK(cudaMemcpyAsync(m_halfBefore.get(), m_half.get(), before * sizeof(Real), cudaMemcpyDeviceToDevice, s));
    GEM_CUDA_CHECK(cudaMemcpyAsync(m_alwaysBefore.get(), m_alwaysDirect.get(), before, cudaMemcpyDeviceToDevice, s));
  }
  GEM_CUDA_CHECK(cudaStreamSynchronize(s));  // ensure() below may move the arrays just copied
  m_half.ensure(std::max<size_t>(n, 1)), m_alwaysDirect.ensure(std::max<size_t>(n, 1));
  if (kept > 0) {
    gatherByOrderKernel<Real><<<blocksFor(kept), kBlock, 0, s>>>(kept, 1, keptOrder, m_halfBefore.get(), m_half.get());
    GEM_CUDA_CHECK_LAUNCH();
    gatherByOrderKernel<unsigned char><<<blocksFor(kept), kBlock, 0, s>>>(kept, 1, keptOrder, m_alwaysBefore.get(), m_alwaysDirect.get());
    GEM_CUDA_CHECK_LAUNCH();
  }
  if (added) {
    GEM_CUDA_CHECK(cudaMemcpyAsync(m_half.get() + kept, addedHalf.data(), added * sizeof(Real), cudaMemcpyHostToDevice, s));
    GEM_CUDA_CHECK(cudaMemcpyAsync(m_alwaysDirect.get() + kept, addedAlways.data(), added, cudaMemcpyHostToDevice, s));
  }
  // The always-direct slots, counted again (a wall or the vessel never breaks, but a plugin's
  // topology event might add one).
  int alwaysCount = 0;
  GEM_CUDA_CHECK(cudaMemsetAsync(m_alwaysFound.get(), 0, sizeof(int), s));
  m_directList.ensure(static_cast<size_t>(m_alwaysDirectCount) + added + NeighbourList::kMaxDirect);
  alwaysDirectListKernel<<<blocksFor(static_cast<int>(n)), kBlock, 0, s>>>(static_cast<int>(n), m_alwaysDirect.get(), m_directList.get(),
                                                                           m_alwaysFound.get());
  GEM_CUDA_CHECK_LAUNCH();
  GEM_CUDA_CHECK(cudaMemcpyAsync(&alwaysCount, m_alwaysFound.get(), sizeof(int), cudaMemcpyDeviceToHost, s));
  GEM_CUDA_CHECK(cudaStreamSynchronize(s));
  m_alwaysDirectCount = alwaysCount;
  resize(static_cast<int>(n));
  markStale();  // slots name other bodies now (NeighbourList::invalidate)
}

cudaStream_t DeviceNeighbourList::sideStream() { return m_side; }

void DeviceNeighbourList::markStale() { GEM_CUDA_CHECK(cudaMemset(&m_control.get()->valid, 0, sizeof(int))); }

// Outside the graph (before a capture): a build that found the list too small asked for a redo
// (listFilterKernel); make room for what it counted.
void DeviceNeighbourList::reserve() {
  if (!m_control.get()) return;
  ListControl control{};
  GEM_CUDA_CHECK(cudaMemcpy(&control, m_control.get(), sizeof(ListControl), cudaMemcpyDeviceToHost));
  if (control.count <= m_capacity) return;
  m_capacity = control.count + control.count / 2 + 1024;
  m_pairs.ensure(static_cast<size_t>(m_capacity));
  markStale();
}

long DeviceNeighbourList::rebuilds() const {
  if (!m_control.get()) return 0;
  ListControl control{};
  GEM_CUDA_CHECK(cudaMemcpy(&control, m_control.get(), sizeof(ListControl), cudaMemcpyDeviceToHost));
  return static_cast<long>(control.rebuilds);
}

ListView DeviceNeighbourList::view() {
  return ListView{m_control.get(),
                  m_half.get(),
                  m_floor,
                  kRebuildTrigger * m_skin / 2,
                  m_alwaysDirect.get(),
                  m_direct.get(),
                  m_directList.get(),
                  m_alwaysDirectCount + NeighbourList::kMaxDirect,
                  m_alwaysDirectCount,
                  m_x0.get(),
                  m_y0.get(),
                  m_angle0.get(),
                  m_pairs.get(),
                  m_capacity,
                  m_lo.get(),
                  m_loSorted.get(),
                  m_slot.get(),
                  m_slotSorted.get()};
}

}  // namespace gem::cuda
