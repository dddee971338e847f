// The kept neighbour list on the device: the twin of neighbour_list.hpp's NeighbourList, for the
// device parts of variable_radius, fixed_radius and triangulation_mesh. Same list, same skin, same
// never-miss rule (MODEL.md 9; the argument is in neighbour_list.hpp), but every decision is taken
// on the device, inside the step's captured graph, so the host never waits on it:
//   1 check   one thread per body: a listed body that moved or turned by more than half the skin
//             since the build becomes direct (as on the CPU); past kMaxDirect of them, or when the
//             list is stale, a flag in device memory says "rebuild".
//   2 order   the bodies sorted by the low end of their x span (CUB, every step: a graph cannot skip
//             a CUB call, and it is cheap next to the rest).
//   3 build   reference state and sweep and prune along x (PairsWithinReach's rule, neighbour_list.hpp); both
//             kernels return at once when the flag is clear, which is almost every step.
//   4 filter  one thread per listed pair: bounding circles overlap now (R_a + R_b), neither direct.
//   5 direct  one thread per (direct body, body): the vessel, the walls and the floes that moved
//             past half the skin, against every body, as the CPU's direct pass.
// The vessel and the walls are always direct (neighbour_list.hpp says why for the vessel; a wall
// spans the field, so listing its pairs would cost as much as testing them). A strategy adds its own
// test on top of the circles through the Accept functor (triangulation_mesh's triangles).
#pragma once
#include <vector>

#include "broadphase/kept_list/neighbour_list.hpp"
#include "framework/api/cuda_events.hpp"  // kBlock, blocksFor
#include "framework/api/device_broadphase.hpp"

namespace gem::cuda {

// The list's state on the device, one record.
struct ListControl {
  int rebuild;      // this step rebuilds: set by the check, read by the build
  int valid;        // 0: never built, or stale (upload, reallocation, overflow)
  int count;        // pairs the last build listed, past the capacity too
  int directCount;  // direct bodies now, past the room too
  long long rebuilds;
};

// What the kernels see: device pointers fixed between upload() and reserve(), passed by value.
struct ListView {
  ListControl* control;
  const Real* half;                   // list reach per body: R + skin / 2
  Real floor;                         // a pair within this is listed whatever its reach (fixed_radius)
  Real limit;                         // a listed body moved past this becomes direct (half the skin)
  const unsigned char* alwaysDirect;  // vessel, walls
  unsigned char* direct;
  int* directList;  // the always-direct bodies first, then those that moved
  int directRoom, alwaysDirectCount;
  Real *x0, *y0, *angle0;  // reference state at the build
  ListedPair* pairs;
  int capacity;
  Real *lo, *loSorted;
  int *slot, *slotSorted;
};

// side: a stream of the list's own, on which a captured step's build is captured into an IF node.
void enqueueListBuild(const ListView& list, const BroadphaseBodies& bodies, void* temp, size_t tempBytes, cudaStream_t stream,
                      cudaStream_t side);

#if defined(__CUDACC__)
template <class Accept>
__global__ void listFilterKernel(ListView list, BroadphaseBodies b, CandidateSink sink, Accept accept) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= list.capacity) return;
  const int count = list.control->count;
  if (p == 0 && count > list.capacity) {  // the build ran out of room: grow (reserve) and redo
    list.control->valid = 0;
    sink.redo();
  }
  if (p >= count) return;
  const ListedPair q = list.pairs[p];
  if (list.direct[q.a] || list.direct[q.b]) return;  // the direct pass finds it
  const Real dx = b.x[q.a] - b.x[q.b], dy = b.y[q.a] - b.y[q.b];
  if (dx * dx + dy * dy <= q.reach2 && accept(b, q.a, q.b)) sink.add(q.a, q.b);
}

template <class Accept>
__global__ void listDirectKernel(ListView list, BroadphaseBodies b, CandidateSink sink, Accept accept) {
  const long long t = static_cast<long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  const int k = static_cast<int>(t / b.n), j = static_cast<int>(t - static_cast<long long>(k) * b.n);
  const int directCount = list.control->directCount;
  if (k >= list.directRoom || k >= directCount) return;
  const int v = list.directList[k];
  if (j == v || (list.direct[j] && j < v)) return;  // a pair of two direct bodies is found once
  if (b.kind[v] == BodyKind::Wall && b.kind[j] == BodyKind::Wall) return;
  const Real dx = b.x[v] - b.x[j], dy = b.y[v] - b.y[j], reach = b.radius[v] + b.radius[j];
  if (dx * dx + dy * dy <= reach * reach && accept(b, v, j)) sink.add(v, j);
}
#endif

