// The device phases of a step (see cuda_simulation.hpp for the list). The rules every driver applies
// (the prefilter, degrees of freedom, what an impulse does to a body, the time of a step) come from
// framework/step/phases.hpp, the same functions the CPU stepper calls; what is written here is how
// the device runs them in parallel while keeping the CPU's order of every sum (tests: golden hashes,
// CUDA vs CPU).
#include "framework/cuda/device_world.hpp"

#include <cooperative_groups.h>
#include <cub/block/block_reduce.cuh>
#include <cub/block/block_scan.cuh>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <tuple>
#include <cstddef>
#include <cstdlib>
#include <iterator>
#include <stdexcept>
#include <string>

#include "framework/api/cuda_check.hpp"
#include "framework/step/phases.hpp"
#include "geometry/contact.hpp"

namespace gem::cuda {

// Counts the reallocations of every DeviceBuffer: a captured graph holds the buffers' addresses,
// so a change of this count means the graph must be captured again.
static std::atomic<unsigned long> g_reallocations{0};

// A device array that only grows (steps reuse it; no allocation in the steady state).
template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  ~DeviceBuffer() {
    if (m_data) cudaFree(m_data);  // no throw from a destructor
  }
  void ensure(size_t n) {
    if (n <= m_capacity) return;
    const size_t capacity = std::max<size_t>(n + n / 2, 64);
    T* data = nullptr;
    GEM_CUDA_CHECK(cudaMalloc(&data, capacity * sizeof(T)));
    if (m_data) GEM_CUDA_CHECK(cudaFree(m_data));
    m_data = data;
    m_capacity = capacity;
    ++g_reallocations;
  }
  // Grows keeping the first `keep` elements (the previous step's contact keys survive a regrowth).
  void ensureKeeping(size_t n, size_t keep) {
    if (n <= m_capacity) return;
    DeviceBuffer bigger;
    bigger.ensure(n);
    if (keep && m_data) GEM_CUDA_CHECK(cudaMemcpy(bigger.m_data, m_data, keep * sizeof(T), cudaMemcpyDeviceToDevice));
    swap(bigger);
  }
  T* get() const { return m_data; }
  void upload(const T* h_data, size_t n) {
    ensure(n);
    if (n) GEM_CUDA_CHECK(cudaMemcpy(m_data, h_data, n * sizeof(T), cudaMemcpyHostToDevice));
  }
  // Rows [offset, offset + n) from the host; the buffer already holds them.
  void uploadAt(size_t offset, const T* h_data, size_t n) {
    if (n) GEM_CUDA_CHECK(cudaMemcpy(m_data + offset, h_data, n * sizeof(T), cudaMemcpyHostToDevice));
  }
  void download(T* h_data, size_t n) const {
    if (n) GEM_CUDA_CHECK(cudaMemcpy(h_data, m_data, n * sizeof(T), cudaMemcpyDeviceToHost));
  }
  void swap(DeviceBuffer& other) {
    std::swap(m_data, other.m_data);
    std::swap(m_capacity, other.m_capacity);
  }

 private:
  T* m_data = nullptr;
  size_t m_capacity = 0;
};

// Scratch for the re-sort and the topology edits, outside the DeviceBuffers: growing it must not
// look like a change of the graph's buffers. It grows with room to spare: a break adds a body or
// two, and a cudaFree on each would wait for the whole device (every other simulation's stream).
struct ReorderScratch {
  void* data = nullptr;
  size_t bytes = 0;
  ReorderScratch() = default;
  ReorderScratch(const ReorderScratch&) = delete;
  ReorderScratch& operator=(const ReorderScratch&) = delete;
  ~ReorderScratch() {
    if (data) cudaFree(data);
  }
  void* get(size_t need) {
    if (need > bytes) {
      if (data) GEM_CUDA_CHECK(cudaFree(data));
      data = nullptr;
      const size_t capacity = need + need / 2 + 4096;
      GEM_CUDA_CHECK(cudaMalloc(&data, capacity));
      bytes = capacity;
    }
    return data;
  }
};

// What the host sets before each launch of the step graph (pinned; the graph's first node copies it).
struct BatchControl {
  long firstStep;  // index of the batch's first step
  Real dt;
  int steps;       // steps to run, at most the ring's length
};

// Why the batch's loop stopped (StepStats::halt).
enum : int { kRunning = 0, kHaltDone = 1, kHaltBreak = 2, kHaltOverflow = 3 };

// The batch's counters, on the device (kernels read and write them), copied to pinned host memory
// at the end of the batch: the one host sync of a batch of steps.
struct StepStats {
  int impactCount, breakCount, logCount;  // RecordSink's counters, over the whole batch
  int impactBegin, breakBegin, logBegin;  // at the start of the step: a step that fails rewinds to them
  int candidatesNeeded;         // the broadphase's pair count, even past the capacity
  int candidates;               // min(needed, capacity)
  int contacts, previousContacts;
  int overflow;                 // 1: candidates or records past their capacity: the step left the state alone
  int stepsDone, halt;          // completed steps of the batch, and why it stopped
};

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

struct DeviceState {
  // World (structure of arrays, as World).
  DeviceBuffer<std::int64_t> id;
  DeviceBuffer<BodyKind> kind;
  DeviceBuffer<int> vertexCount, dof;
  DeviceBuffer<Vec2> local;
  DeviceBuffer<Real> x, y, angle, vx, vy, omega, area, thickness, mass, invMass, invInertia, gyration2, gyrationX2,
      gyrationY2, principalAngle;
  DeviceBuffer<Real> radius;  // bounding radius: what a device broadphase tests (MODEL.md 9)
  DeviceBuffer<unsigned char> isLarge;
  DeviceBuffer<int> large;
  std::vector<int> largeHost;  // the same slots, ascending: a topology edit shifts them on the host
  int largeCount = 0;
  int n = 0;
  // Worlds (DeviceWorld::upload): each body's, and each world's vessel slot (-1: none), on the host
  // and on the device (a re-sort moves them without a new graph).
  int worlds = 1;
  DeviceBuffer<int> world;
  std::vector<int> worldHost;
  std::vector<int> vesselHost{-1};
  DeviceBuffer<int> vessel;
  DeviceBuffer<WorldStepRecord> worldStats;  // this step's, per world
  Real cell = 1;
  unsigned tableSize = 64;
  int tableBits = 6;
  // Per step, per body.
  DeviceBuffer<Vec2> worldVertices;
  DeviceBuffer<Box> boxes;
  DeviceBuffer<PairBody> pairBodies;
  DeviceBuffer<SoloBody> soloBodies;
  DeviceBuffer<VelocityChange> changes;
  DeviceBuffer<MotionBody> motionBodies;
  // Grid.
  DeviceBuffer<unsigned> cellKey, cellKeySorted;
  DeviceBuffer<int> slot, slotSorted, cellStart, cellEnd;
  DeviceBuffer<int> partnerCount, partnerOffset;
  DeviceBuffer<int> largeChunk;  // per large body and chunk of bodies: its hits, then their offset in the row
  // A device broadphase (nullptr: the grid above): its pairs as keys, sorted into candA/candB.
  std::unique_ptr<CudaBroadphase> broadphase;
  DeviceBuffer<unsigned long long> candKey, candKeySorted;
  DeviceBuffer<int> candCount;
  int slotBits = 1;
  // Candidates and contacts.
  DeviceBuffer<int> candA, candB, flag, flagOffset;
  DeviceBuffer<Contact> candContact;
  DeviceBuffer<int> contactA, contactB, bKey, bKeySorted, bIndex, bIndexSorted;
  DeviceBuffer<PairContact> contacts;
  DeviceBuffer<PairSlot> slots;
  DeviceBuffer<unsigned long long> contactKey, previousKeys, sortedKeys;
  int idBits = 0;  // a contact's id pair is keyed (lo << idBits) | hi: a short radix sort
  // Records, over a batch of steps.
  DeviceBuffer<ImpactRecord> impacts;
  DeviceBuffer<BreakRequest> breaks;
  DeviceBuffer<LogRecord> logs;
  int recordCapacity = 0;  // of each record buffer (grows when a single step needs more)
  DeviceBuffer<StepStats> stats;
  DeviceBuffer<StepContext> ctx;  // written on the device at the start of each step
  DeviceBuffer<BatchControl> control;
  DeviceBuffer<StepRecord> ring;  // one record per step of the batch
  DeviceBuffer<WorldStepRecord> worldRing;  // ringSize x worlds
  int ringSize = 16;              // simulation.copy_back_every
  int block = kBlock;             // simulation.cuda_block_size
  StepStats* h_stats = nullptr;       // pinned
  BatchControl* h_control = nullptr;  // pinned: the graph's first node copies it to control
  StepRecord* h_ring = nullptr;       // pinned, ringSize records
  WorldStepRecord* h_worldRing = nullptr;  // pinned, ringSize x worlds records
  DeviceBuffer<unsigned char> temp;  // CUB scratch, sized before capture
  // Topology edits and the rows they fetch: kept here, because a cudaFree waits for the whole
  // device, every other simulation's stream included (a sweep runs many at once).
  DeviceBuffer<int> editRemoved, editOrder, fetchSlots;
  DeviceBuffer<Real> fetchRows;
  DeviceBuffer<unsigned long long> resortBounds;  // the re-sort along the curve's, likewise
  DeviceBuffer<unsigned long long> resortKeys, resortKeysSorted;
  DeviceBuffer<int> resortSlots, resortSlotsSorted;
  ReorderScratch permuteScratch, sortScratch;
  size_t tempBytes = 0;
  int capacity = 0;  // candidate (and contact) capacity the graph was captured for
  cudaStream_t stream = nullptr;
  cudaGraphExec_t graph = nullptr;
  long captures = 0;           // step graphs captured and instantiated (GEM_CUDA_TIMING)
  double captureSeconds = 0;
  std::vector<std::unique_ptr<CudaEventDriver>> pairEvents, soloEvents, motionEvents;

