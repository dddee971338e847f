// Phase 1 of a step: each body's world vertices, box, the events' views of it (PairBody,
// SoloBody, a zero VelocityChange) and its cell key in the step's hashed grid.
#include <cstdlib>
#include <string>

#include "framework/api/cuda_check.hpp"
#include "framework/cuda/body_phases.cuh"
#include "framework/cuda/device_state.cuh"
#include "framework/cuda/step_phases.cuh"
#include "framework/step/phases.hpp"

namespace gem::cuda {
namespace {

// Phase 1 and the views: as CpuStepper::narrowphase's box loop and CpuStepper::step's view loops.
// A body's rows (16 vertices, a PairBody, a SoloBody) are large, and a thread writing its own is a
// strided pattern that wastes most of each memory transaction (0.92 ms of a 10^6-floe step): on
// large fields the block stages them in shared memory and moves each block's rows as one
// contiguous run. On small ones the staging's barriers cost more than they save (14 -> 27 us at
// 824 floes), and each thread writes its own rows.
constexpr int kPrepareBlock = 128;
constexpr int kStagedPrepareFrom = 16384;  // bodies

// GEM_CUDA_PREPARE = staged or direct overrides the choice (tests compare the two). Read when the
// step is enqueued: once per capture.
static bool stagedPrepare(int n) {
  const char* v = std::getenv("GEM_CUDA_PREPARE");
  if (v && std::string(v) == "staged") return true;
  if (v && std::string(v) == "direct") return false;
  return n >= kStagedPrepareFrom;
}

// The block's `count` consecutive rows of T between global memory and shared memory, 8 bytes a
// thread at a time (every staged type holds doubles, so is a multiple of 8 bytes).
template <class T>
__device__ void copyRows(T* to, const T* from, int count) {
  static_assert(sizeof(T) % 8 == 0, "staged rows are moved as 8-byte words");
  const int words = count * static_cast<int>(sizeof(T) / 8);
  auto* d = reinterpret_cast<unsigned long long*>(to);
  const auto* f = reinterpret_cast<const unsigned long long*>(from);
  for (int w = threadIdx.x; w < words; w += blockDim.x) d[w] = f[w];
}

__global__ void prepareDirectKernel(PrepareArgs a) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < a.n) prepareBody(a, i);
}

__global__ void __launch_bounds__(kPrepareBlock) prepareStagedKernel(PrepareArgs a) {
  // Vertex rows, then PairBody rows, then SoloBody rows: one buffer, used in turn.
  constexpr size_t kRowBytes = sizeof(Vec2) * kMaxVertices > sizeof(PairBody) ? sizeof(Vec2) * kMaxVertices : sizeof(PairBody);
  __shared__ alignas(16) unsigned char staging[kPrepareBlock * kRowBytes];
  const int first = blockIdx.x * kPrepareBlock, i = first + threadIdx.x;
  const int rows = min(kPrepareBlock, a.n - first);
  const bool mine = threadIdx.x < rows;

  auto* vertexRows = reinterpret_cast<Vec2*>(staging);
  copyRows(vertexRows, a.local + static_cast<size_t>(first) * kMaxVertices, rows * kMaxVertices);
  __syncthreads();
  Vec2* v = vertexRows + threadIdx.x * kMaxVertices;
  int count = 0;
  Box box{};
  if (mine) {
    count = a.vertexCount[i];
    toWorld(v, count, Vec2{a.x[i], a.y[i]}, a.angle[i], v);  // in place: each vertex is read, then written
    box = boundingBox(v, count);
  }
  __syncthreads();
  Vec2* worldRow = a.worldVertices + static_cast<size_t>(first) * kMaxVertices;
  copyRows(worldRow, vertexRows, rows * kMaxVertices);
  __syncthreads();

  PairBody b{};
  auto* pairRows = reinterpret_cast<PairBody*>(staging);
  if (mine) {
    a.boxes[i] = box;
    b = pairBodyOf(a, i, a.dof[i], worldRow + threadIdx.x * kMaxVertices, count);
    b.id -= static_cast<std::int64_t>(a.world[i]) * a.idStride;
    pairRows[threadIdx.x] = b;
    a.changes[i] = VelocityChange{{0, 0}, 0};
    // A small body lives in the cell of its box's lower-left corner; large ones stay out of the grid.
    a.cellKey[i] = a.isLarge[i] ? a.largeKey : cellHash(cellCoord(box.x0, a.cell), cellCoord(box.y0, a.cell), a.world[i], a.mask);
    a.slot[i] = i;
  }
  __syncthreads();
  copyRows(a.pairBodies + first, pairRows, rows);
  __syncthreads();
  auto* soloRows = reinterpret_cast<SoloBody*>(staging);
  if (mine) soloRows[threadIdx.x] = SoloBody{b.kind, b.dof, b.position, b.angle, b.velocity, b.omega, b.mass, b.area, b.thickness};
  __syncthreads();
  copyRows(a.soloBodies + first, soloRows, rows);
}

}  // namespace

PrepareArgs prepareArgsOf(DeviceState& d, unsigned largeKey, bool grid) {
  return PrepareArgs{d.n,
                     d.id.get(),
                     d.kind.get(),
                     d.vertexCount.get(),
                     d.dof.get(),
                     d.local.get(),
                     d.x.get(),
                     d.y.get(),
                     d.angle.get(),
                     d.vx.get(),
                     d.vy.get(),
                     d.omega.get(),
                     d.area.get(),
                     d.thickness.get(),
                     d.mass.get(),
                     d.invMass.get(),
                     d.invInertia.get(),
                     d.gyration2.get(),
                     d.gyrationX2.get(),
                     d.gyrationY2.get(),
                     d.principalAngle.get(),
                     d.isLarge.get(),
                     d.world.get(),
                     d.idStride,
                     d.cell,
                     d.tableSize - 1,
                     largeKey,
                     d.worldVertices.get(),
                     d.boxes.get(),
                     d.pairBodies.get(),
                     d.soloBodies.get(),
                     d.changes.get(),
                     grid ? d.cellKey.get() : nullptr,
                     grid ? d.slot.get() : nullptr};
}

void enqueuePrepare(DeviceState& d, unsigned largeKey) {
  cudaStream_t s = d.stream;
  const int n = d.n, block = d.block;
  // 1. World vertices, boxes, views, cell keys.
  const PrepareArgs a = prepareArgsOf(d, largeKey, true);
  if (stagedPrepare(n))
    prepareStagedKernel<<<blocksFor(n, kPrepareBlock), kPrepareBlock, 0, s>>>(a);  // a fixed block
  else
    prepareDirectKernel<<<blocksFor(n, block), block, 0, s>>>(a);
  GEM_CUDA_CHECK_LAUNCH();
}

}  // namespace gem::cuda
