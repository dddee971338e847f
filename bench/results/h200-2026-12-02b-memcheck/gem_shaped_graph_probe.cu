// EXPERIMENT (issue 15), not for main: GEM's batch graph with the loop's body cut to the step's
// first and last kernels, rebuilt here from GEM's own types without the rest of DeviceStep.
#include <gtest/gtest.h>
#include <cub/device/device_radix_sort.cuh>
#include <vector>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "framework/cuda/device_state.cuh"
#include "framework/cuda/device_step.hpp"

namespace {
using namespace gem;
using namespace gem::cuda;
#define PCHECK(call) ASSERT_EQ((call), cudaSuccess) << #call
__global__ void touchKernel(float* a, int n) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) a[i] = a[i] * 0.5f + 1.0f;
}
__global__ void pBeginBatch(StepStats* s) {
  for (int q = 0; q < kMaxRecordStreams; ++q) s->recordCount[q] = 0;
  s->stepsDone = 0;
  s->halt = kRunning;
}
__global__ void pBeginStep(const BatchControl* c, StepStats* s, StepContext* ctx, int worlds, WorldStepRecord* worldStats) {
  for (int w = threadIdx.x; w < worlds; w += blockDim.x) worldStats[w] = WorldStepRecord{0, {0, 0}, {0, 0}, {0, 0}, 0};
  if (threadIdx.x != 0) return;
  const long step = c->firstStep + s->stepsDone;
  *ctx = StepContext{c->dt, c->dt * static_cast<Real>(step), step};
  for (int q = 0; q < kMaxRecordStreams; ++q) s->recordBegin[q] = s->recordCount[q];
  s->overflow = 0;
}
__global__ void pEndStep(cudaGraphConditionalHandle loop, const BatchControl* c, StepStats* s, StepRecord* ring, int worlds,
                         const WorldStepRecord* worldStats, WorldStepRecord* worldRing) {
  const int done = s->stepsDone;
  if (!s->overflow)
    for (int w = threadIdx.x; w < worlds; w += blockDim.x) worldRing[static_cast<size_t>(done) * worlds + w] = worldStats[w];
  __syncthreads();
  if (threadIdx.x != 0) return;
  StepRecord r{s->candidates, s->contacts, {}};
  for (int q = 0; q < kMaxRecordStreams; ++q) r.recordEnd[q] = s->recordCount[q];
  ring[s->stepsDone] = r;
  ++s->stepsDone;
  if (s->stepsDone >= c->steps) s->halt = kHaltDone;
  cudaGraphSetConditional(loop, s->halt == kRunning ? 1u : 0u);
}

