// A GEM-free probe of compute-sanitizer memcheck on a CUDA graph with a device-side WHILE loop,
// built the way GEM's step graph is (framework/cuda/step_graph.cu): a copy in from pinned memory,
// a reset kernel, a WHILE node whose body is captured from a non-blocking stream (kernels over
// buffers cudaMalloc'd just before the capture, a CUB radix sort, a last kernel that sets the
// condition), and copies out to pinned memory. Each round allocates fresh buffers, captures,
// launches a few batches and frees, like the CUDA tests' simulations do. A second argument adds to
// the loop's body a kernel with a deep stack ("stack"), a memset node ("memset"), 60 kernels a
// step ("wide"), GEM's prepare kernel's parameter shape ("many"); or, as words anywhere in it, a
// kernel with double cos/sin ("trig"), a kernel of a second module ("module2", second_module.cu),
// and the condition set as GEM's last step kernel sets it, thread 0 of 32 after a barrier ("edge32").
// Build: nvcc -O2 -arch=sm_90 -o while_graph_probe while_graph_probe.cu second_module.cu
// (-DPROBE_NO_MAIN leaves out main, to call whileGraphProbe from a test of another program).
//
// Used by scripts/memcheck-loop.sh: if this probe, which shares no code with GEM, reports an
// error under several sanitized processes at once, the report is the tool's, not GEM's.
// Exit 0 when every batch ran and every result is right; 1 on a wrong result; 2 on a CUDA error.
#include <cub/device/device_radix_sort.cuh>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#define CHECK(call)                                                                               \
  do {                                                                                            \
    cudaError_t e_ = (call);                                                                      \
    if (e_ != cudaSuccess) {                                                                      \
      std::fprintf(stderr, "%s:%d: %s: %s\n", __FILE__, __LINE__, #call, cudaGetErrorString(e_)); \
      std::exit(2);                                                                               \
    }                                                                                             \
  } while (0)

struct Control {
  int steps;
};
struct Stats {
  int done;
  unsigned long long checksum;
};

__global__ void beginKernel(Stats* s) { s->done = 0, s->checksum = 0; }
__global__ void keysKernel(const float* x, unsigned* key, int* value, int n, int step) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) key[i] = (static_cast<unsigned>(x[i] * 1000.0f) + static_cast<unsigned>(step) * 7919u) & 0xffffu, value[i] = i;
}
__global__ void moveKernel(float* x, const int* order, const unsigned* sortedKey, int n, Stats* s) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  x[i] = x[i] * 0.999f + 0.001f;
  if (i == 0) atomicAdd(&s->checksum, static_cast<unsigned long long>(sortedKey[0]) + static_cast<unsigned long long>(order[n - 1] >= 0));
}
// A kernel with a deep per-thread stack (a dynamically indexed local array), like GEM's
// narrowphase with its clipping buffers: run in the loop's body with the probe's "stack" argument.
__global__ void stackKernel(float* x, int n, int step) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  volatile float local[640];  // volatile: kept in local memory, not folded away
  for (int k = 0; k < 640; ++k) local[k] = x[i] + static_cast<float>(k);
  x[i] = local[(i + step) % 640] * 1e-6f + x[i] * 0.5f;
}
// A kernel with GEM's prepare phase's shape: a 288-byte parameter struct naming 36 separate
// allocations, each read and written by every thread.
constexpr int kManyArrays = 36;
struct ManyArrays {
  float* a[kManyArrays];
};
__global__ void manyArraysKernel(ManyArrays m, int n) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float sum = 0;
  for (int k = 0; k < kManyArrays; ++k) sum += m.a[k][i];
  for (int k = 0; k < kManyArrays; ++k) m.a[k][i] = sum * 1e-3f;
}
// GEM's prepare reads its module's libdevice table (__cudart_sin_cos_coeffs) through double cos/sin.
__global__ void trigKernel(float* x, double* angle, int n) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const double c = cos(angle[i]), s = sin(angle[i]);
  angle[i] += 1e-3;
  x[i] = static_cast<float>(x[i] * c + 1e-3 * s);
}
void launchOther(float* x, int n, cudaStream_t s);
__global__ void endKernel(cudaGraphConditionalHandle loop, const Control* c, Stats* s) {
  __syncthreads();
  if (threadIdx.x != 0) return;
  ++s->done;
  cudaGraphSetConditional(loop, s->done < c->steps ? 1u : 0u);
}