  DeviceState() {
    GEM_CUDA_CHECK(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking));
    GEM_CUDA_CHECK(cudaMallocHost(&h_stats, sizeof(StepStats)));
    GEM_CUDA_CHECK(cudaMallocHost(&h_control, sizeof(BatchControl)));
    *h_stats = StepStats{};  // pinned memory starts undefined; previousContacts is read before a first step
    stats.ensure(1);
    ctx.ensure(1);
    control.ensure(1);
    setRing(ringSize, worlds);
    GEM_CUDA_CHECK(cudaMemset(stats.get(), 0, sizeof(StepStats)));
  }
  ~DeviceState() {
    if (graph) cudaGraphExecDestroy(graph);
    if (h_stats) cudaFreeHost(h_stats);
    if (h_control) cudaFreeHost(h_control);
    if (h_ring) cudaFreeHost(h_ring);
    if (h_worldRing) cudaFreeHost(h_worldRing);
    if (stream) cudaStreamDestroy(stream);
  }
  void setRing(int size, int worldCount) {
    if (h_ring) GEM_CUDA_CHECK(cudaFreeHost(h_ring));
    if (h_worldRing) GEM_CUDA_CHECK(cudaFreeHost(h_worldRing));
    h_ring = nullptr, h_worldRing = nullptr;
    ringSize = size;
    const size_t worldRecords = static_cast<size_t>(size) * static_cast<size_t>(worldCount);
    GEM_CUDA_CHECK(cudaMallocHost(&h_ring, sizeof(StepRecord) * static_cast<size_t>(size)));
    GEM_CUDA_CHECK(cudaMallocHost(&h_worldRing, sizeof(WorldStepRecord) * worldRecords));
    ring.ensure(static_cast<size_t>(size));
    worldRing.ensure(worldRecords);
    worldStats.ensure(static_cast<size_t>(worldCount));
    dropGraph();
  }
  // The step graph no longer matches the state (n, a buffer, the ring changed): the next batch
  // captures it anew. (Updating the executable graph in place, cudaGraphExecUpdate, was tried:
  // on the batched load study it saved 0.12 s of 4 s; instantiating is not where the time goes.)
  void dropGraph() {
    if (graph) GEM_CUDA_CHECK(cudaGraphExecDestroy(graph));
    graph = nullptr;
  }
};

// ---- kernels ---------------------------------------------------------------------------------

__device__ inline long long cellCoord(Real v, Real cell) { return static_cast<long long>(floor(v / cell)); }

// A cell of one world: the worlds of a batch share the table (world 0 hashes as a lone run did).
__device__ inline unsigned cellHash(long long cx, long long cy, int world, unsigned mask) {
  return (static_cast<unsigned>(cx) * 73856093u ^ static_cast<unsigned>(cy) * 19349663u ^ static_cast<unsigned>(world) * 83492791u) & mask;
}

struct PrepareArgs {
  int n;
  const std::int64_t* id;
  const BodyKind* kind;
  const int *vertexCount, *dof;
  const Vec2* local;
  const Real *x, *y, *angle, *vx, *vy, *omega, *area, *thickness, *mass, *invMass, *invInertia, *gyration2, *gyrationX2,
      *gyrationY2, *principalAngle;
  const unsigned char* isLarge;
  const int* world;
  Real cell;
  unsigned mask, largeKey;
  Vec2* worldVertices;
  Box* boxes;
  PairBody* pairBodies;
  SoloBody* soloBodies;
  VelocityChange* changes;
  unsigned* cellKey;
  int* slot;
};

// Phase 1 and the views: as Simulation::narrowphase's box loop and Simulation::step's view loops.
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
  if (i >= a.n) return;
  Vec2* v = a.worldVertices + static_cast<size_t>(i) * kMaxVertices;
  const int count = a.vertexCount[i];
  toWorld(a.local + static_cast<size_t>(i) * kMaxVertices, count, Vec2{a.x[i], a.y[i]}, a.angle[i], v);
  const Box box = boundingBox(v, count);
  a.boxes[i] = box;
  const PairBody b = pairBodyOf(a, i, a.dof[i], v, count);
  a.pairBodies[i] = b;
  a.soloBodies[i] = SoloBody{b.kind, b.dof, b.position, b.angle, b.velocity, b.omega, b.mass, b.area, b.thickness};
  a.changes[i] = VelocityChange{{0, 0}, 0};
  // A small body lives in the cell of its box's lower-left corner; large ones stay out of the grid.
  a.cellKey[i] = a.isLarge[i] ? a.largeKey : cellHash(cellCoord(box.x0, a.cell), cellCoord(box.y0, a.cell), a.world[i], a.mask);
  a.slot[i] = i;
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
  if (g.isLarge[i]) return;  // largeRow*Kernel
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
static void launchRows(int lanes, int blocks, int block, cudaStream_t s, const GridView& g, int* count, const int* offset, int* candA, int* candB) {
  switch (lanes) {
    case 1: partnerRowsKernel<Write, 1><<<blocks, block, 0, s>>>(g, count, offset, candA, candB); break;
    case 2: partnerRowsKernel<Write, 2><<<blocks, block, 0, s>>>(g, count, offset, candA, candB); break;
    case 4: partnerRowsKernel<Write, 4><<<blocks, block, 0, s>>>(g, count, offset, candA, candB); break;
    case 8: partnerRowsKernel<Write, 8><<<blocks, block, 0, s>>>(g, count, offset, candA, candB); break;
    case 16: partnerRowsKernel<Write, 16><<<blocks, block, 0, s>>>(g, count, offset, candA, candB); break;
    default: partnerRowsKernel<Write, 32><<<blocks, block, 0, s>>>(g, count, offset, candA, candB); break;
  }
  GEM_CUDA_CHECK_LAUNCH();
}

