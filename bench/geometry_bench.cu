// The GPU half of gem bench --table intersection | triangulation (bench/geometry_bench.hpp):
// computeContact and earClip, the same GEM_HD functions the CPU loop calls, one thread per pair or
// polygon. Registered at load time, as the cuda backend is.
#include <cuda_runtime.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "framework/api/cuda_check.hpp"
#include "framework/api/device_array.hpp"
#include "bench/geometry_bench.hpp"
#include "geometry/contact.hpp"
#include "geometry/triangulate.hpp"

namespace gem {

// framework/cuda/cuda_stepper.cpp (its header brings toml++, which nvcc does not compile).
bool cudaAvailable();
std::string cudaDeviceName();

namespace {

constexpr int kBlock = 128;
constexpr int kWarmups = 5;
constexpr int kTri = (kMaxVertices - 2) * 3;

__global__ void contactKernel(int pairs, const Vec2* p, const int* np, const Vec2* cp, const Vec2* q, const int* nq, const Vec2* cq,
                              Contact* out) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= pairs) return;
  const size_t v = static_cast<size_t>(i) * kContactBenchStride;
  out[i] = computeContact(p + v, np[i], cp[i], q + v, nq[i], cq[i]);
}

__global__ void earClipKernel(int polygons, const Vec2* v, const int* n, int* count, int* tri) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= polygons) return;
  count[i] = earClip(v + static_cast<size_t>(i) * kMaxVertices, n[i], reinterpret_cast<int(*)[3]>(tri + static_cast<size_t>(i) * kTri));
}

// Device allocations of a fixed size, freed on scope exit, so that a failed check leaks nothing.
using cuda::DeviceArray;

template <class T>
struct PinnedArray {
  T* ptr = nullptr;
  explicit PinnedArray(size_t n) { GEM_CUDA_CHECK(cudaMallocHost(&ptr, std::max<size_t>(n, 1) * sizeof(T))); }
  ~PinnedArray() { cudaFreeHost(ptr); }
  PinnedArray(const PinnedArray&) = delete;
  PinnedArray& operator=(const PinnedArray&) = delete;
};

struct Events {
  cudaEvent_t start = nullptr, stop = nullptr;
  Events() {
    GEM_CUDA_CHECK(cudaEventCreate(&start));
    GEM_CUDA_CHECK(cudaEventCreate(&stop));
  }
  ~Events() {
    cudaEventDestroy(start);
    cudaEventDestroy(stop);
  }
  float elapsedMs() {
    GEM_CUDA_CHECK(cudaEventSynchronize(stop));
    float ms = 0;
    GEM_CUDA_CHECK(cudaEventElapsedTime(&ms, start, stop));
    return ms;
  }
};

