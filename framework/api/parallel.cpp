#include "framework/api/parallel.hpp"

#include <algorithm>

namespace gem {

namespace {
thread_local ParallelRunner* t_runner = nullptr;
}

ParallelScope::ParallelScope(ParallelRunner* runner) : m_previous(t_runner) { t_runner = runner; }

ParallelScope::~ParallelScope() { t_runner = m_previous; }

int parallelTasks(long n, int grain, int perThread) {
  if (!t_runner || t_runner->size() <= 1 || n < 4L * grain) return 1;
  return static_cast<int>(std::min<long>(n / grain, static_cast<long>(perThread) * t_runner->size()));
}

void parallelEach(int tasks, const std::function<void(int)>& task) {
  if (!t_runner || t_runner->size() <= 1 || tasks <= 1) {
    for (int t = 0; t < tasks; ++t) task(t);
    return;
  }
  ParallelRunner* runner = t_runner;
  const ParallelScope inner(nullptr);
  runner->run(tasks, task);
}

int parallelRanges(long n, int grain, const std::function<void(int, long, long)>& range, int perThread) {
  const int tasks = parallelTasks(n, grain, perThread);
  if (tasks <= 1) {
    range(0, 0, n);
    return 1;
  }
  // A range that asks for ranges again gets one thread: the runner is not re-entrant.
  ParallelRunner* runner = t_runner;
  const ParallelScope inner(nullptr);
  runner->run(tasks, [&](int t) { range(t, n * t / tasks, n * (t + 1) / tasks); });
  return tasks;
}

}  // namespace gem
