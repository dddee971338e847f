// gem bench --table intersection | triangulation: the thesis's Chapter 5.2 and 5.3 experiments,
// computeContact over N polygon pairs and earClip over N polygons, one CPU core (a loop) against
// the GPU (one thread per pair or polygon). The GPU half is a registry entry that libgem_cuda
// fills at load time (bench/geometry_bench.cu), as registerBackend does: gem_core never
// depends on CUDA, and a CPU-only build prints the CPU columns and "no CUDA device".
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "geometry/config.hpp"
#include "geometry/contact.hpp"
#include "geometry/vec2.hpp"

namespace gem {

// The intersection table's polygons have 4 to 12 vertices, stored with this fixed stride.
constexpr int kContactBenchStride = 12;

// `sets` independent sets of `pairs` polygon pairs (p[i], q[i]), one after the other; repetitions
// rotate among the sets so that no timing sees the same bytes twice in a row.
struct ContactBenchInput {
  int pairs = 0, sets = 0;
  std::vector<Vec2> p, q;    // sets * pairs * kContactBenchStride, counter-clockwise, world coordinates
  std::vector<int> np, nq;   // sets * pairs vertex counts
  std::vector<Vec2> cp, cq;  // sets * pairs area centroids
};

// `sets` independent sets of `polygons` simple counter-clockwise polygons, stride kMaxVertices.
struct TriangulationBenchInput {
  int polygons = 0, sets = 0;
  std::vector<Vec2> v;  // sets * polygons * kMaxVertices
  std::vector<int> n;   // sets * polygons vertex counts
};

// Triangles of each polygon: count and (kMaxVertices - 2) index triples per polygon.
struct TriangulationBenchOutput {
  std::vector<int> count;  // sets * polygons
  std::vector<int> tri;    // sets * polygons * (kMaxVertices - 2) * 3
};

// Medians over the timed repetitions, in ms: the kernel alone (device events around the launch),
// and host-to-device copy + kernel + device-to-host copy (pinned host buffers).
struct DeviceTiming {
  double kernelMs = 0, totalMs = 0;
};

// The GPU half. Each timing function warms up, then times `reps` repetitions rotating among the
// input's sets, and finally writes every set's results to the output (for the check on the CPU).
struct GeometryBenchKernels {
  std::function<bool()> available;  // a device exists
  std::function<std::string()> deviceName;
  std::function<DeviceTiming(const ContactBenchInput&, int reps, std::vector<Contact>& out)> contacts;
  std::function<DeviceTiming(const TriangulationBenchInput&, int reps, TriangulationBenchOutput& out)> triangulate;
};

void registerGeometryBenchKernels(GeometryBenchKernels kernels);
// nullptr when this build has no GPU half.
const GeometryBenchKernels* geometryBenchKernels();

struct GeometryBenchOptions {
  std::string table;        // "intersection" or "triangulation"
  std::vector<long> sizes;  // N per row; empty: the thesis's sizes (and 10^5, 10^6 pairs for intersection)
  std::string csv;          // also write the table here when not empty
  int reps = 50;            // GPU repetitions timed (median); the CPU does up to this many within a time budget
};

int runGeometryBench(const GeometryBenchOptions& options);

}  // namespace gem
