// Internal to framework/cuda: what the files of a step share. CubCalls, the function each phase's
// file gives the step graph to enqueue its kernels, and the grid's hash (phase 1 and the grid).
#pragma once
#include <cuda_runtime.h>

#include <cmath>
#include <cstddef>

#include "framework/cuda/device_state.cuh"

namespace gem::cuda {

// The CUB calls of a step, for a fixed n and capacity: run with temp == nullptr they only add up
// the scratch they need (so every buffer exists before the capture), then for real (step_graph.cu).
struct CubCalls {
  DeviceState& d;
  void* temp;
  size_t& bytes;  // in: available (real run); out: the largest need (sizing run)
  bool sizing;

  // need by reference: read after the CUB call has written it (argument order is unspecified).
  void check(cudaError_t status, const size_t& need, const char* what);
  void cellSort(int n, int bits);
  void scanPartners(int n);
  void sortCandidates(int capacity, int bits);
  void scanFlags(int capacity);
  void sortKeys(int capacity, int bits);
  void sortB(int capacity, int bits);
};

// The phases, each enqueued on d.stream by the file that holds its kernels, in the order
// step_graph.cu's enqueueStep calls them.
// 1. World vertices, boxes, views, cell keys (prepare.cu). largeKey: the cell key of a large body.
void enqueuePrepare(DeviceState& d, unsigned largeKey);
// 2. The candidate pairs, sorted by (a, b): a device strategy's, or the step's own hashed grid
// (broadphase_grid.cu). Returns the device count of candidates the phase needed.
const int* enqueueBroadphase(DeviceState& d, CubCalls& cubCalls, unsigned largeKey);
// 3. Narrowphase, compaction in order (with padding), onset, the two sorts (contacts.cu).
void enqueueContacts(DeviceState& d, CubCalls& cubCalls, const int* candidatesNeeded);
// 5. The impulses gathered per body, then the motion written back (gather.cu).
void enqueueGather(DeviceState& d);
void enqueueWriteBack(DeviceState& d);
// This step's contact keys become the next step's "previous" (contacts.cu).
void enqueueCommitContacts(DeviceState& d);
// After the ids outgrew the contact key's field: re-keys the kept pairs, on the host's schedule
// (contacts.cu; sizeForBodies calls it).
void rekeyContacts(DeviceState& d, int newBits);

// The resident driver's batch of steps, in place of the step graph's (resident.cu).
void runResident(DeviceState& d, long firstStep, Real dt, int steps, DeviceBatchResult& result);

// A large body's row is split into chunks of kLargeChunk bodies (broadphase_grid.cu says why);
// sizeForBodies sizes the chunk counts.
constexpr int kLargeChunk = 256;
inline int largeChunks(int n) { return (n + kLargeChunk - 1) / kLargeChunk; }

#if defined(__CUDACC__)
// A coordinate as an integer of the same order (min and max by integer atomics are then exact, as
// the host's loop): doubles keep every float and coordinate exactly. The re-sort along the curve's
// box of centroids, on the device-wide driver (edits.cu) and in the resident kernel.
__device__ inline unsigned long long orderedRealBits(Real v) {
  const unsigned long long u = static_cast<unsigned long long>(__double_as_longlong(static_cast<double>(v)));
  return (u >> 63) ? ~u : u | (1ull << 63);
}
__device__ inline Real fromOrderedRealBits(unsigned long long u) {
  return static_cast<Real>(__longlong_as_double(static_cast<long long>((u >> 63) ? u & ~(1ull << 63) : ~u)));
}

__device__ inline long long cellCoord(Real v, Real cell) { return static_cast<long long>(floor(v / cell)); }

// A cell of one world: the worlds of a batch share the table (world 0 hashes as a lone run did).
__device__ inline unsigned cellHash(long long cx, long long cy, int world, unsigned mask) {
  return (static_cast<unsigned>(cx) * 73856093u ^ static_cast<unsigned>(cy) * 19349663u ^ static_cast<unsigned>(world) * 83492791u) & mask;
}
#endif

}  // namespace gem::cuda
