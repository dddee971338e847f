// while_graph_probe.cu's "module2": a body kernel in a second module (its own translation unit, no
// -rdc), as prepare.cu is to step_graph.cu.
#include <cuda_runtime.h>
__global__ void otherKernel(float* x, int n) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) x[i] = x[i] * 0.5f + 0.25f;
}
void launchOther(float* x, int n, cudaStream_t s) { otherKernel<<<(n + 127) / 128, 128, 0, s>>>(x, n); }