// A large body's row (every j > l whose box its box overlaps: walls and the vessel) is split into
// chunks of kLargeChunk bodies, a block each, so that the rows of a few large bodies still fill the
// GPU (a block per large body left all but five multiprocessors idle: 1.8 ms of a 10^6-floe step).
// Count per chunk, a scan per row over its chunks, then each chunk writes its hits in order.
constexpr int kLargeChunk = 256;
static int largeChunks(int n) { return (n + kLargeChunk - 1) / kLargeChunk; }

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

// Over the capacity + 1 entries: candidates past this step's count get flag 0, so the scan of a
// fixed length (captured in the graph) counts exactly this step's contacts.
__global__ void narrowphaseKernel(int capacity, const int* needed, const int* candA, const int* candB, const Vec2* worldVertices,
                                  const int* vertexCount, const Real* x, const Real* y, const Box* boxes, const Real* invMass,
                                  const int* world, Contact* out, int* flag, StepStats* stats) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p > capacity) return;
  const int total = *needed, count = total < capacity ? total : capacity;
  if (p == 0) {
    stats->candidatesNeeded = total;
    stats->candidates = count;
    stats->overflow = total > capacity ? 1 : 0;
  }
  // A step whose candidates passed the capacity is redone with more room, and its candidate list
  // may hold entries no one wrote (a strategy that ran out of its own room, grid rows that did not
  // fit): it tests nothing. (Reading them once read far out of bounds, when the memory had held
  // another run's data.)
  if (p >= count || total > capacity) {
    flag[p] = 0;
    return;
  }
  const int a = candA[p], b = candB[p];
  // The prefilter (phases.hpp): a device broadphase may propose more than the grid's accept() lets
  // through; dropping the same pairs here keeps the contacts bit-identical. Bodies of two worlds
  // never touch (a device strategy does not know the worlds).
  if (world[a] != world[b] || !mayTouch(invMass[a], invMass[b], boxes[a], boxes[b])) {
    flag[p] = 0;
    return;
  }
  const Contact c = computeContact(worldVertices + static_cast<size_t>(a) * kMaxVertices, vertexCount[a], Vec2{x[a], y[a]},
                                   worldVertices + static_cast<size_t>(b) * kMaxVertices, vertexCount[b], Vec2{x[b], y[b]});
  out[p] = c;
  flag[p] = c.touching ? 1 : 0;
}

__device__ inline unsigned long long contactIdKey(std::int64_t ia, std::int64_t ib, int bits) {
  const std::int64_t lo = ia < ib ? ia : ib, hi = ia < ib ? ib : ia;
  return (static_cast<unsigned long long>(lo) << bits) | static_cast<unsigned long long>(hi);
}

__device__ inline bool sortedContains(const unsigned long long* keys, int n, unsigned long long key) {
  int lo = 0, hi = n;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (keys[mid] < key) lo = mid + 1;
    else hi = mid;
  }
  return lo < n && keys[lo] == key;
}

struct CompactArgs {
  int capacity, n, idBits;
  unsigned long long padKey;  // larger than any real key: padding sorts to the end
  const int *candA, *candB;
  const Contact* cand;
  const int *flag, *offset;
  const std::int64_t* id;
  const int* world;
  WorldStepRecord* worldStats;
  const unsigned long long* previous;
  int *contactA, *contactB;
  PairContact* contacts;
  PairSlot* slots;
  unsigned long long* keys;
  int *bKey, *bIndex;
  StepStats* stats;
};

// Compaction in order, onset against the previous step's sorted id pairs. The entries past this
// step's contacts are padded (slot n, the largest key) so the fixed-length sorts keep them last.
__global__ void compactContactsKernel(CompactArgs a) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= a.capacity) return;
  const int contacts = a.offset[a.capacity];
  if (p == 0) a.stats->contacts = contacts;
  if (!a.flag[p]) {
    const int k = contacts + (p - a.offset[p]);  // the non-contacts fill [contacts, capacity) once each
    a.contactA[k] = a.n;
    a.contactB[k] = a.n;
    a.keys[k] = a.padKey;
    a.bKey[k] = a.n;
    a.bIndex[k] = k;
    return;
  }
  const int k = a.offset[p], ia = a.candA[p], ib = a.candB[p];
  const unsigned long long key = contactIdKey(a.id[ia], a.id[ib], a.idBits);
  atomicAdd(&a.worldStats[a.world[ia]].contacts, 1);  // an integer count: the order does not matter
  a.contactA[k] = ia;
  a.contactB[k] = ib;
  a.contacts[k] = PairContact{a.cand[p], !sortedContains(a.previous, a.stats->previousContacts, key)};
  a.slots[k] = PairSlot{{0, 0}};
  a.keys[k] = key;
  a.bKey[k] = ib;
  a.bIndex[k] = k;
}

// This step's sorted id pairs become the next step's "previous" (not when the step overflowed).
// Run at the end of the step, once nothing can overflow any more.
__global__ void commitContactsKernel(int capacity, const unsigned long long* sorted, unsigned long long* previous, StepStats* stats) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= capacity || stats->overflow) return;
  const int contacts = stats->contacts;
  if (k < contacts) previous[k] = sorted[k];
  if (k == 0) stats->previousContacts = contacts;
}

// After ids outgrew the key's field width: re-key the kept pairs (the order is unchanged).
__global__ void rekeyKernel(unsigned long long* keys, const StepStats* stats, int oldBits, int newBits) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= stats->previousContacts) return;
  const unsigned long long key = keys[k], hi = key & ((1ull << oldBits) - 1), lo = key >> oldBits;
  keys[k] = (lo << newBits) | hi;
}

__device__ inline int lowerBound(const int* v, int n, int x) {
  int lo = 0, hi = n;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (v[mid] < x) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

// Each body sums its contacts in contact order: the CPU loop visits contact k's a then b, and a
// body's contacts as b (a < i) all come before its contacts as a (sorted by a). No atomics.
// contactA and bKeySorted are sorted with the padding (slot n) last, so searching the whole
// capacity finds only real contacts.
__global__ void gatherKernel(int n, const int* world, const int* vesselSlot, const PairBody* bodies, const VelocityChange* changes,
                             int capacity, const int* contactA, const int* bKeySorted, const int* bIndexSorted,
                             const PairContact* contacts, const PairSlot* slots, MotionBody* motion, WorldStepRecord* worldStats) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const int vessel = vesselSlot[world[i]];
  const PairBody& b = bodies[i];
  VelocityChange total = changes[i];
  Vec2 vesselImpulse{0, 0};
  for (int q = lowerBound(bKeySorted, capacity, i); q < capacity && bKeySorted[q] == i; ++q) {
    const int k = bIndexSorted[q];
    const Vec2 j = slots[k].impulse;
    if (j.x == 0 && j.y == 0) continue;
    if (i == vessel) vesselImpulse += j;
    addContactImpulse(b, j, contacts[k].geometry.point, total);
  }
  for (int k = lowerBound(contactA, capacity, i); k < capacity && contactA[k] == i; ++k) {
    const Vec2 j = slots[k].impulse;
    if (j.x == 0 && j.y == 0) continue;
    if (i == vessel) vesselImpulse += -j;
    addContactImpulse(b, -j, contacts[k].geometry.point, total);
  }
  if (i == vessel) worldStats[world[i]].vesselImpulse = vesselImpulse;
  motion[i] = MotionBody{b.kind, b.dof, b.position, b.angle, b.velocity + total.dv, b.omega + total.domega};
}

// The batch's start: its record counters and step count (previousContacts carries over).
__global__ void beginBatchKernel(StepStats* s) {
  s->impactCount = s->breakCount = s->logCount = 0;
  s->stepsDone = 0;
  s->halt = kRunning;
}

// One block for the start and the end of a step: its threads share the worlds' records (a lone
// run has one; a sweep's batch one per case), and no launch is added per step for them.
static unsigned stepEdgeThreads(int worlds) { return static_cast<unsigned>(std::min(std::max(worlds, 32), 1024)); }

