// The memory a machine gives one to N threads: c[i] = a[i] + 1.5 b[i] over 64 MB arrays (three
// streams), each thread its own contiguous share, best of 10 passes. Prints GB/s per thread count.
// Build: g++ -O2 -pthread stream.cpp -o stream; run: stream 1 2 4 8 16
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

int main(int argc, char** argv) {
  const size_t n = size_t(8) << 20;  // 8 M doubles: 64 MB an array
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 0.0);
  for (int arg = 1; arg < argc; ++arg) {
    const int threads = std::atoi(argv[arg]);
    double best = 1e30;
    for (int pass = 0; pass < 10; ++pass) {
      const auto t0 = std::chrono::steady_clock::now();
      std::vector<std::thread> pool;
      for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
          const size_t begin = n * t / threads, end = n * (t + 1) / threads;
          for (size_t i = begin; i < end; ++i) c[i] = a[i] + 1.5 * b[i];
        });
      for (std::thread& t : pool) t.join();
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf("%d threads: %.1f GB/s (c[0] %.1f)\n", threads, 3.0 * 8 * n / best / 1e9, c[0]);
  }
}