int whileGraphProbe(int argc, char** argv) {
  const int rounds = argc > 1 ? std::atoi(argv[1]) : 8;
  const bool deepStack = argc > 2 && std::string(argv[2]) == "stack";
  const bool memsetNode = argc > 2 && std::string(argv[2]) == "memset";                  // a memset node in the loop's body
  const bool many = argc > 2 && std::string(argv[2]) == "many";                          // GEM's prepare kernel's shape
  const bool wide = argc > 2 && std::string(argv[2]) == "wide";                          // 60 kernels a step, as many as GEM's step
  const bool trig = argc > 2 && std::string(argv[2]).find("trig") != std::string::npos;  // double cos/sin: module-global table reads
  const bool edge32 = argc > 2 && std::string(argv[2]).find("edge32") != std::string::npos;
  const bool module2 = argc > 2 && std::string(argv[2]).find("module2") != std::string::npos;  // a body kernel from a second module
  cudaStream_t stream;
  CHECK(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking));
  Control* hControl;
  Stats* hStats;
  CHECK(cudaMallocHost(&hControl, sizeof(Control)));
  CHECK(cudaMallocHost(&hStats, sizeof(Stats)));
  for (int round = 0; round < rounds; ++round) {
    const int n = 4096 + 1024 * round;  // sizes change from round to round, as worlds do
    float* x;
    unsigned *key, *keySorted;
    int *value, *valueSorted;
    Control* control;
    Stats* stats;
    CHECK(cudaMalloc(&x, n * sizeof(float)));
    CHECK(cudaMalloc(&key, n * sizeof(unsigned)));
    CHECK(cudaMalloc(&keySorted, n * sizeof(unsigned)));
    CHECK(cudaMalloc(&value, n * sizeof(int)));
    CHECK(cudaMalloc(&valueSorted, n * sizeof(int)));
    CHECK(cudaMalloc(&control, sizeof(Control)));
    CHECK(cudaMalloc(&stats, sizeof(Stats)));
    double* angle;
    CHECK(cudaMalloc(&angle, n * sizeof(double)));
    CHECK(cudaMemset(angle, 0, n * sizeof(double)));
    std::vector<float> hx(n, 0.5f);
    CHECK(cudaMemcpy(x, hx.data(), n * sizeof(float), cudaMemcpyHostToDevice));  // legacy stream, as GEM's uploads
    size_t tempBytes = 0;
    CHECK(cub::DeviceRadixSort::SortPairs(nullptr, tempBytes, key, keySorted, value, valueSorted, n, 0, 16, stream));
    void* temp;
    CHECK(cudaMalloc(&temp, tempBytes));
    CHECK(cudaStreamSynchronize(stream));
    CHECK(cudaStreamSynchronize(cudaStreamLegacy));

    ManyArrays arrays{};
    for (int k = 0; many && k < kManyArrays; ++k) {
      CHECK(cudaMalloc(&arrays.a[k], n * sizeof(float)));
      CHECK(cudaMemset(arrays.a[k], 0, n * sizeof(float)));
    }
    if (many) CHECK(cudaDeviceSynchronize());
    cudaGraph_t graph;
    CHECK(cudaGraphCreate(&graph, 0));
    cudaGraphNode_t in, begin, loop, out;
    CHECK(cudaGraphAddMemcpyNode1D(&in, graph, nullptr, 0, control, hControl, sizeof(Control), cudaMemcpyHostToDevice));
    void* beginArgs[] = {&stats};
    cudaKernelNodeParams beginParams{};
    beginParams.func = reinterpret_cast<void*>(beginKernel);
    beginParams.gridDim = dim3(1);
    beginParams.blockDim = dim3(1);
    beginParams.kernelParams = beginArgs;
    CHECK(cudaGraphAddKernelNode(&begin, graph, &in, 1, &beginParams));
    cudaGraphConditionalHandle handle;
    CHECK(cudaGraphConditionalHandleCreate(&handle, graph, 1, cudaGraphCondAssignDefault));
    cudaGraphNodeParams loopParams{};
    loopParams.type = cudaGraphNodeTypeConditional;
    loopParams.conditional.handle = handle;
    loopParams.conditional.type = cudaGraphCondTypeWhile;
    loopParams.conditional.size = 1;
    CHECK(cudaGraphAddNode(&loop, graph, &begin, nullptr, 1, &loopParams));
    cudaGraph_t body = loopParams.conditional.phGraph_out[0];
    CHECK(cudaStreamBeginCaptureToGraph(stream, body, nullptr, nullptr, 0, cudaStreamCaptureModeThreadLocal));
    const int blocks = (n + 127) / 128;
    if (memsetNode) CHECK(cudaMemsetAsync(key, 0xff, n * sizeof(unsigned), stream));
    keysKernel<<<blocks, 128, 0, stream>>>(x, key, value, n, round);
    CHECK(cub::DeviceRadixSort::SortPairs(temp, tempBytes, key, keySorted, value, valueSorted, n, 0, 16, stream));
    moveKernel<<<blocks, 128, 0, stream>>>(x, valueSorted, keySorted, n, stats);
    if (deepStack) stackKernel<<<blocks, 128, 0, stream>>>(x, n, round);
    if (many) manyArraysKernel<<<blocks, 128, 0, stream>>>(arrays, n);
    if (trig) trigKernel<<<blocks, 128, 0, stream>>>(x, angle, n);
    if (module2) launchOther(x, n, stream);
    for (int k = 0; wide && k < 60; ++k) stackKernel<<<blocks, 128, 0, stream>>>(x, n, round + k);
    endKernel<<<1, edge32 ? 32 : 1, 0, stream>>>(handle, control, stats);
    CHECK(cudaStreamEndCapture(stream, &body));
    CHECK(cudaGraphAddMemcpyNode1D(&out, graph, &loop, 1, hStats, stats, sizeof(Stats), cudaMemcpyDeviceToHost));
    cudaGraphExec_t exec;
    CHECK(cudaGraphInstantiate(&exec, graph, 0));
    for (int batch = 0; batch < 4; ++batch) {
      hControl->steps = 16 + batch;
      CHECK(cudaGraphLaunch(exec, stream));
      CHECK(cudaStreamSynchronize(stream));
      if (hStats->done != hControl->steps) {
        std::fprintf(stderr, "round %d batch %d: %d steps done, %d asked\n", round, batch, hStats->done, hControl->steps);
        return 1;
      }
    }
    CHECK(cudaGraphExecDestroy(exec));
    CHECK(cudaGraphDestroy(graph));
    for (void* p : {static_cast<void*>(x), static_cast<void*>(key), static_cast<void*>(keySorted), static_cast<void*>(value),
                    static_cast<void*>(valueSorted), static_cast<void*>(control), static_cast<void*>(stats), temp})
      CHECK(cudaFree(p));
    for (int k = 0; many && k < kManyArrays; ++k) CHECK(cudaFree(arrays.a[k]));
    CHECK(cudaFree(angle));
  }
  std::printf("while_graph_probe: %d rounds, every batch ran its steps\n", rounds);
  return 0;
}

#ifndef PROBE_NO_MAIN
int main(int argc, char** argv) { return whileGraphProbe(argc, argv); }
#endif