// A step's start: its context (the host's formula, time = index x dt), the counters it may rewind
// to, and each world's record emptied.
__global__ void beginStepKernel(const BatchControl* c, StepStats* s, StepContext* ctx, int worlds, WorldStepRecord* worldStats) {
  for (int w = threadIdx.x; w < worlds; w += blockDim.x) worldStats[w] = WorldStepRecord{0, {0, 0}, {0, 0}, {0, 0}, 0};
  if (threadIdx.x != 0) return;
  const long step = c->firstStep + s->stepsDone;
  *ctx = StepContext{c->dt, stepTime(step, c->dt), step};
  s->impactBegin = s->impactCount, s->breakBegin = s->breakCount, s->logBegin = s->logCount;
  s->overflow = 0;
}

// After the pair events: records past a buffer's end fail the step like too many candidates do.
__global__ void checkRecordsKernel(StepStats* s, int capacity) {
  if (s->impactCount > capacity || s->breakCount > capacity || s->logCount > capacity) s->overflow = 1;
}

// A step's end: its record into the ring, and whether the loop goes on. It stops when the batch is
// done, after a step that asked for a break (the host's topology phase comes next), or at a step
// that overflowed (rewound: the host grows the buffers and runs it again).
__global__ void endStepKernel(cudaGraphConditionalHandle loop, bool inGraph, const BatchControl* c, StepStats* s, StepRecord* ring,
                              int worlds, const WorldStepRecord* worldStats, WorldStepRecord* worldRing) {
  // The worlds' records beside the step's, at its place in the ring (read before thread 0 moves on).
  const int done = s->stepsDone;
  if (!s->overflow)
    for (int w = threadIdx.x; w < worlds; w += blockDim.x) worldRing[static_cast<size_t>(done) * worlds + w] = worldStats[w];
  __syncthreads();
  if (threadIdx.x != 0) return;
  if (s->overflow) {
    s->impactCount = s->impactBegin, s->breakCount = s->breakBegin, s->logCount = s->logBegin;
    s->halt = kHaltOverflow;
  } else {
    ring[s->stepsDone] = StepRecord{s->candidates, s->contacts, s->impactCount, s->breakCount, s->logCount};
    ++s->stepsDone;
    if (s->breakCount > s->breakBegin) s->halt = kHaltBreak;
    else if (s->stepsDone >= c->steps) s->halt = kHaltDone;
  }
  if (inGraph) cudaGraphSetConditional(loop, s->halt == kRunning ? 1u : 0u);
}

// The only write of the state; skipped when the step overflowed, so it can simply be run again.
__global__ void writeBackKernel(int n, const int* world, const int* vesselSlot, const MotionBody* motion, Real* x, Real* y, Real* angle,
                                Real* vx, Real* vy, Real* omega, const StepStats* stats, WorldStepRecord* worldStats) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n || stats->overflow) return;
  const MotionBody& b = motion[i];
  x[i] = b.position.x;
  y[i] = b.position.y;
  angle[i] = b.angle;
  vx[i] = b.velocity.x;
  vy[i] = b.velocity.y;
  omega[i] = b.omega;
  if (i == vesselSlot[world[i]]) {
    WorldStepRecord& r = worldStats[world[i]];
    r.vesselPosition = b.position;
    r.vesselVelocity = b.velocity;
    r.vesselAngle = b.angle;
  }
}

static int bitsFor(unsigned long long v) {
  int bits = 1;
  while (bits < 64 && (1ull << bits) <= v) ++bits;
  return bits;
}

// ---- DeviceWorld -------------------------------------------------------------------------------

DeviceWorld::DeviceWorld() : m_state(std::make_unique<DeviceState>()) {}
DeviceWorld::~DeviceWorld() = default;
void DeviceWorld::addPairEvent(std::unique_ptr<CudaEventDriver> driver) { m_state->pairEvents.push_back(std::move(driver)); }
void DeviceWorld::addSoloEvent(std::unique_ptr<CudaEventDriver> driver) { m_state->soloEvents.push_back(std::move(driver)); }
void DeviceWorld::addMotionEvent(std::unique_ptr<CudaEventDriver> driver) { m_state->motionEvents.push_back(std::move(driver)); }
void DeviceWorld::setBroadphase(std::unique_ptr<CudaBroadphase> broadphase) {
  m_state->dropGraph();
  m_state->broadphase = std::move(broadphase);
}
const CudaBroadphase* DeviceWorld::broadphase() const { return m_state->broadphase.get(); }

// What a captured graph baked in: when it is the same after an upload (a re-sort along the curve
// every kResortPeriod steps changes only the arrays' contents) the graph is kept, not captured again.
static auto bakedValues(const DeviceState& d) {
  return std::make_tuple(d.n, d.cell, d.tableSize, d.largeCount, d.idBits, d.capacity, d.worlds, g_reallocations.load());
}


// Everything that follows from n and the ids: the hash table, the key widths, the per-step buffers.
static void sizeForBodies(DeviceState& d, std::int64_t nextId) {
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
    if (d.idBits > 0 && d.capacity > 0) {
      rekeyKernel<<<blocksFor(d.capacity), kBlock, 0, d.stream>>>(d.previousKeys.get(), d.stats.get(), d.idBits, newBits);
      GEM_CUDA_CHECK_LAUNCH();
      GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
    }
    d.idBits = newBits;
  }

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

int DeviceWorld::worlds() const { return m_state->worlds; }
const std::vector<int>& DeviceWorld::worldOfSlots() const { return m_state->worldHost; }

// Each world's vessel slot, to the device.
static void uploadVessels(DeviceState& d) { d.vessel.upload(d.vesselHost.data(), d.vesselHost.size()); }

void DeviceWorld::upload(const World& w, const std::vector<int>& worldOf, const std::vector<int>& vesselSlots,
                         const std::vector<int>& vesselDofs) {
  DeviceState& d = *m_state;
  const int n = w.size(), worlds = static_cast<int>(vesselSlots.size());
  if (worlds < 1 || vesselDofs.size() != vesselSlots.size() || (!worldOf.empty() && worldOf.size() != static_cast<size_t>(n)))
    throw std::invalid_argument("DeviceWorld::upload: one world at least, a vessel and its dof per world, a world per body");
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

  // The grid cell is the largest floe diameter, so a floe's box spans at most one cell; bodies
  // larger than that (walls, the vessel) are "large" and tested against all.
  std::vector<int> dof(n);
  Real largestFloe = 0;
  for (int i = 0; i < n; ++i) {
    dof[i] = degreesOfFreedom(w.kind[i], vesselDofs[static_cast<size_t>(d.worldHost[static_cast<size_t>(i)])]);
    if (w.kind[i] == BodyKind::Floe) largestFloe = std::max(largestFloe, w.radius[i]);
  }
  d.cell = largestFloe > 0 ? 2 * largestFloe : Real(1);
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

namespace {

// A coordinate as an integer of the same order (min and max by integer atomics are then exact, as
// the host's loop): doubles keep every float and coordinate exactly.
__device__ inline unsigned long long orderedBits(Real v) {
  const unsigned long long u = static_cast<unsigned long long>(__double_as_longlong(static_cast<double>(v)));
  return (u >> 63) ? ~u : u | (1ull << 63);
}
__device__ inline Real fromOrderedBits(unsigned long long u) {
  return static_cast<Real>(__longlong_as_double(static_cast<long long>((u >> 63) ? u & ~(1ull << 63) : ~u)));
}

// Per world: the box of its bodies' centroids (min x, min y, max x, max y), as ordered bits.
__global__ void curveBoundsInitKernel(int worlds, unsigned long long* bounds) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k < 4 * worlds) bounds[k] = k % 4 < 2 ? ~0ull : 0ull;
}
__global__ void curveBoundsKernel(int n, const Real* x, const Real* y, const int* world, unsigned long long* bounds) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  unsigned long long* b = bounds + 4 * world[i];
  const unsigned long long bx = orderedBits(x[i]), by = orderedBits(y[i]);
  atomicMin(b + 0, bx), atomicMin(b + 1, by), atomicMax(b + 2, bx), atomicMax(b + 3, by);
}

