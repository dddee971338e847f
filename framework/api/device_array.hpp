// DeviceArray: the one growable device array, for a device broadphase's own storage, the CUDA
// backend's step buffers and its scratch alike (device_broadphase.hpp includes it for strategies).
#pragma once
#include <cuda_runtime.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <utility>

#include "framework/api/cuda_check.hpp"

namespace gem::cuda {

// What an array is for, which sets how it grows and whether its moves are counted.
enum class DeviceArrayUse {
  // A strategy's own storage, sized on the host outside the graph (device_broadphase.hpp): grows
  // to n + n/2 + 64. A strategy learns of a move from ensure()'s result.
  Storage,
  // A buffer of the CUDA backend's step graph (framework/cuda/device_state.cuh): grows to
  // max(n + n/2, 64), and every reallocation counts in graphArrayReallocations().
  Graph,
  // Scratch outside the graph (the backend's re-sort and topology edits): grows to n + n/2 + 4096,
  // room to spare, and is not counted, so growing it never looks like a change of the graph's buffers.
  Scratch,
};

// Reallocations of every Graph array: a captured graph holds the buffers' addresses, so a change of
// this count means the graph must be captured again.
inline std::atomic<unsigned long>& graphArrayReallocations() {
  static std::atomic<unsigned long> count{0};
  return count;
}

// A device array that only grows (reused step after step: no allocation in the steady state).
template <class T, DeviceArrayUse Use = DeviceArrayUse::Storage>
class DeviceArray {
 public:
  DeviceArray() = default;
  // Exactly n elements (one at least), for an array of a fixed size.
  explicit DeviceArray(size_t n) { allocate(std::max<size_t>(n, 1)); }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;
  ~DeviceArray() {
    if (m_data) cudaFree(m_data);  // no throw from a destructor
  }
  // Room for n elements. True when it had to reallocate (the old contents are gone).
  bool ensure(size_t n) {
    if (n <= m_capacity) return false;
    allocate(grown(n));
    return true;
  }
  // The same, keeping the first `keep` elements (the previous step's contact keys survive a regrowth).
  bool ensureKeeping(size_t n, size_t keep) {
    if (n <= m_capacity) return false;
    DeviceArray bigger;
    bigger.ensure(n);
    if (keep && m_data) GEM_CUDA_CHECK(cudaMemcpy(bigger.m_data, m_data, keep * sizeof(T), cudaMemcpyDeviceToDevice));
    swap(bigger);
    return true;
  }
  void upload(const T* h_data, size_t n) {
    ensure(n);
    if (n) GEM_CUDA_CHECK(cudaMemcpy(m_data, h_data, n * sizeof(T), cudaMemcpyHostToDevice));
  }
  // Rows [offset, offset + n) from the host; the array already holds them.
  void uploadAt(size_t offset, const T* h_data, size_t n) {
    if (n) GEM_CUDA_CHECK(cudaMemcpy(m_data + offset, h_data, n * sizeof(T), cudaMemcpyHostToDevice));
  }
  void download(T* h_data, size_t n) const {
    if (n) GEM_CUDA_CHECK(cudaMemcpy(h_data, m_data, n * sizeof(T), cudaMemcpyDeviceToHost));
  }
  void swap(DeviceArray& other) {
    std::swap(m_data, other.m_data);
    std::swap(m_capacity, other.m_capacity);
  }
  T* get() const { return m_data; }
  size_t capacity() const { return m_capacity; }

 private:
  static size_t grown(size_t n) {
    if constexpr (Use == DeviceArrayUse::Graph)
      return std::max<size_t>(n + n / 2, 64);
    else if constexpr (Use == DeviceArrayUse::Scratch)
      return n + n / 2 + 4096;
    else
      return n + n / 2 + 64;
  }
  void allocate(size_t capacity) {
    if (m_data) GEM_CUDA_CHECK(cudaFree(m_data));
    m_data = nullptr;
    m_capacity = 0;  // a failed cudaMalloc leaves an empty array
    GEM_CUDA_CHECK(cudaMalloc(&m_data, capacity * sizeof(T)));
    m_capacity = capacity;
    if constexpr (Use == DeviceArrayUse::Graph) ++graphArrayReallocations();
  }

  T* m_data = nullptr;
  size_t m_capacity = 0;
};

}  // namespace gem::cuda