// The host side: storage, sizes, and the enqueue of the five steps above.
class DeviceNeighbourList {
 public:
  explicit DeviceNeighbourList(Real skin) : m_skin(skin) {}
  // half: R + skin / 2 per body; floor: fixed_radius's global radius (0 for the others).
  void upload(const World& world, const std::vector<Real>& half, Real floor);
  // The bodies were permuted on the device (new slot k holds old slot order[k]): the per-body
  // inputs follow them and the list is rebuilt at the next step (as after an upload).
  void reorder(const int* order, int n, cudaStream_t stream);
  // A topology edit on the device (CudaBroadphase::edited): the survivors' inputs follow keptOrder,
  // the new bodies' (half, always direct) are appended, and the list is rebuilt.
  void edited(const int* keptOrder, int kept, const std::vector<Real>& addedHalf, const std::vector<unsigned char>& addedAlways,
              cudaStream_t stream);
  void reserve();
  long rebuilds() const;
  Real skin() const { return m_skin; }

#if defined(__CUDACC__)
  template <class Accept>
  void enqueue(const BroadphaseBodies& bodies, const CandidateSink& sink, cudaStream_t stream, Accept accept) {
    if (bodies.n == 0) return;
    const ListView list = view();
    enqueueListBuild(list, bodies, m_temp.get(), m_tempBytes, stream, sideStream());
    listFilterKernel<<<blocksFor(list.capacity), kBlock, 0, stream>>>(list, bodies, sink, accept);
    GEM_CUDA_CHECK_LAUNCH();
    const long long threads = static_cast<long long>(list.directRoom) * bodies.n;
    listDirectKernel<<<static_cast<unsigned>((threads + kBlock - 1) / kBlock), kBlock, 0, stream>>>(list, bodies, sink, accept);
    GEM_CUDA_CHECK_LAUNCH();
  }
#endif

 private:
  ListView view();
  void markStale();
  cudaStream_t sideStream();  // made once, outside any capture (upload)
  void resize(int n);         // per-body storage and the sort's scratch for n bodies

  Real m_skin;
  int m_n = 0, m_alwaysDirectCount = 0, m_capacity = 0;
  Real m_floor = 0;
  DeviceArray<ListControl> m_control;
  DeviceArray<Real> m_half, m_x0, m_y0, m_angle0, m_lo, m_loSorted;
  DeviceArray<unsigned char> m_alwaysDirect, m_direct;
  DeviceArray<int> m_directList, m_slot, m_slotSorted;
  DeviceArray<ListedPair> m_pairs;
  DeviceArray<unsigned char> m_temp;
  size_t m_tempBytes = 0;
  DeviceArray<Real> m_halfBefore;  // reorder()'s copies
  DeviceArray<unsigned char> m_alwaysBefore;
  DeviceArray<int> m_alwaysFound;
  cudaStream_t m_side = nullptr;

 public:
  ~DeviceNeighbourList() {
    if (m_side) cudaStreamDestroy(m_side);
  }
  DeviceNeighbourList(const DeviceNeighbourList&) = delete;
  DeviceNeighbourList& operator=(const DeviceNeighbourList&) = delete;
};

// The kept list's inputs for the bodies a topology edit appended (rows [first, world.size())):
// half = R + skin / 2, and whether the body is always direct (not a floe).
inline void appendedListInputs(const World& world, int first, Real skin, std::vector<Real>& half, std::vector<unsigned char>& always) {
  half.clear(), always.clear();
  for (int i = first; i < world.size(); ++i) {
    half.push_back(world.radius[i] + skin / 2);
    always.push_back(world.kind[i] != BodyKind::Floe ? 1 : 0);
  }
}

// Row k of `to` becomes row order[k] of `from`, width values a row (a strategy's per-body storage
// following a re-sort of the bodies on the device).
template <class T>
__global__ void gatherByOrderKernel(long long count, int width, const int* order, const T* from, T* to) {
  const long long k = static_cast<long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (k >= count) return;
  to[k] = from[static_cast<long long>(order[k / width]) * width + k % width];
}

// A device strategy built on the kept list (fixed_radius, variable_radius, triangulation_mesh): the
// list follows re-sorts and topology edits on the device, so a strategy says only how it uploads
// and which filter its enqueue() applies; one with per-body storage of its own extends reorder()
// and edited().
class DeviceKeptListBroadphase : public CudaBroadphase {
 public:
  explicit DeviceKeptListBroadphase(Real skin) : m_list(skin) {}
  void reserve(cudaStream_t) override { m_list.reserve(); }
  bool reorder(const int* order, int n, cudaStream_t stream) override {
    m_list.reorder(order, n, stream);
    return true;
  }
  bool edited(const int* keptOrder, int kept, const World& after, int firstAdded, cudaStream_t stream) override {
    std::vector<Real> half;
    std::vector<unsigned char> always;
    appendedListInputs(after, firstAdded, m_list.skin(), half, always);
    m_list.edited(keptOrder, kept, half, always, stream);
    return true;
  }
  long rebuilds() const override { return m_list.rebuilds(); }

 protected:
  // The list of the whole world: each body's reach R + skin / 2 (|c_a - c_b| <= the sum of two
  // reaches at the build, as variable_radius.cpp), or one global radius where fixedRadius > 0.
  void uploadList(const World& world, Real fixedRadius) {
    std::vector<Real> half(world.radius.begin(), world.radius.end());
    for (Real& h : half) h += m_list.skin() / 2;
    m_list.upload(world, half, fixedRadius);
  }
  DeviceNeighbourList m_list;
};

// The plain circle test of variable_radius and fixed_radius: nothing on top.
struct AcceptAll {
#if defined(__CUDACC__)
  __device__ bool operator()(const BroadphaseBodies&, int, int) const { return true; }
#endif
};

}  // namespace gem::cuda