TEST(MemcheckProbe, GemShapedGraph) {
  const char* mode = std::getenv("GEM_MEMCHECK_GEMGRAPH");
  if (!mode) GTEST_SKIP() << "GEM_MEMCHECK_GEMGRAPH not set";
  const std::string m = mode;
  const int ringSize = 16, worlds = 1;
  cudaStream_t stream;
  PCHECK(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking));
  StepStats* hStats;
  BatchControl* hControl;
  StepRecord* hRing;
  WorldStepRecord* hWorldRing;
  PCHECK(cudaMallocHost(&hStats, sizeof(StepStats)));
  PCHECK(cudaMallocHost(&hControl, sizeof(BatchControl)));
  PCHECK(cudaMallocHost(&hRing, sizeof(StepRecord) * ringSize));
  PCHECK(cudaMallocHost(&hWorldRing, sizeof(WorldStepRecord) * ringSize * worlds));
  StepStats* stats;
  BatchControl* control;
  StepContext* ctx;
  StepRecord* ring;
  WorldStepRecord *worldRing, *worldStats;
  PCHECK(cudaMalloc(&stats, sizeof(StepStats)));
  PCHECK(cudaMalloc(&control, sizeof(BatchControl)));
  PCHECK(cudaMalloc(&ctx, sizeof(StepContext)));
  PCHECK(cudaMalloc(&ring, sizeof(StepRecord) * ringSize));
  PCHECK(cudaMalloc(&worldRing, sizeof(WorldStepRecord) * ringSize * worlds));
  PCHECK(cudaMalloc(&worldStats, sizeof(WorldStepRecord) * worlds));
  PCHECK(cudaMemset(stats, 0, sizeof(StepStats)));
  PCHECK(cudaStreamSynchronize(cudaStreamLegacy));
  // DeviceStep's work before its first launch, by the mode's words.
  const int arrays = 40, n = 1 << 18;
  std::vector<float*> a(arrays, nullptr);
  for (auto& p : a) PCHECK(cudaMalloc(&p, n * sizeof(float)));
  if (m.find("upload") != std::string::npos) {
    std::vector<float> host(n, 0.25f);
    for (auto* p : a) PCHECK(cudaMemcpy(p, host.data(), n * sizeof(float), cudaMemcpyHostToDevice));
  }
  if (m.find("memset") != std::string::npos)
    for (auto* p : a) PCHECK(cudaMemset(p, 0, n * sizeof(float)));
  if (m.find("realloc") != std::string::npos)
    for (int k = 0; k < arrays; k += 2) {
      PCHECK(cudaFree(a[k]));
      PCHECK(cudaMalloc(&a[k], 2 * n * sizeof(float)));
    }
  if (m.find("big") != std::string::npos) {
    void* big;
    PCHECK(cudaMalloc(&big, size_t(2) << 30));
  }
  PCHECK(cudaStreamSynchronize(cudaStreamLegacy));
  if (m.find("kernels") != std::string::npos)
    for (auto* p : a) touchKernel<<<(n + 127) / 128, 128, 0, stream>>>(p, n);
  if (m.find("cub") != std::string::npos) {
    unsigned *key, *keyOut;
    int *val, *valOut;
    PCHECK(cudaMalloc(&key, n * 4));
    PCHECK(cudaMalloc(&keyOut, n * 4));
    PCHECK(cudaMalloc(&val, n * 4));
    PCHECK(cudaMalloc(&valOut, n * 4));
    PCHECK(cudaMemset(key, 0, n * 4));
    PCHECK(cudaMemset(val, 0, n * 4));
    size_t bytes = 0;
    PCHECK(cub::DeviceRadixSort::SortPairs(nullptr, bytes, key, keyOut, val, valOut, n, 0, 32, stream));
    void* temp;
    PCHECK(cudaMalloc(&temp, bytes));
    PCHECK(cudaStreamSynchronize(cudaStreamLegacy));
    PCHECK(cub::DeviceRadixSort::SortPairs(temp, bytes, key, keyOut, val, valOut, n, 0, 32, stream));
  }
  PCHECK(cudaStreamSynchronize(stream));

  cudaGraph_t graph;
  PCHECK(cudaGraphCreate(&graph, 0));
  cudaGraphNode_t controlIn, begin, loop, ringOut, worldRingOut, statsOut;
  PCHECK(cudaGraphAddMemcpyNode1D(&controlIn, graph, nullptr, 0, control, hControl, sizeof(BatchControl), cudaMemcpyHostToDevice));
  void* beginArgs[] = {&stats};
  cudaKernelNodeParams beginParams{};
  beginParams.func = reinterpret_cast<void*>(pBeginBatch);
  beginParams.gridDim = dim3(1);
  beginParams.blockDim = dim3(1);
  beginParams.kernelParams = beginArgs;
  PCHECK(cudaGraphAddKernelNode(&begin, graph, &controlIn, 1, &beginParams));
  cudaGraphConditionalHandle handle;
  PCHECK(cudaGraphConditionalHandleCreate(&handle, graph, 1, cudaGraphCondAssignDefault));
  cudaGraphNodeParams loopParams{};
  loopParams.type = cudaGraphNodeTypeConditional;
  loopParams.conditional.handle = handle;
  loopParams.conditional.type = cudaGraphCondTypeWhile;
  loopParams.conditional.size = 1;
  PCHECK(cudaGraphAddNode(&loop, graph, &begin, nullptr, 1, &loopParams));
  cudaGraph_t body = loopParams.conditional.phGraph_out[0];
  PCHECK(cudaStreamBeginCaptureToGraph(stream, body, nullptr, nullptr, 0, cudaStreamCaptureModeThreadLocal));
  pBeginStep<<<1, 32, 0, stream>>>(control, stats, ctx, worlds, worldStats);
  pEndStep<<<1, 32, 0, stream>>>(handle, control, stats, ring, worlds, worldStats, worldRing);
  PCHECK(cudaStreamEndCapture(stream, &body));
  if (m.find("noring") == std::string::npos) {
    PCHECK(cudaGraphAddMemcpyNode1D(&ringOut, graph, &loop, 1, hRing, ring, sizeof(StepRecord) * ringSize, cudaMemcpyDeviceToHost));
    PCHECK(cudaGraphAddMemcpyNode1D(&worldRingOut, graph, &loop, 1, hWorldRing, worldRing, sizeof(WorldStepRecord) * ringSize * worlds,
                                    cudaMemcpyDeviceToHost));
  }
  PCHECK(cudaGraphAddMemcpyNode1D(&statsOut, graph, &loop, 1, hStats, stats, sizeof(StepStats), cudaMemcpyDeviceToHost));
  cudaGraphExec_t exec;
  PCHECK(cudaGraphInstantiate(&exec, graph, 0));
  long next = 0;
  for (int batch = 0; batch < 200; ++batch) {
    *hControl = BatchControl{next, Real(0.1), ringSize};
    PCHECK(cudaGraphLaunch(exec, stream));
    PCHECK(cudaStreamSynchronize(stream));
    ASSERT_EQ(hStats->stepsDone, ringSize) << "batch " << batch;
    next += ringSize;
  }
  PCHECK(cudaGraphExecDestroy(exec));
  PCHECK(cudaGraphDestroy(graph));
}
}  // namespace