// Key (world, curve key within the world's box): worlds in order, each along its own curve.
__global__ void curveKeyKernel(int n, const Real* x, const Real* y, const int* world, const unsigned long long* bounds,
                               unsigned long long* key, int* slot) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const unsigned long long* b = bounds + 4 * world[i];
  const Real x0 = fromOrderedBits(b[0]), y0 = fromOrderedBits(b[1]);
  const Real scale = curveScale(x0, y0, fromOrderedBits(b[2]), fromOrderedBits(b[3]));
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
void permuteOnDevice(DeviceBuffer<T>& buffer, int n, int width, const int* order, ReorderScratch& scratch, cudaStream_t s, int from = -1,
                     int room = -1) {
  const size_t rows = static_cast<size_t>(from < 0 ? n : from), count = static_cast<size_t>(n) * width;
  T* copy = static_cast<T*>(scratch.get(std::max<size_t>(rows * width, 1) * sizeof(T)));
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
    if (removed[mid] < slot) lo = mid + 1;
    else hi = mid;
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

std::vector<int> DeviceWorld::reorderAlongCurve(bool* broadphaseFollowed) {
  DeviceState& d = *m_state;
  const int n = d.n;
  *broadphaseFollowed = true;
  std::vector<int> order(static_cast<size_t>(n));
  if (n < 2) {
    for (int i = 0; i < n; ++i) order[static_cast<size_t>(i)] = i;
    return order;
  }
  cudaStream_t s = d.stream;
  ReorderScratch& scratch = d.permuteScratch;
  ReorderScratch& sortScratch = d.sortScratch;
  // Each world's centroid box: exact (min and max round nothing), as the host's loop.
  DeviceBuffer<unsigned long long>& bounds = d.resortBounds;
  bounds.ensure(4 * static_cast<size_t>(d.worlds));
  curveBoundsInitKernel<<<blocksFor(4 * d.worlds), kBlock, 0, s>>>(d.worlds, bounds.get());
  GEM_CUDA_CHECK_LAUNCH();
  curveBoundsKernel<<<blocksFor(n), kBlock, 0, s>>>(n, d.x.get(), d.y.get(), d.world.get(), bounds.get());
  GEM_CUDA_CHECK_LAUNCH();
  // Keys, then a stable radix sort: ties keep slot order, as the host's sort of (key, slot) pairs.
  DeviceBuffer<unsigned long long>& keys = d.resortKeys;
  DeviceBuffer<unsigned long long>& sortedKeys = d.resortKeysSorted;
  DeviceBuffer<int>& slots = d.resortSlots;
  DeviceBuffer<int>& sortedSlots = d.resortSlotsSorted;
  keys.ensure(n), sortedKeys.ensure(n), slots.ensure(n), sortedSlots.ensure(n);
  curveKeyKernel<<<blocksFor(n), kBlock, 0, s>>>(n, d.x.get(), d.y.get(), d.world.get(), bounds.get(), keys.get(), slots.get());
  GEM_CUDA_CHECK_LAUNCH();
  const int keyBits = 32 + (d.worlds > 1 ? bitsFor(static_cast<unsigned long long>(d.worlds - 1)) : 0);
  size_t bytes = 0;
  GEM_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, bytes, keys.get(), sortedKeys.get(), slots.get(), sortedSlots.get(), n, 0, keyBits, s));
  void* temp = sortScratch.get(bytes);
  GEM_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp, bytes, keys.get(), sortedKeys.get(), slots.get(), sortedSlots.get(), n, 0, keyBits, s));
  const int* o = sortedSlots.get();
  permuteOnDevice(d.id, n, 1, o, scratch, s), permuteOnDevice(d.kind, n, 1, o, scratch, s);
  permuteOnDevice(d.world, n, 1, o, scratch, s);
  permuteOnDevice(d.vertexCount, n, 1, o, scratch, s), permuteOnDevice(d.dof, n, 1, o, scratch, s);
  permuteOnDevice(d.local, n, kMaxVertices, o, scratch, s), permuteOnDevice(d.isLarge, n, 1, o, scratch, s);
  for (DeviceBuffer<Real>* r : {&d.x, &d.y, &d.angle, &d.vx, &d.vy, &d.omega, &d.radius, &d.area, &d.thickness, &d.mass, &d.invMass,
                                &d.invInertia, &d.gyration2, &d.gyrationX2, &d.gyrationY2, &d.principalAngle})
    permuteOnDevice(*r, n, 1, o, scratch, s);
  if (d.broadphase) *broadphaseFollowed = d.broadphase->reorder(o, n, s);
  sortedSlots.download(order.data(), static_cast<size_t>(n));

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
  return order;
}