double median(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

template <class T>
void toPinned(PinnedArray<T>& dst, const std::vector<T>& src) {
  std::memcpy(dst.ptr, src.data(), src.size() * sizeof(T));
}

// Runs launch(set) and copies for `reps` repetitions after kWarmups, rotating among the sets.
// Kernel only: every set already on the device. With copies: the set's inputs from pinned host
// memory, the kernel, the results back to pinned host memory, all inside the events.
template <class Launch, class Upload, class Download>
DeviceTiming timeRotating(int sets, int reps, Launch&& launch, Upload&& upload, Download&& download) {
  Events ev;
  DeviceTiming t;
  std::vector<double> ms;
  // Every set once at least, so that each set's results are written before they are checked (with
  // fewer repetitions than sets, `gem bench --reps 3` compared sets never run: 150 of 400 pairs).
  for (int r = 0; r < std::max(kWarmups, sets); ++r) launch(r % sets);
  GEM_CUDA_CHECK(cudaDeviceSynchronize());
  for (int r = 0; r < reps; ++r) {
    GEM_CUDA_CHECK(cudaEventRecord(ev.start));
    launch(r % sets);
    GEM_CUDA_CHECK(cudaEventRecord(ev.stop));
    ms.push_back(ev.elapsedMs());
  }
  t.kernelMs = median(ms);
  ms.clear();
  for (int r = 0; r < kWarmups + reps; ++r) {
    GEM_CUDA_CHECK(cudaEventRecord(ev.start));
    upload(r % sets);
    launch(r % sets);
    download(r % sets);
    GEM_CUDA_CHECK(cudaEventRecord(ev.stop));
    const double e = ev.elapsedMs();
    if (r >= kWarmups) ms.push_back(e);
  }
  t.totalMs = median(ms);
  return t;
}

DeviceTiming timeContacts(const ContactBenchInput& in, int reps, std::vector<Contact>& out) {
  const size_t n = static_cast<size_t>(in.pairs), total = n * in.sets, nv = n * kContactBenchStride;
  PinnedArray<Vec2> hp(total * kContactBenchStride), hq(total * kContactBenchStride), hcp(total), hcq(total);
  PinnedArray<int> hnp(total), hnq(total);
  PinnedArray<Contact> hout(total);
  toPinned(hp, in.p), toPinned(hq, in.q), toPinned(hcp, in.cp), toPinned(hcq, in.cq), toPinned(hnp, in.np), toPinned(hnq, in.nq);
  // Every set on the device (kernel-only timing) and one staging set (timing with copies).
  DeviceArray<Vec2> p(total * kContactBenchStride), q(total * kContactBenchStride), cp(total), cq(total);
  DeviceArray<int> np(total), nq(total);
  DeviceArray<Contact> res(total);
  DeviceArray<Vec2> sp(nv), sq(nv), scp(n), scq(n);
  DeviceArray<int> snp(n), snq(n);
  DeviceArray<Contact> sres(n);
  GEM_CUDA_CHECK(cudaMemcpy(p.get(), hp.ptr, total * kContactBenchStride * sizeof(Vec2), cudaMemcpyHostToDevice));
  GEM_CUDA_CHECK(cudaMemcpy(q.get(), hq.ptr, total * kContactBenchStride * sizeof(Vec2), cudaMemcpyHostToDevice));
  GEM_CUDA_CHECK(cudaMemcpy(cp.get(), hcp.ptr, total * sizeof(Vec2), cudaMemcpyHostToDevice));
  GEM_CUDA_CHECK(cudaMemcpy(cq.get(), hcq.ptr, total * sizeof(Vec2), cudaMemcpyHostToDevice));
  GEM_CUDA_CHECK(cudaMemcpy(np.get(), hnp.ptr, total * sizeof(int), cudaMemcpyHostToDevice));
  GEM_CUDA_CHECK(cudaMemcpy(nq.get(), hnq.ptr, total * sizeof(int), cudaMemcpyHostToDevice));
  // Poisoned results: a pair the kernel skipped cannot pass the check.
  GEM_CUDA_CHECK(cudaMemset(res.get(), 0xff, total * sizeof(Contact)));
  const int blocks = static_cast<int>((n + kBlock - 1) / kBlock);
  bool staged = false;
  auto launchOn = [&](const Vec2* a, const int* na, const Vec2* ca, const Vec2* b, const int* nb, const Vec2* cb, Contact* o) {
    contactKernel<<<blocks, kBlock>>>(in.pairs, a, na, ca, b, nb, cb, o);
    GEM_CUDA_CHECK_LAUNCH();
  };
  auto launch = [&](int s) {
    if (staged) return launchOn(sp.get(), snp.get(), scp.get(), sq.get(), snq.get(), scq.get(), sres.get());
    const size_t o = s * n;
    launchOn(p.get() + o * kContactBenchStride, np.get() + o, cp.get() + o, q.get() + o * kContactBenchStride, nq.get() + o, cq.get() + o,
             res.get() + o);
  };
  auto upload = [&](int s) {
    staged = true;
    const size_t o = s * n;
    GEM_CUDA_CHECK(cudaMemcpyAsync(sp.get(), hp.ptr + o * kContactBenchStride, nv * sizeof(Vec2), cudaMemcpyHostToDevice));
    GEM_CUDA_CHECK(cudaMemcpyAsync(sq.get(), hq.ptr + o * kContactBenchStride, nv * sizeof(Vec2), cudaMemcpyHostToDevice));
    GEM_CUDA_CHECK(cudaMemcpyAsync(scp.get(), hcp.ptr + o, n * sizeof(Vec2), cudaMemcpyHostToDevice));
    GEM_CUDA_CHECK(cudaMemcpyAsync(scq.get(), hcq.ptr + o, n * sizeof(Vec2), cudaMemcpyHostToDevice));
    GEM_CUDA_CHECK(cudaMemcpyAsync(snp.get(), hnp.ptr + o, n * sizeof(int), cudaMemcpyHostToDevice));
    GEM_CUDA_CHECK(cudaMemcpyAsync(snq.get(), hnq.ptr + o, n * sizeof(int), cudaMemcpyHostToDevice));
  };
  auto download = [&](int s) {
    GEM_CUDA_CHECK(cudaMemcpyAsync(hout.ptr + s * n, sres.get(), n * sizeof(Contact), cudaMemcpyDeviceToHost));
  };
  // The results checked are those of the kernel-only runs (every set written by then); the copied-
  // back results of the staged runs are checked too, for the sets they covered.
  DeviceTiming t = timeRotating(in.sets, reps, launch, upload, download);
  GEM_CUDA_CHECK(cudaDeviceSynchronize());
  out.resize(total);
  GEM_CUDA_CHECK(cudaMemcpy(out.data(), res.get(), total * sizeof(Contact), cudaMemcpyDeviceToHost));
  const int covered = std::min(in.sets, kWarmups + reps);
  for (size_t i = 0; i < static_cast<size_t>(covered) * n; ++i)
    if (hout.ptr[i].touching != out[i].touching || hout.ptr[i].area != out[i].area || hout.ptr[i].width != out[i].width)
      out[i].touching = !out[i].touching;  // fails the check loudly
  return t;
}

DeviceTiming timeTriangulation(const TriangulationBenchInput& in, int reps, TriangulationBenchOutput& out) {
  const size_t n = static_cast<size_t>(in.polygons), total = n * in.sets;
  PinnedArray<Vec2> hv(total * kMaxVertices);
  PinnedArray<int> hn(total), hcount(total), htri(total * kTri);
  toPinned(hv, in.v), toPinned(hn, in.n);
  DeviceArray<Vec2> v(total * kMaxVertices), sv(n * kMaxVertices);
  DeviceArray<int> nv(total), count(total), tri(total * kTri), snv(n), scount(n), stri(n * kTri);
  GEM_CUDA_CHECK(cudaMemcpy(v.get(), hv.ptr, total * kMaxVertices * sizeof(Vec2), cudaMemcpyHostToDevice));
  GEM_CUDA_CHECK(cudaMemcpy(nv.get(), hn.ptr, total * sizeof(int), cudaMemcpyHostToDevice));
  GEM_CUDA_CHECK(cudaMemset(count.get(), 0xff, total * sizeof(int)));
  GEM_CUDA_CHECK(cudaMemset(tri.get(), 0xff, total * kTri * sizeof(int)));
  const int blocks = static_cast<int>((n + kBlock - 1) / kBlock);
  bool staged = false;
  auto launch = [&](int s) {
    const size_t o = s * n;
    if (staged)
      earClipKernel<<<blocks, kBlock>>>(in.polygons, sv.get(), snv.get(), scount.get(), stri.get());
    else
      earClipKernel<<<blocks, kBlock>>>(in.polygons, v.get() + o * kMaxVertices, nv.get() + o, count.get() + o, tri.get() + o * kTri);
    GEM_CUDA_CHECK_LAUNCH();
  };
  auto upload = [&](int s) {
    staged = true;
    const size_t o = s * n;
    GEM_CUDA_CHECK(cudaMemcpyAsync(sv.get(), hv.ptr + o * kMaxVertices, n * kMaxVertices * sizeof(Vec2), cudaMemcpyHostToDevice));
    GEM_CUDA_CHECK(cudaMemcpyAsync(snv.get(), hn.ptr + o, n * sizeof(int), cudaMemcpyHostToDevice));
  };
  auto download = [&](int s) {
    const size_t o = s * n;
    GEM_CUDA_CHECK(cudaMemcpyAsync(hcount.ptr + o, scount.get(), n * sizeof(int), cudaMemcpyDeviceToHost));
    GEM_CUDA_CHECK(cudaMemcpyAsync(htri.ptr + o * kTri, stri.get(), n * kTri * sizeof(int), cudaMemcpyDeviceToHost));
  };
  DeviceTiming t = timeRotating(in.sets, reps, launch, upload, download);
  GEM_CUDA_CHECK(cudaDeviceSynchronize());
  out.count.resize(total);
  out.tri.resize(total * kTri);
  GEM_CUDA_CHECK(cudaMemcpy(out.count.data(), count.get(), total * sizeof(int), cudaMemcpyDeviceToHost));
  GEM_CUDA_CHECK(cudaMemcpy(out.tri.data(), tri.get(), total * kTri * sizeof(int), cudaMemcpyDeviceToHost));
  // The staged runs' copied-back counts and used triangles must match the kernel-only runs' too.
  const int covered = std::min(in.sets, kWarmups + reps);
  for (size_t i = 0; i < static_cast<size_t>(covered) * n; ++i) {
    bool same = hcount.ptr[i] == out.count[i];
    for (int k = 0; same && k < 3 * out.count[i] && k < kTri; ++k) same = htri.ptr[i * kTri + k] == out.tri[i * kTri + k];
    if (!same) out.count[i] = -2;  // fails the check loudly
  }
  return t;
}

const bool kRegistered = [] {
  registerGeometryBenchKernels(
      GeometryBenchKernels{[] { return cudaAvailable(); }, [] { return cudaDeviceName(); }, timeContacts, timeTriangulation});
  return true;
}();

}  // namespace
}  // namespace gem
