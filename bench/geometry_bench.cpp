#include "bench/geometry_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

#include "framework/output/atomic_file.hpp"
#include "framework/output/csv.hpp"
#include "bench/bench.hpp"
#include "framework/api/errors.hpp"
#include "geometry/polygon.hpp"
#include "geometry/triangulate.hpp"

namespace gem {

static std::unique_ptr<GeometryBenchKernels>& kernelsSlot() {
  static std::unique_ptr<GeometryBenchKernels> slot;
  return slot;
}

void registerGeometryBenchKernels(GeometryBenchKernels kernels) {
  kernelsSlot() = std::make_unique<GeometryBenchKernels>(std::move(kernels));
}

const GeometryBenchKernels* geometryBenchKernels() { return kernelsSlot().get(); }

namespace {

constexpr unsigned kSeed = 20100501;  // fixed: every run times the same polygons

// n points at sorted random angles on an ellipse (semi-axes r and r * squash), turned by a random
// angle and moved to centre: strictly convex and counter-clockwise.
int convexPolygon(std::mt19937_64& rng, int n, Real r, Vec2 centre, Vec2* out) {
  std::uniform_real_distribution<Real> u(0, 1);
  Real angles[kMaxVertices];
  for (int i = 0; i < n; ++i) angles[i] = 2 * kPi * u(rng);
  std::sort(angles, angles + n);
  const Real squash = Real(0.5) + Real(0.5) * u(rng), turn = 2 * kPi * u(rng);
  for (int i = 0; i < n; ++i) out[i] = centre + rotate(Vec2{r * std::cos(angles[i]), r * squash * std::sin(angles[i])}, turn);
  return n;
}

// n vertices at evenly jittered angles with radii in [0.35 r, r]: star-shaped about centre, so
// simple, counter-clockwise and (almost always) not convex.
int starPolygon(std::mt19937_64& rng, int n, Real r, Vec2 centre, Vec2* out) {
  std::uniform_real_distribution<Real> u(0, 1);
  const Real turn = 2 * kPi * u(rng);
  for (int i = 0; i < n; ++i) {
    const Real a = turn + 2 * kPi * (i + Real(0.8) * u(rng)) / n;
    const Real radius = r * (Real(0.35) + Real(0.65) * u(rng));
    out[i] = centre + Vec2{radius * std::cos(a), radius * std::sin(a)};
  }
  return n;
}

// Pairs of floe-sized convex polygons (radius 3 to 12 m) in a 2 km square: half of them with
// centres closer than 0.7 (rP + rQ) (nearly all overlap), half between 0.7 and 1.3 (rP + rQ)
// (grazing and near misses, as a broadphase proposes them).
ContactBenchInput contactInput(long pairs, int sets) {
  ContactBenchInput in;
  in.pairs = static_cast<int>(pairs);
  in.sets = sets;
  const size_t total = static_cast<size_t>(pairs) * sets;
  in.p.assign(total * kContactBenchStride, Vec2{});
  in.q.assign(total * kContactBenchStride, Vec2{});
  in.np.resize(total), in.nq.resize(total), in.cp.resize(total), in.cq.resize(total);
  std::mt19937_64 rng(kSeed + pairs);
  std::uniform_real_distribution<Real> u(0, 1);
  std::uniform_int_distribution<int> vertices(4, kContactBenchStride);
  for (size_t i = 0; i < total; ++i) {
    const Real rp = 3 + 9 * u(rng), rq = 3 + 9 * u(rng);
    const Vec2 c{2000 * u(rng) - 1000, 2000 * u(rng) - 1000};
    const Real d = (rp + rq) * (i % 2 == 0 ? Real(0.7) * u(rng) : Real(0.7) + Real(0.6) * u(rng));
    const Vec2 cq = c + rotate(Vec2{d, 0}, 2 * kPi * u(rng));
    Vec2* p = &in.p[i * kContactBenchStride];
    Vec2* q = &in.q[i * kContactBenchStride];
    in.np[i] = convexPolygon(rng, vertices(rng), rp, c, p);
    in.nq[i] = convexPolygon(rng, vertices(rng), rq, cq, q);
    in.cp[i] = areaCentroid(p, in.np[i]);
    in.cq[i] = areaCentroid(q, in.nq[i]);
  }
  return in;
}

// Simple polygons of 4 to 24 vertices, half convex, half star-shaped and not convex.
TriangulationBenchInput triangulationInput(long polygons, int sets) {
  TriangulationBenchInput in;
  in.polygons = static_cast<int>(polygons);
  in.sets = sets;
  const size_t total = static_cast<size_t>(polygons) * sets;
  in.v.assign(total * kMaxVertices, Vec2{});
  in.n.resize(total);
  std::mt19937_64 rng(kSeed + 7 * polygons);
  std::uniform_real_distribution<Real> u(0, 1);
  std::uniform_int_distribution<int> vertices(4, kMaxVertices);
  for (size_t i = 0; i < total; ++i) {
    const Vec2 c{2000 * u(rng) - 1000, 2000 * u(rng) - 1000};
    const Real r = 3 + 9 * u(rng);
    Vec2* v = &in.v[i * kMaxVertices];
    in.n[i] = i % 2 == 0 ? convexPolygon(rng, vertices(rng), r, c, v) : starPolygon(rng, vertices(rng), r, c, v);
  }
  return in;
}

double median(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// Times body(set) for repetitions rotating among the sets: one untimed pass over every set first
// (warm-up, and the reference results), then up to maxReps timed, fewer when one takes long
// (about 3 s per row at most, and never fewer than 3). Returns the median in ms.
template <class Body>
double timeCpu(int sets, int maxReps, Body&& body) {
  for (int s = 0; s < sets; ++s) body(s);
  std::vector<double> ms;
  double spent = 0;
  for (int r = 0; r < maxReps && (r < 3 || spent < 3000); ++r) {
    const auto start = std::chrono::steady_clock::now();
    body(r % sets);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    spent += ms.back();
  }
  return median(ms);
}

// Enough distinct sets that the rotation walks through at least ~64 MB where that costs little,
// at most 8: large rows (10^5, 10^6) run on one or two sets, far beyond any cache.
int setsFor(size_t bytesPerSet) {
  const size_t want = (size_t(64) << 20) / std::max<size_t>(bytesPerSet, 1);
  return static_cast<int>(std::clamp<size_t>(want, 1, 8));
}

struct Row {
  long n;
  double cpuMs;
  bool gpu;
  DeviceTiming gpuMs;
  double extra;  // intersection: fraction touching; triangulation: mean triangles per polygon
};

bool relClose(Real a, Real b, Real rel) { return std::fabs(a - b) <= rel * std::max<Real>(std::fabs(a), std::fabs(b)); }

Row intersectionRow(long n, int reps, const GeometryBenchKernels* gpu) {
  const size_t bytes = static_cast<size_t>(n) * 2 * (kContactBenchStride * sizeof(Vec2) + sizeof(int) + sizeof(Vec2));
  const ContactBenchInput in = contactInput(n, setsFor(bytes));
  std::vector<Contact> cpu(static_cast<size_t>(n) * in.sets);
  Row row{n, 0, false, {}, 0};
  row.cpuMs = timeCpu(in.sets, reps, [&](int s) {
    const size_t o = static_cast<size_t>(s) * n;
    for (size_t i = o; i < o + n; ++i)
      cpu[i] = computeContact(&in.p[i * kContactBenchStride], in.np[i], in.cp[i], &in.q[i * kContactBenchStride], in.nq[i], in.cq[i]);
  });
  long touching = 0;
  for (const Contact& c : cpu) touching += c.touching;
  row.extra = double(touching) / cpu.size();
  if (touching == 0 || touching == static_cast<long>(cpu.size()))
    throw std::runtime_error("gem bench --table intersection: the random pairs do not mix touching and apart pairs");
  if (gpu && gpu->available()) {
    std::vector<Contact> dev;
    row.gpuMs = gpu->contacts(in, reps, dev);
    row.gpu = true;
    if (dev.size() != cpu.size()) throw std::runtime_error("gem bench --table intersection: the GPU returned the wrong number of contacts");
    long bad = 0;
    size_t first = 0;
    for (size_t i = 0; i < cpu.size(); ++i) {
      const bool ok = cpu[i].touching == dev[i].touching && relClose(cpu[i].area, dev[i].area, Real(1e-12));
      if (!ok && bad++ == 0) first = i;
    }
    if (bad)
      throw std::runtime_error(fmt::format(
          "gem bench --table intersection: GPU and CPU disagree on {} of {} pairs (N = {}); first: pair {}, CPU touching {} area {:.17g}, "
          "GPU touching {} area {:.17g}",
          bad, cpu.size(), n, first, cpu[first].touching, cpu[first].area, dev[first].touching, dev[first].area));
  }
  return row;
}

Row triangulationRow(long n, int reps, const GeometryBenchKernels* gpu) {
  const size_t bytes = static_cast<size_t>(n) * (kMaxVertices * sizeof(Vec2) + sizeof(int));
  const TriangulationBenchInput in = triangulationInput(n, setsFor(bytes));
  constexpr int kTri = (kMaxVertices - 2) * 3;
  TriangulationBenchOutput cpu;
  cpu.count.assign(static_cast<size_t>(n) * in.sets, -1);
  cpu.tri.assign(cpu.count.size() * kTri, -1);
  Row row{n, 0, false, {}, 0};
  row.cpuMs = timeCpu(in.sets, reps, [&](int s) {
    const size_t o = static_cast<size_t>(s) * n;
    for (size_t i = o; i < o + n; ++i)
      cpu.count[i] = earClip(&in.v[i * kMaxVertices], in.n[i], reinterpret_cast<int(*)[3]>(&cpu.tri[i * kTri]));
  });
  long triangles = 0;
  for (size_t i = 0; i < cpu.count.size(); ++i) {
    if (cpu.count[i] != in.n[i] - 2) throw std::runtime_error("gem bench --table triangulation: earClip gave a wrong triangle count");
    triangles += cpu.count[i];
  }
  row.extra = double(triangles) / cpu.count.size();
  if (gpu && gpu->available()) {
    TriangulationBenchOutput dev;
    row.gpuMs = gpu->triangulate(in, reps, dev);
    row.gpu = true;
    if (dev.count.size() != cpu.count.size() || dev.tri.size() != cpu.tri.size())
      throw std::runtime_error("gem bench --table triangulation: the GPU returned the wrong number of results");
    long bad = 0;
    size_t first = 0;
    for (size_t i = 0; i < cpu.count.size(); ++i) {
      bool ok = cpu.count[i] == dev.count[i];
      for (int k = 0; ok && k < 3 * cpu.count[i]; ++k) ok = cpu.tri[i * kTri + k] == dev.tri[i * kTri + k];
      if (!ok && bad++ == 0) first = i;
    }
    if (bad)
      throw std::runtime_error(
          fmt::format("gem bench --table triangulation: GPU and CPU disagree on {} of {} polygons (N = {}); first: "
                      "polygon {} ({} vertices), CPU {} triangles, GPU {}",
                      bad, cpu.count.size(), n, first, in.n[first], cpu.count[first], dev.count[first]));
  }
  return row;
}

}  // namespace

int runGeometryBench(const GeometryBenchOptions& options) {
  const bool intersection = options.table == "intersection";
  if (!intersection && options.table != "triangulation")
    throw InputError(fmt::format("gem bench --table {}: valid tables are step, intersection and triangulation", options.table));
  if (options.reps < 1) throw InputError("gem bench --reps: must be at least 1");
  std::vector<long> sizes = options.sizes;
  if (sizes.empty())
    sizes = intersection ? std::vector<long>{100, 300, 1000, 3000, 100000, 1000000} : std::vector<long>{500, 1000, 2000, 4000, 8000, 16000};
  for (long n : sizes)
    if (n < 2 || n > 4000000) throw InputError(fmt::format("gem bench --sizes: {} is out of range (2 to 4000000)", n));

  const GeometryBenchKernels* gpu = geometryBenchKernels();
  const bool haveGpu = gpu && gpu->available();
  const std::string device = haveGpu ? gpu->deviceName() : std::string("no CUDA device");
  const std::string cpu = cpuName() + " (one core)";
  const char* what = intersection ? "computeContact over N convex polygon pairs (4-12 vertices)"
                                  : "earClip over N simple polygons (4-24 vertices, half convex, half star-shaped)";
  std::printf("gem bench --table %s: %s\n", options.table.c_str(), what);
  std::printf("GPU: %s, one thread per %s; CPU: %s\n", device.c_str(), intersection ? "pair" : "polygon", cpu.c_str());
  std::printf("median ms of up to %d repetitions after a warm-up, rotating among input sets; GPU checked against the CPU (%s)\n",
              options.reps, intersection ? "touching flags equal, areas within 1e-12 relative" : "triangles identical");
  std::printf("%9s %11s %13s %13s %10s %10s %10s\n", "N", "CPU ms", "GPU kernel ms", "GPU+copy ms", "speed-up", "w/ copy",
              intersection ? "touching" : "tri/poly");
  std::string csv = fmt::format("table,n,cpu_ms,gpu_kernel_ms,gpu_with_copies_ms,speedup_kernel,speedup_with_copies,{},device,cpu\n",
                                intersection ? "touching_fraction" : "triangles_per_polygon");
  for (long n : sizes) {
    const Row r = intersection ? intersectionRow(n, options.reps, gpu) : triangulationRow(n, options.reps, gpu);
    if (r.gpu) {
      std::printf("%9ld %11.4f %13.4f %13.4f %10.1f %10.1f %10.3f\n", n, r.cpuMs, r.gpuMs.kernelMs, r.gpuMs.totalMs,
                  r.cpuMs / r.gpuMs.kernelMs, r.cpuMs / r.gpuMs.totalMs, r.extra);
      csv +=
          fmt::format("{},{},{:.6f},{:.6f},{:.6f},{:.3f},{:.3f},{:.4f},{},{}\n", csvField(options.table), n, r.cpuMs, r.gpuMs.kernelMs,
                      r.gpuMs.totalMs, r.cpuMs / r.gpuMs.kernelMs, r.cpuMs / r.gpuMs.totalMs, r.extra, csvQuoted(device), csvQuoted(cpu));
    } else {
      std::printf("%9ld %11.4f %13s %13s %10s %10s %10.3f\n", n, r.cpuMs, "-", "-", "-", "-", r.extra);
      csv +=
          fmt::format("{},{},{:.6f},,,,,{:.4f},{},{}\n", csvField(options.table), n, r.cpuMs, r.extra, csvQuoted(device), csvQuoted(cpu));
    }
    std::fflush(stdout);
  }
  if (!haveGpu) std::printf("GPU columns: no CUDA device (%s)\n", gpu ? "none found on this machine" : "this build has no CUDA");
  if (!options.csv.empty()) writeFileAtomically(options.csv, csv);
  return 0;
}

}  // namespace gem