void DeviceWorld::downloadKinematics(const std::vector<int>& deviceSlots, const std::vector<int>& hostSlots, World& w) const {
  DeviceState& d = *m_state;
  const int count = static_cast<int>(deviceSlots.size());
  if (count == 0) return;
  DeviceBuffer<int>& slots = d.fetchSlots;
  DeviceBuffer<Real>& rows = d.fetchRows;
  slots.upload(deviceSlots.data(), deviceSlots.size());
  rows.ensure(6 * deviceSlots.size());
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

bool DeviceWorld::editBodies(const std::vector<int>& removedSlots, const World& from, int firstAdded, const std::vector<int>& addedWorlds,
                             const std::vector<int>& vesselDofs) {
  DeviceState& d = *m_state;
  const int before = d.n, removedCount = static_cast<int>(removedSlots.size());
  const int kept = before - removedCount, added = from.size() - firstAdded, n = kept + added;
  if (kept < 0 || added < 0 || (!addedWorlds.empty() && addedWorlds.size() != static_cast<size_t>(added)) ||
      vesselDofs.size() != static_cast<size_t>(d.worlds))
    throw std::logic_error("DeviceWorld::editBodies: the edit does not match the device's bodies");
  cudaStream_t s = d.stream;
  ReorderScratch& scratch = d.permuteScratch;

  // The kept rows, in their order (a stable compaction), with room for the new ones after them.
  DeviceBuffer<int>& removed = d.editRemoved;
  DeviceBuffer<int>& order = d.editOrder;
  removed.ensure(std::max<size_t>(removedSlots.size(), 1));
  removed.uploadAt(0, removedSlots.data(), removedSlots.size());
  order.ensure(static_cast<size_t>(std::max(kept, 1)));
  keptOrderKernel<<<blocksFor(before), kBlock, 0, s>>>(before, removed.get(), removedCount, order.get());
  GEM_CUDA_CHECK_LAUNCH();
  const int* o = order.get();
  permuteOnDevice(d.id, kept, 1, o, scratch, s, before, n), permuteOnDevice(d.kind, kept, 1, o, scratch, s, before, n);
  permuteOnDevice(d.vertexCount, kept, 1, o, scratch, s, before, n), permuteOnDevice(d.dof, kept, 1, o, scratch, s, before, n);
  permuteOnDevice(d.local, kept, kMaxVertices, o, scratch, s, before, n), permuteOnDevice(d.isLarge, kept, 1, o, scratch, s, before, n);
  permuteOnDevice(d.world, kept, 1, o, scratch, s, before, n);
  DeviceBuffer<Real>* reals[] = {&d.x, &d.y, &d.angle, &d.vx, &d.vy, &d.omega, &d.radius, &d.area, &d.thickness, &d.mass, &d.invMass,
                                 &d.invInertia, &d.gyration2, &d.gyrationX2, &d.gyrationY2, &d.principalAngle};
  for (DeviceBuffer<Real>* r : reals) permuteOnDevice(*r, kept, 1, o, scratch, s, before, n);

  // The new bodies' rows, as World::addBody made them on the host (a few per step): rows
  // from[firstAdded..] go to slots kept...
  const size_t at = static_cast<size_t>(kept), first = static_cast<size_t>(firstAdded), count = static_cast<size_t>(added);
  d.id.uploadAt(at, from.id.data() + first, count);
  d.kind.uploadAt(at, from.kind.data() + first, count);
  d.vertexCount.uploadAt(at, from.vertexCount.data() + first, count);
  d.local.uploadAt(at * kMaxVertices, from.localVertices.data() + first * kMaxVertices, count * kMaxVertices);
  const std::vector<Real>* hostReals[] = {&from.x, &from.y, &from.angle, &from.vx, &from.vy, &from.omega, &from.radius, &from.area,
                                          &from.thickness, &from.mass, &from.invMass, &from.invInertia, &from.gyration2,
                                          &from.gyrationX2, &from.gyrationY2, &from.principalAngle};
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
      throw std::logic_error("DeviceWorld::editBodies: a topology event removed the vessel");
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
  const bool followed = !d.broadphase || d.broadphase->edited(o, kept, from, firstAdded, s);
  d.dropGraph();  // n changed: the graph's launches were sized for the old count
  return followed;
}

void DeviceWorld::uploadBroadphase(const World& w) {
  DeviceState& d = *m_state;
  if (!d.broadphase) return;
  d.broadphase->upload(w);
  d.dropGraph();
}

void DeviceWorld::download(World& w) const {
  const DeviceState& d = *m_state;
  const int n = w.size();
  d.x.download(w.x.data(), n), d.y.download(w.y.data(), n), d.angle.download(w.angle.data(), n);
  d.vx.download(w.vx.data(), n), d.vy.download(w.vy.data(), n), d.omega.download(w.omega.data(), n);
}

namespace {

// The CUB calls of a step, for a fixed n and capacity: run with temp == nullptr they only add up
// the scratch they need (so every buffer exists before the capture), then for real.
struct CubCalls {
  DeviceState& d;
  void* temp;
  size_t& bytes;  // in: available (real run); out: the largest need (sizing run)
  bool sizing;

  // need by reference: read after the CUB call has written it (argument order is unspecified).
  void check(cudaError_t status, const size_t& need, const char* what) {
    ::gem::cuda::check(status, what, __FILE__, __LINE__);
    if (sizing) bytes = std::max(bytes, need);
  }
  void cellSort(int n, int bits) {
    size_t need = sizing ? 0 : bytes;
    check(cub::DeviceRadixSort::SortPairs(temp, need, d.cellKey.get(), d.cellKeySorted.get(), d.slot.get(), d.slotSorted.get(), n, 0,
                                          bits, d.stream),
          need, "cub SortPairs (cells)");
  }
  void scanPartners(int n) {
    size_t need = sizing ? 0 : bytes;
    check(cub::DeviceScan::ExclusiveSum(temp, need, d.partnerCount.get(), d.partnerOffset.get(), n + 1, d.stream), need, "cub ExclusiveSum (partners)");
  }
  void sortCandidates(int capacity, int bits) {
    size_t need = sizing ? 0 : bytes;
    check(cub::DeviceRadixSort::SortKeys(temp, need, d.candKey.get(), d.candKeySorted.get(), capacity, 0, bits, d.stream), need,
          "cub SortKeys (device broadphase pairs)");
  }
  void scanFlags(int capacity) {
    size_t need = sizing ? 0 : bytes;
    check(cub::DeviceScan::ExclusiveSum(temp, need, d.flag.get(), d.flagOffset.get(), capacity + 1, d.stream), need, "cub ExclusiveSum (flags)");
  }
  void sortKeys(int capacity, int bits) {
    size_t need = sizing ? 0 : bytes;
    check(cub::DeviceRadixSort::SortKeys(temp, need, d.contactKey.get(), d.sortedKeys.get(), capacity, 0, bits, d.stream), need, "cub SortKeys (contact ids)");
  }
  void sortB(int capacity, int bits) {
    size_t need = sizing ? 0 : bytes;
    check(cub::DeviceRadixSort::SortPairs(temp, need, d.bKey.get(), d.bKeySorted.get(), d.bIndex.get(), d.bIndexSorted.get(), capacity, 0,
                                          bits, d.stream),
          need, "cub SortPairs (b side)");
  }
};

// Enqueues one whole step on d.stream: captured as the body of the batch graph's loop (inGraph),
// or launched directly when graphs are off (GEM_CUDA_GRAPH=0, for debugging).
void enqueueStep(DeviceState& d, cudaGraphConditionalHandle loop, bool inGraph) {
  cudaStream_t s = d.stream;
  const int n = d.n, capacity = d.capacity, block = d.block;
  const unsigned largeKey = d.tableSize;  // past every cell: large bodies sort to the end
  size_t bytes = d.tempBytes;
  CubCalls cubCalls{d, d.temp.get(), bytes, false};
  StepStats* stats = d.stats.get();

  beginStepKernel<<<1, stepEdgeThreads(d.worlds), 0, s>>>(d.control.get(), stats, d.ctx.get(), d.worlds, d.worldStats.get());
  GEM_CUDA_CHECK_LAUNCH();

  // 1. World vertices, boxes, views, cell keys.
  PrepareArgs a{n, d.id.get(), d.kind.get(), d.vertexCount.get(), d.dof.get(), d.local.get(), d.x.get(), d.y.get(),
                d.angle.get(), d.vx.get(), d.vy.get(), d.omega.get(), d.area.get(), d.thickness.get(), d.mass.get(),
                d.invMass.get(), d.invInertia.get(), d.gyration2.get(), d.gyrationX2.get(), d.gyrationY2.get(),
                d.principalAngle.get(), d.isLarge.get(), d.world.get(), d.cell, d.tableSize - 1, largeKey, d.worldVertices.get(), d.boxes.get(),
                d.pairBodies.get(), d.soloBodies.get(), d.changes.get(), d.cellKey.get(), d.slot.get()};
  if (stagedPrepare(n)) prepareStagedKernel<<<blocksFor(n, kPrepareBlock), kPrepareBlock, 0, s>>>(a);  // a fixed block
  else prepareDirectKernel<<<blocksFor(n, block), block, 0, s>>>(a);
  GEM_CUDA_CHECK_LAUNCH();

  // 2. Broadphase. A device strategy (device_broadphase.hpp) emits keys in any order; they are
  // sorted by (a, b) here, so the pairs come in the CPU's order whatever found them.
  const int* candidatesNeeded = d.partnerOffset.get() + n;
  if (d.broadphase) {
    int* count = d.candCount.get();
    GEM_CUDA_CHECK(cudaMemsetAsync(count, 0, sizeof(int), s));
    const BroadphaseBodies bodies{n, d.x.get(), d.y.get(), d.angle.get(), d.radius.get(), d.boxes.get(), d.invMass.get(),
                                  d.kind.get(), d.worldVertices.get(), d.vertexCount.get()};
    d.broadphase->enqueue(bodies, CandidateSink{d.candKey.get(), capacity, count, d.slotBits}, s);
    padCandidateKeysKernel<<<blocksFor(capacity), kBlock, 0, s>>>(capacity, count, d.candKey.get(), (1ull << (2 * d.slotBits)) - 1);
    GEM_CUDA_CHECK_LAUNCH();
    cubCalls.sortCandidates(capacity, 2 * d.slotBits);
    unpackCandidatesKernel<<<blocksFor(capacity), kBlock, 0, s>>>(capacity, count, d.candKeySorted.get(), d.slotBits, d.candA.get(),
                                                                  d.candB.get());
    GEM_CUDA_CHECK_LAUNCH();
    candidatesNeeded = count;
  } else {
  // The built-in grid, uniform_grid (left at its old indentation to keep the diff small): sort by
  // cell, cell ranges, count, scan, write (rows sorted: pairs by (a, b), no sort of the pairs).
  cubCalls.cellSort(n, bitsFor(largeKey));
  GEM_CUDA_CHECK(cudaMemsetAsync(d.cellStart.get(), 0xff, d.tableSize * sizeof(int), s));
  cellRangeKernel<<<blocksFor(n, block), block, 0, s>>>(d.cellKeySorted.get(), n, largeKey, d.cellStart.get(), d.cellEnd.get());
  GEM_CUDA_CHECK_LAUNCH();
  const GridView g{d.world.get(), d.boxes.get(), d.invMass.get(), d.isLarge.get(), d.large.get(), d.largeCount, d.cellStart.get(),
                   d.cellEnd.get(), d.slotSorted.get(), d.cell, d.tableSize - 1, n, capacity};
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

  // 3. Narrowphase, compaction in order (with padding), onset, the two sorts.
  // computeContact is a long serial chain per pair with a 2.3 KB local-memory frame: while the
  // pairs are few, blocks of one warp spread them over every multiprocessor's L1.
  const int narrowBlock = capacity + 1 < 64 * 1024 ? 32 : block;
  narrowphaseKernel<<<(capacity + narrowBlock) / narrowBlock, narrowBlock, 0, s>>>(capacity, candidatesNeeded, d.candA.get(), d.candB.get(),
                                                                d.worldVertices.get(), d.vertexCount.get(), d.x.get(), d.y.get(),
                                                                d.boxes.get(), d.invMass.get(), d.world.get(), d.candContact.get(), d.flag.get(), stats);
  GEM_CUDA_CHECK_LAUNCH();
  cubCalls.scanFlags(capacity);
  const unsigned long long padKey = d.idBits >= 32 ? ~0ull : (1ull << (2 * d.idBits)) - 1;
  const CompactArgs c{capacity, n, d.idBits, padKey, d.candA.get(), d.candB.get(), d.candContact.get(), d.flag.get(),
                      d.flagOffset.get(), d.id.get(), d.world.get(), d.worldStats.get(), d.previousKeys.get(), d.contactA.get(), d.contactB.get(), d.contacts.get(),
                      d.slots.get(), d.contactKey.get(), d.bKey.get(), d.bIndex.get(), stats};
  compactContactsKernel<<<blocksFor(capacity, block), block, 0, s>>>(c);
  GEM_CUDA_CHECK_LAUNCH();
  cubCalls.sortKeys(capacity, std::min(64, 2 * d.idBits));
  // The b side of every body, in contact order: a stable radix sort of (b, k) by b.
  cubCalls.sortB(capacity, bitsFor(static_cast<unsigned long long>(n)));

  // 4. Two-body events write into each contact's slot; solo events from the start-of-step state.
  const int records = d.recordCapacity;
  const RecordSink sink{d.impacts.get(), records, &stats->impactCount, d.breaks.get(), records, &stats->breakCount,
                        d.logs.get(), records, &stats->logCount};
  const DevicePairData pairData{d.pairBodies.get(), d.world.get(), d.contactA.get(), d.contactB.get(), d.contacts.get(), d.slots.get(),
                                capacity, block, &stats->contacts, d.ctx.get(), sink};
  for (auto& e : d.pairEvents) e->launchPairs(pairData, s);
  checkRecordsKernel<<<1, 1, 0, s>>>(stats, records);
  GEM_CUDA_CHECK_LAUNCH();
  const DeviceSoloData soloData{d.soloBodies.get(), d.world.get(), d.changes.get(), n, block, d.ctx.get()};
  for (auto& e : d.soloEvents) e->launchSolo(soloData, s);

  // 5. Gather, motion, write back; then the counters to the host.
  gatherKernel<<<blocksFor(n, block), block, 0, s>>>(n, d.world.get(), d.vessel.get(), d.pairBodies.get(), d.changes.get(), capacity,
                                                     d.contactA.get(), d.bKeySorted.get(), d.bIndexSorted.get(), d.contacts.get(),
                                                     d.slots.get(), d.motionBodies.get(), d.worldStats.get());
  GEM_CUDA_CHECK_LAUNCH();
  const DeviceMotionData motionData{d.motionBodies.get(), d.world.get(), n, block, d.ctx.get()};
  for (auto& e : d.motionEvents) e->launchMotion(motionData, s);
  writeBackKernel<<<blocksFor(n, block), block, 0, s>>>(n, d.world.get(), d.vessel.get(), d.motionBodies.get(), d.x.get(), d.y.get(),
                                                        d.angle.get(), d.vx.get(), d.vy.get(), d.omega.get(), stats, d.worldStats.get());
  GEM_CUDA_CHECK_LAUNCH();
  commitContactsKernel<<<blocksFor(capacity, block), block, 0, s>>>(capacity, d.sortedKeys.get(), d.previousKeys.get(), stats);
  GEM_CUDA_CHECK_LAUNCH();
  endStepKernel<<<1, stepEdgeThreads(d.worlds), 0, s>>>(loop, inGraph, d.control.get(), stats, d.ring.get(), d.worlds,
                                                       d.worldStats.get(), d.worldRing.get());
  GEM_CUDA_CHECK_LAUNCH();
}

// Sizes every buffer for n and the capacity.
void prepareBuffers(DeviceState& d) {
  const size_t cap = static_cast<size_t>(d.capacity);
  d.candA.ensure(cap), d.candB.ensure(cap), d.candContact.ensure(cap), d.flag.ensure(cap + 1), d.flagOffset.ensure(cap + 1);
  d.contactA.ensure(cap), d.contactB.ensure(cap), d.contacts.ensure(cap), d.slots.ensure(cap), d.contactKey.ensure(cap);
  d.sortedKeys.ensure(cap), d.bKey.ensure(cap), d.bKeySorted.ensure(cap), d.bIndex.ensure(cap), d.bIndexSorted.ensure(cap);
  // Records of a whole batch: a step needs one impact and one break per contact at most, and
  // a batch that fills the buffers stops there (the next batch starts them empty).
  d.recordCapacity = std::max(d.recordCapacity, d.capacity);
  const size_t records = static_cast<size_t>(d.recordCapacity);
  d.impacts.ensure(records), d.breaks.ensure(records), d.logs.ensure(records);
  d.previousKeys.ensureKeeping(cap, static_cast<size_t>(d.h_stats->previousContacts));

  size_t bytes = 1;
  CubCalls sizing{d, nullptr, bytes, true};
  sizing.cellSort(d.n, bitsFor(d.tableSize));
  sizing.scanPartners(d.n);
  sizing.scanFlags(d.capacity);
  sizing.sortKeys(d.capacity, std::min(64, 2 * d.idBits));
  sizing.sortB(d.capacity, bitsFor(static_cast<unsigned long long>(d.n)));
  if (d.broadphase) {
    d.candKey.ensure(cap), d.candKeySorted.ensure(cap), d.candCount.ensure(1);
    d.broadphase->reserve(d.stream);
    sizing.sortCandidates(d.capacity, 2 * d.slotBits);
  }
  d.temp.ensure(bytes);
  d.tempBytes = bytes;
}

// Captures a batch as one graph, replayed every batch until n, a capacity or the ring changes:
//   copy the control in -> reset the batch's counters -> WHILE (a step; its last kernel sets the
//   condition) -> copy the ring and the counters out to pinned memory.
// So a batch of up to copy_back_every steps is one launch and one host sync (thesis 5.7).
void captureStep(DeviceState& d) {
  prepareBuffers(d);
  d.dropGraph();
  // This stream's uploads and memsets finished before the capture: compute-sanitizer otherwise
  // reports reads of "not yet allocated" memory inside a WHILE body (NVIDIA/warp#1406). Only this
  // stream: a device-wide sync would also wait on (and so invalidate) another thread's capture
  // (a sweep runs several simulations on one device).
  GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
  cudaGraph_t graph = nullptr;
  GEM_CUDA_CHECK(cudaGraphCreate(&graph, 0));
  struct Owned {
    cudaGraph_t g;
    ~Owned() { cudaGraphDestroy(g); }
  } owned{graph};
  cudaGraphNode_t controlIn, begin, loop, ringOut, worldRingOut, statsOut;
  GEM_CUDA_CHECK(cudaGraphAddMemcpyNode1D(&controlIn, graph, nullptr, 0, d.control.get(), d.h_control, sizeof(BatchControl),
                                          cudaMemcpyHostToDevice));
  StepStats* stats = d.stats.get();
  void* beginArgs[] = {&stats};
  cudaKernelNodeParams beginParams{};
  beginParams.func = reinterpret_cast<void*>(beginBatchKernel);
  beginParams.gridDim = dim3(1);
  beginParams.blockDim = dim3(1);
  beginParams.kernelParams = beginArgs;
  GEM_CUDA_CHECK(cudaGraphAddKernelNode(&begin, graph, &controlIn, 1, &beginParams));

  cudaGraphConditionalHandle handle;
  GEM_CUDA_CHECK(cudaGraphConditionalHandleCreate(&handle, graph, 1, cudaGraphCondAssignDefault));
  cudaGraphNodeParams loopParams{};
  loopParams.type = cudaGraphNodeTypeConditional;
  loopParams.conditional.handle = handle;
  loopParams.conditional.type = cudaGraphCondTypeWhile;
  loopParams.conditional.size = 1;
  GEM_CUDA_CHECK(cudaGraphAddNode(&loop, graph, &begin, nullptr, 1, &loopParams));
  cudaGraph_t body = loopParams.conditional.phGraph_out[0];
  GEM_CUDA_CHECK(cudaStreamBeginCaptureToGraph(d.stream, body, nullptr, nullptr, 0, cudaStreamCaptureModeThreadLocal));
  try {
    enqueueStep(d, handle, true);
  } catch (...) {
    cudaStreamEndCapture(d.stream, &body);
    throw;
  }
  GEM_CUDA_CHECK(cudaStreamEndCapture(d.stream, &body));

  GEM_CUDA_CHECK(cudaGraphAddMemcpyNode1D(&ringOut, graph, &loop, 1, d.h_ring, d.ring.get(),
                                          sizeof(StepRecord) * static_cast<size_t>(d.ringSize), cudaMemcpyDeviceToHost));
  GEM_CUDA_CHECK(cudaGraphAddMemcpyNode1D(&worldRingOut, graph, &loop, 1, d.h_worldRing, d.worldRing.get(),
                                          sizeof(WorldStepRecord) * static_cast<size_t>(d.ringSize) * static_cast<size_t>(d.worlds),
                                          cudaMemcpyDeviceToHost));
  GEM_CUDA_CHECK(cudaGraphAddMemcpyNode1D(&statsOut, graph, &loop, 1, d.h_stats, stats, sizeof(StepStats), cudaMemcpyDeviceToHost));
  GEM_CUDA_CHECK(cudaGraphInstantiate(&d.graph, graph, 0));
}

// The same batch with every kernel launched from the host, a sync per step (GEM_CUDA_GRAPH=0).
void runBatchUncaptured(DeviceState& d) {
  prepareBuffers(d);
  GEM_CUDA_CHECK(cudaMemcpyAsync(d.control.get(), d.h_control, sizeof(BatchControl), cudaMemcpyHostToDevice, d.stream));
  beginBatchKernel<<<1, 1, 0, d.stream>>>(d.stats.get());
  GEM_CUDA_CHECK_LAUNCH();
  do {
    enqueueStep(d, cudaGraphConditionalHandle{}, false);
    GEM_CUDA_CHECK(cudaMemcpyAsync(d.h_stats, d.stats.get(), sizeof(StepStats), cudaMemcpyDeviceToHost, d.stream));
    GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
  } while (d.h_stats->halt == kRunning);
  GEM_CUDA_CHECK(cudaMemcpyAsync(d.h_ring, d.ring.get(), sizeof(StepRecord) * static_cast<size_t>(d.ringSize), cudaMemcpyDeviceToHost, d.stream));
  GEM_CUDA_CHECK(cudaMemcpyAsync(d.h_worldRing, d.worldRing.get(),
                                 sizeof(WorldStepRecord) * static_cast<size_t>(d.ringSize) * static_cast<size_t>(d.worlds), cudaMemcpyDeviceToHost,
                                 d.stream));
}

}  // namespace

std::pair<long, double> DeviceWorld::captures() const { return {m_state->captures, m_state->captureSeconds}; }

void DeviceWorld::configure(int copyBackEvery, int blockSize) {
  DeviceState& d = *m_state;
  if (copyBackEvery < 1 || blockSize < 32 || blockSize > 1024 || blockSize % 32)
    throw std::invalid_argument("DeviceWorld::configure: copy_back_every >= 1, block size a multiple of 32 up to 1024");
  if (copyBackEvery != d.ringSize) d.setRing(copyBackEvery, d.worlds);
  if (blockSize != d.block) d.dropGraph();
  d.block = blockSize;
}

void DeviceWorld::run(long firstStep, Real dt, int steps, DeviceBatchResult& result) {
  DeviceState& d = *m_state;
  result.steps.clear(), result.worldSteps.clear(), result.impacts.clear(), result.breaks.clear(), result.logs.clear();
  result.worlds = d.worlds;
  if (d.n == 0) {
    result.steps.assign(static_cast<size_t>(steps), StepRecord{});
    result.worldSteps.assign(static_cast<size_t>(steps) * static_cast<size_t>(d.worlds), WorldStepRecord{});
    return;
  }
  static const bool useGraph = [] {
    const char* v = std::getenv("GEM_CUDA_GRAPH");  // 0: launch the kernels one by one (debugging)
    return !(v && v[0] == '0');
  }();
  long next = firstStep;
  int remaining = steps;
  while (remaining > 0) {
    *d.h_control = BatchControl{next, dt, std::min(remaining, d.ringSize)};
    if (!useGraph) {
      runBatchUncaptured(d);
    } else {
      if (!d.graph) {
        const auto start = std::chrono::steady_clock::now();
        captureStep(d);
        ++d.captures;
        d.captureSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
      GEM_CUDA_CHECK(cudaGraphLaunch(d.graph, d.stream));
    }
    GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
    const StepStats stats = *d.h_stats;
    const int done = stats.stepsDone;

    // The completed steps' records, appended; their ends shifted past what earlier batches added.
    const int impactBase = static_cast<int>(result.impacts.size()), breakBase = static_cast<int>(result.breaks.size()),
              logBase = static_cast<int>(result.logs.size());
    const StepRecord last = done > 0 ? d.h_ring[done - 1] : StepRecord{};
    result.impacts.resize(static_cast<size_t>(impactBase + last.impactEnd));
    result.breaks.resize(static_cast<size_t>(breakBase + last.breakEnd));
    result.logs.resize(static_cast<size_t>(logBase + last.logEnd));
    d.impacts.download(result.impacts.data() + impactBase, static_cast<size_t>(last.impactEnd));
    d.breaks.download(result.breaks.data() + breakBase, static_cast<size_t>(last.breakEnd));
    d.logs.download(result.logs.data() + logBase, static_cast<size_t>(last.logEnd));
    for (int k = 0; k < done; ++k) {
      StepRecord r = d.h_ring[k];
      r.impactEnd += impactBase, r.breakEnd += breakBase, r.logEnd += logBase;
      result.steps.push_back(r);
    }
    result.worldSteps.insert(result.worldSteps.end(), d.h_worldRing, d.h_worldRing + static_cast<size_t>(done) * static_cast<size_t>(d.worlds));
    next += done;
    remaining -= done;
    if (stats.halt == kHaltBreak) break;
    if (stats.halt != kHaltOverflow) continue;
    // A step overflowed and left the state alone: grow what it passed, re-capture, run it again.
    if (stats.candidatesNeeded > d.capacity) {
      d.capacity = stats.candidatesNeeded + stats.candidatesNeeded / 2 + 256;
    } else if (done == 0) {
      d.recordCapacity *= 4;  // one step's records alone passed the buffers (a batch that filled them just stops)
    }
    d.dropGraph();
  }
}

}  // namespace gem::cuda
