// Issue "CPU speed", 2026-12-07 (session 29): World::curveOrder timed alone, 10^5 bodies at random
// in a 1,000 m square, on THREADS threads of the CPU stepper's pool (argument, default 1): the best
// and the mean of 30 calls after 10. Built against a build's library from the repository root:
//   g++ -O2 -std=c++20 -I. bench/results/cpu-2026-12-07c-threads/curve_order_timing.cpp \
//       -Lbuild -lgem_core -Wl,-rpath,$PWD/build -o /tmp/curve_order_timing
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "framework/step/thread_pool.hpp"
#include "framework/world/world.hpp"

int main(int argc, char** argv) {
  using namespace gem;
  const int n = 100000, threads = argc > 1 ? std::atoi(argv[1]) : 1;
  World w;
  std::mt19937 random(1);
  std::uniform_real_distribution<double> at(0, 1000);
  w.x.resize(n), w.y.resize(n), w.id.resize(n);
  for (int i = 0; i < n; ++i) w.x[i] = at(random), w.y[i] = at(random);
  ThreadPool pool(threads);
  World::TaskRunner run;
  if (threads > 1) run = [&](int count, const std::function<void(int)>& task) { pool.run(count, task); };
  double best = 1e9, sum = 0;
  long check = 0;
  for (int k = 0; k < 40; ++k) {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<int> order = w.curveOrder(run);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    best = std::min(best, s);
    if (k >= 10) sum += s;
    check += order[static_cast<size_t>(k)];
  }
  std::printf("threads %d: best %.3f ms, mean %.3f ms (check %ld)\n", threads, best * 1e3, sum / 30 * 1e3, check);
}
