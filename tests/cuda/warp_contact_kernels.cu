// tests/cuda/warp_contact_kernels.hpp. Built with gem_cuda's --fmad=false, as the drivers are.
#include <cuda_runtime.h>

#include "framework/api/cuda_check.hpp"
#include "framework/api/device_array.hpp"
#include "framework/cuda/warp_contact.cuh"
#include "tests/cuda/warp_contact_kernels.hpp"

namespace gem::test {
namespace {

constexpr int kWarps = 4;

__global__ void contactByThread(int pairs, const Vec2* p, const int* np, const Vec2* cp, const Vec2* q, const int* nq, const Vec2* cq,
                                Contact* out) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= pairs) return;
  const size_t v = static_cast<size_t>(i) * kMaxVertices;
  out[i] = computeContact(p + v, np[i], cp[i], q + v, nq[i], cq[i]);
}

__global__ void contactByWarp(int pairs, const Vec2* p, const int* np, const Vec2* cp, const Vec2* q, const int* nq, const Vec2* cq,
                              Contact* out) {
  __shared__ ClipVertex buf[kWarps][cuda::kWarpClipRoom];
  const int warp = threadIdx.x >> 5;
  const int i = blockIdx.x * kWarps + warp;
  if (i >= pairs) return;  // the whole warp leaves together
  const size_t v = static_cast<size_t>(i) * kMaxVertices;
  Contact c{};
  c.apexVertexP = c.apexVertexQ = -1;
  if (convexOverlap(p + v, np[i], q + v, nq[i])) c = cuda::warpContactOfOverlapping(p + v, np[i], cp[i], q + v, nq[i], cq[i], buf[warp]);
  if ((threadIdx.x & 31) == 0) out[i] = c;
}

// Overlapping pairs overlapping[2w] and [2w + 1] on warp w, the half warps with HalfRoom vertices.
template <int HalfRoom>
__global__ void contactByHalfWarps(int count, const int* overlapping, const Vec2* p, const int* np, const Vec2* cp, const Vec2* q,
                                   const int* nq, const Vec2* cq, Contact* out) {
  __shared__ ClipVertex buf[kWarps][cuda::kWarpClipRoom];
  const int warp = threadIdx.x >> 5;
  const int j0 = 2 * (blockIdx.x * kWarps + warp);
  if (j0 >= count) return;  // the whole warp leaves together
  auto fetch = [&](int j) {
    const int i = overlapping[j];
    const size_t v = static_cast<size_t>(i) * kMaxVertices;
    return cuda::PairPolygons{p + v, np[i], cp[i], q + v, nq[i], cq[i]};
  };
  auto store = [&](int j, const Contact& c) { out[overlapping[j]] = c; };
  cuda::warpContactsOfTwo<HalfRoom>(j0, count, fetch, store, buf[warp]);
}

}  // namespace

void deviceContacts(const PolygonPairs& in, std::vector<Contact>& byThread, std::vector<Contact>& byWarp, std::vector<Contact>& byHalfWarp,
                    std::vector<Contact>& byCrampedHalfWarp) {
  const size_t n = static_cast<size_t>(in.size()), nv = n * kMaxVertices;
  cuda::DeviceArray<Vec2> p(nv), q(nv), cp(n), cq(n);
  cuda::DeviceArray<int> np(n), nq(n);
  cuda::DeviceArray<Contact> thread(n), warp(n);
  p.upload(in.p.data(), nv), q.upload(in.q.data(), nv), cp.upload(in.cp.data(), n), cq.upload(in.cq.data(), n);
  np.upload(in.np.data(), n), nq.upload(in.nq.data(), n);
  // Poisoned results: a pair a kernel skipped cannot match.
  GEM_CUDA_CHECK(cudaMemset(thread.get(), 0xff, n * sizeof(Contact)));
  GEM_CUDA_CHECK(cudaMemset(warp.get(), 0x7f, n * sizeof(Contact)));
  contactByThread<<<static_cast<unsigned>((n + 127) / 128), 128>>>(in.size(), p.get(), np.get(), cp.get(), q.get(), nq.get(), cq.get(),
                                                                   thread.get());
  GEM_CUDA_CHECK_LAUNCH();
  contactByWarp<<<static_cast<unsigned>((n + kWarps - 1) / kWarps), 32 * kWarps>>>(in.size(), p.get(), np.get(), cp.get(), q.get(),
                                                                                   nq.get(), cq.get(), warp.get());
  GEM_CUDA_CHECK_LAUNCH();
  // The overlapping pairs (the CPU's separating-axis test: the same as the device's), two a warp.
  std::vector<int> overlapping;
  for (int i = 0; i < in.size(); ++i) {
    const size_t v = static_cast<size_t>(i) * kMaxVertices;
    if (convexOverlap(&in.p[v], in.np[i], &in.q[v], in.nq[i])) overlapping.push_back(i);
  }
  const int count = static_cast<int>(overlapping.size());
  cuda::DeviceArray<int> list(overlapping.size());
  list.upload(overlapping.data(), overlapping.size());
  cuda::DeviceArray<Contact> half(n), cramped(n);
  std::vector<Contact> apart(n, Contact{});
  for (Contact& c : apart) c.apexVertexP = c.apexVertexQ = -1;
  half.upload(apart.data(), n);
  cramped.upload(apart.data(), n);
  const unsigned blocks = static_cast<unsigned>(((count + 1) / 2 + kWarps - 1) / kWarps);
  contactByHalfWarps<cuda::kWarpClipRoom / 2>
      <<<blocks, 32 * kWarps>>>(count, list.get(), p.get(), np.get(), cp.get(), q.get(), nq.get(), cq.get(), half.get());
  GEM_CUDA_CHECK_LAUNCH();
  // Half warps with room for 8 vertices: most pairs outgrow it and go to the whole warp.
  contactByHalfWarps<8>
      <<<blocks, 32 * kWarps>>>(count, list.get(), p.get(), np.get(), cp.get(), q.get(), nq.get(), cq.get(), cramped.get());
  GEM_CUDA_CHECK_LAUNCH();
  GEM_CUDA_CHECK(cudaDeviceSynchronize());
  byThread.resize(n), byWarp.resize(n), byHalfWarp.resize(n), byCrampedHalfWarp.resize(n);
  thread.download(byThread.data(), n);
  warp.download(byWarp.data(), n);
  half.download(byHalfWarp.data(), n);
  cramped.download(byCrampedHalfWarp.data(), n);
}

}  // namespace gem::test
