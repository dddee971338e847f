// Phase 2 of a step, the candidate pairs sorted by (a, b): a device strategy's keys sorted, or the
// step's own hashed grid (the built-in uniform_grid): cell ranges, partner rows, large bodies' rows.
#include <cooperative_groups.h>
#include <cub/block/block_reduce.cuh>
#include <cub/block/block_scan.cuh>

#include <cstdlib>

#include "framework/api/cuda_check.hpp"
#include "framework/api/device_broadphase.hpp"
#include "framework/cuda/device_state.cuh"
#include "framework/cuda/step_phases.cuh"
#include "framework/step/phases.hpp"

namespace gem::cuda {
namespace {

// The grid's view, passed by value to the broadphase kernels.
struct GridView {
  const int* world;  // bodies of two worlds (a sweep's batched cases) never pair
  const Box* boxes;
  const Real* invMass;
  const unsigned char* isLarge;
  const int* large;  // slots of the large bodies, ascending
  int largeCount;
  const int* cellStart;
  const int* cellEnd;
  const int* sortedSlot;
  Real cell;
  unsigned mask;  // table size - 1
  int n;
  int capacity;  // of the candidate list: a row that would pass it is not written (overflow)
};

__global__ void cellRangeKernel(const unsigned* key, int n, unsigned largeKey, int* start, int* end) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= n || key[k] == largeKey) return;
  if (k == 0 || key[k - 1] != key[k]) start[key[k]] = k;
  if (k == n - 1 || key[k + 1] != key[k]) end[key[k]] = k + 1;
}

// The narrowphase's prefilter (phases.hpp), within one world: a hash cell may hold another world's bodies.
__device__ inline bool accept(const GridView& g, int i, int j) {
  return g.world[i] == g.world[j] && mayTouch(g.invMass[i], g.invMass[j], g.boxes[i], g.boxes[j]);
}

// A tile of Lanes threads per small body: its lanes test Lanes candidates at a time, so the
// dependent loads of a row are in flight together (a thread per body was latency-bound: 60 us for
// 824 floes on an H200; a warp per body wastes lanes when there are 10^5 bodies to fill the GPU). Write
// pass: each hit goes to its rank among the row's hits (ballot + popc), then lane 0 sorts the row
// by j, so the whole list is sorted by (a, b) as on the CPU.
template <bool Write, int Lanes>
__global__ void partnerRowsKernel(GridView g, int* count, const int* offset, int* candA, int* candB) {
  namespace cg = cooperative_groups;
  const auto tile = cg::tiled_partition<Lanes>(cg::this_thread_block());
  const int i = (blockIdx.x * blockDim.x + threadIdx.x) / Lanes, lane = static_cast<int>(tile.thread_rank());
  if (i > g.n) return;  // i is the same for the whole tile: it returns together
  if (i == g.n) {
    if (!Write && lane == 0) count[i] = 0;  // the scan's last element gives the total
    return;
  }
  if (g.isLarge[i]) return;                         // largeRow*Kernel
  if (Write && offset[i + 1] > g.capacity) return;  // overflow: the step is redone with more room
  const int begin = Write ? offset[i] : 0;
  int end = begin;
  auto visit = [&](int j, bool valid) {
    const bool hit = valid && j > i && accept(g, i, j);
    const unsigned mask = tile.ballot(hit);
    if (Write && hit) {
      const int at = end + __popc(mask & ((1u << lane) - 1));
      candA[at] = i;
      candB[at] = j;
    }
    end += __popc(mask);
  };
  const Box box = g.boxes[i];
  const long long cx = cellCoord(box.x0, g.cell), cy = cellCoord(box.y0, g.cell);
  const int world = g.world[i];
  unsigned seen[9];
  int seenCount = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const unsigned h = cellHash(cx + dx, cy + dy, world, g.mask);
      bool repeated = false;
      for (int s = 0; s < seenCount; ++s) repeated = repeated || seen[s] == h;
      if (repeated) continue;
      seen[seenCount++] = h;
      const int start = g.cellStart[h];
      if (start < 0) continue;
      const int stop = g.cellEnd[h];
      for (int q0 = start; q0 < stop; q0 += Lanes) {
        const int q = q0 + lane;
        visit(q < stop ? g.sortedSlot[q] : 0, q < stop);
      }
    }
  for (int l0 = 0; l0 < g.largeCount; l0 += Lanes) {
    const int l = l0 + lane;
    visit(l < g.largeCount ? g.large[l] : 0, l < g.largeCount);
  }
  if (!Write) {
    if (lane == 0) count[i] = end;
    return;
  }
  tile.sync();  // the lanes' writes of the row are visible to lane 0
  if (lane != 0) return;
  for (int k = begin + 1; k < end; ++k) {
    const int v = candB[k];
    int p = k - 1;
    while (p >= begin && candB[p] > v) {
      candB[p + 1] = candB[p];
      --p;
    }
    candB[p + 1] = v;
  }
}

