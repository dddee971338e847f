// The CPU stepper's threads (simulation.threads), lent to the host code it calls: a broadphase's
// build and filter split their work over contiguous ranges with parallelRanges() and join the
// ranges' results in range order, so what they produce is the same whatever the thread count
// (docs/architecture.md "Determinism"). Without a runner on the calling thread (a test, the
// initial overlap check, the CUDA backend's host mirror) parallelRanges() is a plain call.
//
// Not part of the plugin ABI: nothing here travels in a struct a plugin reads, and a plugin built
// without it simply runs on one thread.
#pragma once
#include <functional>

namespace gem {

// What runs tasks on several threads (the CPU stepper's pool). run() returns when every task has
// ended and rethrows the first exception a task threw.
class ParallelRunner {
 public:
  virtual ~ParallelRunner() = default;
  virtual int size() const = 0;  // threads, the caller's included
  virtual void run(int tasks, const std::function<void(int)>& task) = 0;
};

// While one is alive on this thread, parallelRanges() there runs on `runner` (null: one thread).
class ParallelScope {
 public:
  explicit ParallelScope(ParallelRunner* runner);
  ~ParallelScope();
  ParallelScope(const ParallelScope&) = delete;
  ParallelScope& operator=(const ParallelScope&) = delete;

 private:
  ParallelRunner* m_previous;
};

// How many tasks a round of work is cut into at most, per thread. Threads take tasks one at a time
// until none is left, so a round ends at most one task after the last thread starts its final
// one; but each task costs a call, a counter and, in most phases, a part of its own to join. 16 a
// thread was tried (2026-12-05): no gain beyond the noise on 16 Xeon threads, and 3 % slower at 10^5
// floes on the development machine's 2 (docs/performance.md 3.10).
constexpr int kTasksPerThread = 4;

// Tasks a thread for a pass whose work crowds into a few stretches of its items (a resting pack's
// few moving bodies around the vessel): finer ranges let the threads share those stretches out.
constexpr int kCrowdedTasksPerThread = 16;

// How many ranges parallelRanges(n, grain, ...) cuts [0, n) into: 1 without a runner or when n is
// under 4 grains (then waking threads costs more than the work), else at most `perThread` per
// thread and at least `grain` items each. A caller sizes its per-range buffers with it.
int parallelTasks(long n, int grain, int perThread = kTasksPerThread);

// range(task, begin, end) for task 0 .. tasks - 1, over contiguous ranges that cover [0, n) in
// order, on the runner's threads; tasks is parallelTasks(n, grain, perThread). Returns tasks.
int parallelRanges(long n, int grain, const std::function<void(int, long, long)>& range, int perThread = kTasksPerThread);
// The same two for a crowded pass: kCrowdedTasksPerThread ranges a thread at most. A caller that
// sizes buffers for parallelCrowdedRanges sizes them with parallelCrowdedTasks.
inline int parallelCrowdedTasks(long n, int grain) { return parallelTasks(n, grain, kCrowdedTasksPerThread); }
inline int parallelCrowdedRanges(long n, int grain, const std::function<void(int, long, long)>& range) {
  return parallelRanges(n, grain, range, kCrowdedTasksPerThread);
}

// task(0 .. tasks - 1) on the runner's threads, however few the tasks (a pass over parts that
// parallelRanges made earlier).
void parallelEach(int tasks, const std::function<void(int)>& task);

}  // namespace gem
