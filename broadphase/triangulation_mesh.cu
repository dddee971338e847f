// triangulation_mesh on the device. What runs where:
//   host, at an upload (set-up), and for the new floes of a break: polygons are ear-clipped in
//     their body frame (geometry/triangulate.hpp, the CPU's very function) and the index triples
//     copied over; a re-sort or a break moves the others' triples on the device;
//   device, every step: the variable_radius kept list of device_neighbour_list.cuh (same skin, same
//     rebuild rule, as triangulation_mesh.cpp), and on each pair whose circles overlap the
//     triangle test of triangulation_mesh.cpp: boxes within eps, then any triangle of one whose box
//     meets the other's box overlapping any such triangle of the other (trianglesOverlap, GEM_HD),
//     the world vertices being the step's own (phase 1).
// The eps and the box test are the CPU's (broadphase/triangle_overlap.hpp).
#include "broadphase/kept_list/device_neighbour_list.cuh"
#include "broadphase/triangle_overlap.hpp"
#include "framework/api/registry.hpp"
#include "geometry/triangulate.hpp"

namespace gem::cuda {
namespace {

struct TrianglesOverlap {
  const int* triangleCount;  // per body
  const int* triangles;      // kMaxTriangles x 3 vertex indices per body

#if defined(__CUDACC__)
  __device__ void place(const BroadphaseBodies& b, int body, int t, Vec2 out[3]) const {
    const int* k = triangles + (static_cast<size_t>(body) * kMaxTriangles + t) * 3;
    const Vec2* v = b.worldVertices + static_cast<size_t>(body) * kMaxVertices;
    out[0] = v[k[0]], out[1] = v[k[1]], out[2] = v[k[2]];
  }
  __device__ bool operator()(const BroadphaseBodies& b, int i, int j) const {
    const int p = i < j ? i : j, q = i < j ? j : i;  // the CPU's eps is taken at the pair's a
    const Real eps = triangleTestEps(b.radius[p], b.radius[q], b.x[p], b.y[p]);
    if (!boxesMeet(b.boxes[p], b.boxes[q], eps)) return false;
    for (int s = 0; s < triangleCount[p]; ++s) {
      Vec2 tp[3];
      place(b, p, s, tp);
      if (!boxesMeet(boundingBox(tp, 3), b.boxes[q], eps)) continue;
      for (int t = 0; t < triangleCount[q]; ++t) {
        Vec2 tq[3];
        place(b, q, t, tq);
        if (!boxesMeet(boundingBox(tq, 3), b.boxes[p], eps)) continue;
        if (trianglesOverlap(tp, tq, eps)) return true;
      }
    }
    return false;
  }
#endif
};

class DeviceTriangulationMesh final : public DeviceKeptListBroadphase {
 public:
  static constexpr const char* kSettings[] = {"skin"};  // honoured on the device too
  explicit DeviceTriangulationMesh(const BroadphaseSettings& s) : DeviceKeptListBroadphase(checkedSettings(s).skin) {}
  void upload(const World& world) override {
    const int n = world.size();
    m_rows = n;
    uploadList(world, 0);
    std::vector<int> count(static_cast<size_t>(std::max(n, 1)), 0);
    std::vector<int> triangles(static_cast<size_t>(std::max(n, 1)) * kMaxTriangles * 3, 0);
    for (int i = 0; i < n; ++i)
      count[i] = earClip(world.local(i), world.vertexCount[i],
                         reinterpret_cast<int(*)[3]>(&triangles[static_cast<size_t>(i) * kMaxTriangles * 3]));
    m_count.upload(count.data(), count.size());
    m_triangles.upload(triangles.data(), triangles.size());
  }
  bool reorder(const int* order, int n, cudaStream_t stream) override {
    DeviceKeptListBroadphase::reorder(order, n, stream);
    if (n == 0) return true;
    // Each body's triangles (indices into its own vertices) follow it.
    const long long rows = n, width = kMaxTriangles * 3;
    m_countBefore.ensure(static_cast<size_t>(rows)), m_trianglesBefore.ensure(static_cast<size_t>(rows * width));
    GEM_CUDA_CHECK(cudaMemcpyAsync(m_countBefore.get(), m_count.get(), rows * sizeof(int), cudaMemcpyDeviceToDevice, stream));
    GEM_CUDA_CHECK(
        cudaMemcpyAsync(m_trianglesBefore.get(), m_triangles.get(), rows * width * sizeof(int), cudaMemcpyDeviceToDevice, stream));
    gatherByOrderKernel<int><<<blocksFor(n), kBlock, 0, stream>>>(rows, 1, order, m_countBefore.get(), m_count.get());
    GEM_CUDA_CHECK_LAUNCH();
    gatherByOrderKernel<int><<<static_cast<unsigned>((rows * width + kBlock - 1) / kBlock), kBlock, 0, stream>>>(
        rows * width, static_cast<int>(width), order, m_trianglesBefore.get(), m_triangles.get());
    GEM_CUDA_CHECK_LAUNCH();
    GEM_CUDA_CHECK(cudaStreamSynchronize(stream));
    return true;
  }
  bool edited(const int* keptOrder, int kept, const World& after, int firstAdded, cudaStream_t stream) override {
    DeviceKeptListBroadphase::edited(keptOrder, kept, after, firstAdded, stream);
    // The survivors' triangles follow them; only the new bodies are ear-clipped (on the host).
    const long long width = kMaxTriangles * 3, added = after.size() - firstAdded, n = kept + added;
    const long long before = static_cast<long long>(m_rows);
    m_countBefore.ensure(static_cast<size_t>(std::max(before, 1LL))),
        m_trianglesBefore.ensure(static_cast<size_t>(std::max(before, 1LL) * width));
    if (before) {
      GEM_CUDA_CHECK(cudaMemcpyAsync(m_countBefore.get(), m_count.get(), before * sizeof(int), cudaMemcpyDeviceToDevice, stream));
      GEM_CUDA_CHECK(
          cudaMemcpyAsync(m_trianglesBefore.get(), m_triangles.get(), before * width * sizeof(int), cudaMemcpyDeviceToDevice, stream));
    }
    GEM_CUDA_CHECK(cudaStreamSynchronize(stream));  // ensure() below may move the arrays just copied
    m_count.ensure(static_cast<size_t>(std::max(n, 1LL))), m_triangles.ensure(static_cast<size_t>(std::max(n, 1LL) * width));
    if (kept > 0) {
      gatherByOrderKernel<int><<<blocksFor(kept), kBlock, 0, stream>>>(kept, 1, keptOrder, m_countBefore.get(), m_count.get());
      GEM_CUDA_CHECK_LAUNCH();
      gatherByOrderKernel<int><<<static_cast<unsigned>((kept * width + kBlock - 1) / kBlock), kBlock, 0, stream>>>(
          kept * width, static_cast<int>(width), keptOrder, m_trianglesBefore.get(), m_triangles.get());
      GEM_CUDA_CHECK_LAUNCH();
    }
    if (added > 0) {
      std::vector<int> count(static_cast<size_t>(added)), triangles(static_cast<size_t>(added * width), 0);
      for (int k = 0; k < added; ++k) {
        const int i = firstAdded + k;
        count[k] = earClip(after.local(i), after.vertexCount[i], reinterpret_cast<int(*)[3]>(&triangles[static_cast<size_t>(k * width)]));
      }
      GEM_CUDA_CHECK(cudaMemcpyAsync(m_count.get() + kept, count.data(), count.size() * sizeof(int), cudaMemcpyHostToDevice, stream));
      GEM_CUDA_CHECK(cudaMemcpyAsync(m_triangles.get() + kept * width, triangles.data(), triangles.size() * sizeof(int),
                                     cudaMemcpyHostToDevice, stream));
    }
    GEM_CUDA_CHECK(cudaStreamSynchronize(stream));
    m_rows = static_cast<int>(n);
    return true;
  }
  void enqueue(const BroadphaseBodies& bodies, const CandidateSink& sink, cudaStream_t stream) override {
    m_list.enqueue(bodies, sink, stream, TrianglesOverlap{m_count.get(), m_triangles.get()});
  }

 private:
  DeviceArray<int> m_count, m_triangles;
  DeviceArray<int> m_countBefore, m_trianglesBefore;  // reorder()'s and edited()'s copies
  int m_rows = 0;                                     // bodies the triangle arrays hold
};

}  // namespace

GEM_REGISTER_CUDA_BROADPHASE(DeviceTriangulationMesh, "triangulation_mesh");

}  // namespace gem::cuda