// Lanes per body: a warp while the bodies alone cannot fill the GPU, fewer when they can
// (GEM_CUDA_ROW_LANES = 1, 2, 4, 8, 16 or 32 overrides, for measuring).
static int rowLanes(int n) {
  static const int forced = [] {
    const char* v = std::getenv("GEM_CUDA_ROW_LANES");
    return v ? std::atoi(v) : 0;
  }();
  if (forced == 1 || forced == 2 || forced == 4 || forced == 8 || forced == 16 || forced == 32) return forced;
  return n < 16384 ? 32 : 4;  // measured on an H200: 4 and 8 lanes best at 10^5 floes, 32 at 824
}

template <bool Write>
static void launchRows(int lanes, int blocks, int block, cudaStream_t s, const GridView& g, int* count, const int* offset, int* candA,
                       int* candB) {
  switch (lanes) {
    case 1:
      partnerRowsKernel<Write, 1><<<blocks, block, 0, s>>>(g, count, offset, candA, candB);
      break;
    case 2:
      partnerRowsKernel<Write, 2><<<blocks, block, 0, s>>>(g, count, offset, candA, candB);
      break;
    case 4:
      partnerRowsKernel<Write, 4><<<blocks, block, 0, s>>>(g, count, offset, candA, candB);
      break;
    case 8:
      partnerRowsKernel<Write, 8><<<blocks, block, 0, s>>>(g, count, offset, candA, candB);
      break;
    case 16:
      partnerRowsKernel<Write, 16><<<blocks, block, 0, s>>>(g, count, offset, candA, candB);
      break;
    default:
      partnerRowsKernel<Write, 32><<<blocks, block, 0, s>>>(g, count, offset, candA, candB);
      break;
  }
  GEM_CUDA_CHECK_LAUNCH();
}

// A large body's row (every j > l whose box its box overlaps: walls and the vessel) is split into
// chunks of kLargeChunk bodies, a block each, so that the rows of a few large bodies still fill the
// GPU (a block per large body left all but five multiprocessors idle: 1.8 ms of a 10^6-floe step).
// Count per chunk, a scan per row over its chunks, then each chunk writes its hits in order.
// (kLargeChunk and largeChunks are in step_phases.cuh: sizeForBodies sizes the chunks' counts.)

// grid (chunks, largeCount): hits of large body large[blockIdx.y] in chunk blockIdx.x.
__global__ void largeChunkCountKernel(GridView g, int chunks, int* chunkCount) {
  using Reduce = cub::BlockReduce<int, kLargeChunk>;
  __shared__ typename Reduce::TempStorage temp;
  const int l = g.large[blockIdx.y], j = blockIdx.x * kLargeChunk + threadIdx.x;
  const int hit = j > l && j < g.n && accept(g, l, j) ? 1 : 0;
  const int total = Reduce(temp).Sum(hit);
  if (threadIdx.x == 0) chunkCount[blockIdx.y * chunks + blockIdx.x] = total;
}

// One block per large body: its chunks' counts become their offsets in the row, and the row's total
// its partner count.
__global__ void largeRowTotalKernel(GridView g, int chunks, int* chunkCount, int* count) {
  using Scan = cub::BlockScan<int, kLargeChunk>;
  __shared__ typename Scan::TempStorage temp;
  int* row = chunkCount + blockIdx.x * chunks;
  int base = 0;
  for (int start = 0; start < chunks; start += kLargeChunk) {
    const int k = start + threadIdx.x;
    const int c = k < chunks ? row[k] : 0;
    int position = 0, total = 0;
    Scan(temp).ExclusiveSum(c, position, total);
    if (k < chunks) row[k] = base + position;
    base += total;
    __syncthreads();  // temp is reused by the next round's scan
  }
  if (threadIdx.x == 0) count[g.large[blockIdx.x]] = base;
}

__global__ void largeChunkWriteKernel(GridView g, int chunks, const int* chunkOffset, const int* offset, int* candA, int* candB) {
  using Scan = cub::BlockScan<int, kLargeChunk>;
  __shared__ typename Scan::TempStorage temp;
  const int l = g.large[blockIdx.y], j = blockIdx.x * kLargeChunk + threadIdx.x;
  if (offset[l + 1] > g.capacity) return;  // overflow: the step is redone with more room
  const int hit = j > l && j < g.n && accept(g, l, j) ? 1 : 0;
  int position = 0;
  Scan(temp).ExclusiveSum(hit, position);
  const int at = offset[l] + chunkOffset[blockIdx.y * chunks + blockIdx.x] + position;
  if (hit) candA[at] = l, candB[at] = j;
}

// A device broadphase's pairs (device_broadphase.hpp) come as keys in any order. The sort has a
// fixed length (captured in the graph), so the entries past this step's count get a key larger
// than any pair's and sort last.
__global__ void padCandidateKeysKernel(int capacity, const int* count, unsigned long long* keys, unsigned long long padKey) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k < capacity && k >= *count) keys[k] = padKey;
}

// Sorted keys back to (a, b), the grid's layout, in the CPU's order.
__global__ void unpackCandidatesKernel(int capacity, const int* count, const unsigned long long* sorted, int slotBits, int* candA,
                                       int* candB) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= capacity || k >= *count) return;
  const unsigned long long key = sorted[k];
  candA[k] = static_cast<int>(key >> slotBits);
  candB[k] = static_cast<int>(key & ((1ull << slotBits) - 1));
}

}  // namespace

const int* enqueueBroadphase(DeviceState& d, CubCalls& cubCalls, unsigned largeKey) {
  cudaStream_t s = d.stream;
  const int n = d.n, capacity = d.capacity, block = d.block;
  // 2. Broadphase. A device strategy (device_broadphase.hpp) emits keys in any order; they are
  // sorted by (a, b) here, so the pairs come in the CPU's order whatever found them.
  const int* candidatesNeeded = d.partnerOffset.get() + n;
  if (d.broadphase) {
    int* count = d.candCount.get();
    GEM_CUDA_CHECK(cudaMemsetAsync(count, 0, sizeof(int), s));
    const BroadphaseBodies bodies{n,
                                  d.x.get(),
                                  d.y.get(),
                                  d.angle.get(),
                                  d.radius.get(),
                                  d.boxes.get(),
                                  d.invMass.get(),
                                  d.kind.get(),
                                  d.worldVertices.get(),
                                  d.vertexCount.get()};
    d.broadphase->enqueue(bodies, CandidateSink{d.candKey.get(), capacity, count, d.slotBits}, s);
    padCandidateKeysKernel<<<blocksFor(capacity), kBlock, 0, s>>>(capacity, count, d.candKey.get(), (1ull << (2 * d.slotBits)) - 1);
    GEM_CUDA_CHECK_LAUNCH();
    cubCalls.sortCandidates(capacity, 2 * d.slotBits);
    unpackCandidatesKernel<<<blocksFor(capacity), kBlock, 0, s>>>(capacity, count, d.candKeySorted.get(), d.slotBits, d.candA.get(),
                                                                  d.candB.get());
    GEM_CUDA_CHECK_LAUNCH();
    candidatesNeeded = count;
  } else {
    // The built-in grid, uniform_grid: sort by cell, cell ranges, count, scan, write (rows sorted:
    // pairs by (a, b), no sort of the pairs).
    cubCalls.cellSort(n, bitsFor(largeKey));
    GEM_CUDA_CHECK(cudaMemsetAsync(d.cellStart.get(), 0xff, d.tableSize * sizeof(int), s));
    cellRangeKernel<<<blocksFor(n, block), block, 0, s>>>(d.cellKeySorted.get(), n, largeKey, d.cellStart.get(), d.cellEnd.get());
    GEM_CUDA_CHECK_LAUNCH();
    const GridView g{d.world.get(),     d.boxes.get(),   d.invMass.get(),    d.isLarge.get(), d.large.get(),   d.largeCount,
                     d.cellStart.get(), d.cellEnd.get(), d.slotSorted.get(), d.cell,          d.tableSize - 1, n,
                     capacity};
    const int lanes = rowLanes(n);
    const int rowBlocks = (lanes * (n + 1) + block - 1) / block;  // a tile per body, one more for count[n]
    launchRows<false>(lanes, rowBlocks, block, s, g, d.partnerCount.get(), nullptr, nullptr, nullptr);
    const int chunks = largeChunks(n);
    const dim3 largeGrid(static_cast<unsigned>(chunks), static_cast<unsigned>(d.largeCount));
    if (d.largeCount > 0) {
      largeChunkCountKernel<<<largeGrid, kLargeChunk, 0, s>>>(g, chunks, d.largeChunk.get());
      GEM_CUDA_CHECK_LAUNCH();
      largeRowTotalKernel<<<d.largeCount, kLargeChunk, 0, s>>>(g, chunks, d.largeChunk.get(), d.partnerCount.get());
      GEM_CUDA_CHECK_LAUNCH();
    }
    cubCalls.scanPartners(n);
    launchRows<true>(lanes, rowBlocks, block, s, g, nullptr, d.partnerOffset.get(), d.candA.get(), d.candB.get());
    if (d.largeCount > 0) {
      largeChunkWriteKernel<<<largeGrid, kLargeChunk, 0, s>>>(g, chunks, d.largeChunk.get(), d.partnerOffset.get(), d.candA.get(),
                                                              d.candB.get());
      GEM_CUDA_CHECK_LAUNCH();
    }
  }
  return candidatesNeeded;
}

}  // namespace gem::cuda
