#include "framework/step/thread_pool.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

namespace gem {

int threadsFor(int requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace {

// How long a thread spins for a round (or for its end) before it sleeps. Long enough to cover the
// gaps between the rounds of one step at 10^5 floes (tens to hundreds of microseconds), short
// enough that a thread waiting through the single-threaded parts of a step (the pair events, a
// large broadphase rebuild's sort) soon gives its core back to the machine.
constexpr auto kSpinBudget = std::chrono::microseconds(100);

inline void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

// Spins until ready() or the budget is spent; true when ready.
template <class Ready>
bool spinUntil(Ready ready) {
  const auto until = std::chrono::steady_clock::now() + kSpinBudget;
  for (;;) {
    for (int k = 0; k < 64; ++k) {
      if (ready()) return true;
      cpuRelax();
    }
    if (std::chrono::steady_clock::now() > until) return ready();
  }
}

}  // namespace

ThreadPool::ThreadPool(int threads)
    : m_groups(static_cast<size_t>(threads < 1 ? 1 : threads)), m_times(static_cast<size_t>(threads < 1 ? 1 : threads)) {
  for (int t = 1; t < threads; ++t) m_workers.emplace_back([this, t] { work(t - 1); });
}

ThreadPool::~ThreadPool() {
  m_stop.store(true);
  { std::lock_guard<std::mutex> lock(m_mutex); }  // a worker between its check and its wait is then waiting
  m_wake.notify_all();
  for (std::thread& t : m_workers) t.join();
}

// Tasks are taken one at a time, first from the thread's own group, then from the others' in
// turn, until none is left.
void ThreadPool::drain(int self) {
  ThreadTimes* times = m_measuring ? &m_times[static_cast<size_t>(self)] : nullptr;
  const int groups = m_groupCount;
  const int own = self < groups - 1 ? self : groups - 1;  // the caller (and only it) takes the last group
  for (int step = 0; step < groups; ++step) {
    Group& group = m_groups[static_cast<size_t>((own + step) % groups)];
    for (int k = group.next++; k < group.end; k = group.next++) {
      try {
        if (times) {
          const auto start = std::chrono::steady_clock::now();
          (*m_task)(k);
          const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          times->busy += took, times->longest = std::max(times->longest, took), ++times->tasks;
        } else {
          (*m_task)(k);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_error) m_error = std::current_exception();
      }
    }
  }
}

void ThreadPool::work(int index) {
  std::uint64_t seen = 0;  // the last round this worker noted
  auto fresh = [&] { return m_stop.load() || m_round.load() / kRoundUnit != seen; };
  for (;;) {
    if (!spinUntil(fresh)) {
      std::unique_lock<std::mutex> lock(m_mutex);
      ++m_sleepingWorkers;  // then the check in wait(): the caller sees the sleeper, or this the round
      m_wake.wait(lock, fresh);
      --m_sleepingWorkers;
    }
    if (m_stop.load()) return;
    // The newest round: a round cannot pass while one of its workers has not ended it, so a worker
    // that takes part in a round always sees it; one that does not may miss it, which is harmless.
    const std::uint64_t word = m_round.load();
    seen = word / kRoundUnit;
    if (index >= static_cast<int>(word % kRoundUnit)) continue;
    drain(index);
    if (m_running.fetch_sub(1) == 1 && m_callerSleeping.load()) {
      std::lock_guard<std::mutex> lock(m_mutex);
      m_done.notify_one();
    }
  }
}

void ThreadPool::run(int tasks, const std::function<void(int)>& task) {
  if (m_workers.empty() || tasks <= 1) {
    for (int k = 0; k < tasks; ++k) task(k);
    return;
  }
  // No worker is in a round here (the last one ended before the previous run() returned), so the
  // round's fields are written plainly; the store of the round word publishes them.
  std::chrono::steady_clock::time_point published, callerDone;
  if (m_measuring) {
    published = std::chrono::steady_clock::now();
    for (ThreadTimes& t : m_times) t = ThreadTimes{};
  }
  m_task = &task;
  m_tasks = tasks;
  m_error = nullptr;
  const int participants = std::min(static_cast<int>(m_workers.size()), tasks - 1);
  m_groupCount = participants + 1;
  for (int g = 0; g < m_groupCount; ++g) {
    Group& group = m_groups[static_cast<size_t>(g)];
    group.next.store(static_cast<int>(static_cast<long>(tasks) * g / m_groupCount), std::memory_order_relaxed);
    group.end = static_cast<int>(static_cast<long>(tasks) * (g + 1) / m_groupCount);
  }
  m_running.store(participants);
  m_round.store((m_round.load() / kRoundUnit + 1) * kRoundUnit + static_cast<std::uint64_t>(participants));
  if (m_sleepingWorkers.load() > 0) {
    { std::lock_guard<std::mutex> lock(m_mutex); }
    m_wake.notify_all();
  }
  drain(static_cast<int>(m_workers.size()));  // the caller's group is the last
  if (m_measuring) callerDone = std::chrono::steady_clock::now();
  if (!spinUntil([&] { return m_running.load() == 0; })) {
    std::unique_lock<std::mutex> lock(m_mutex);
    m_callerSleeping.store(true);  // then the check in wait(): the last worker sees it, or this its end
    m_done.wait(lock, [&] { return m_running.load() == 0; });
    m_callerSleeping.store(false);
  }
  m_task = nullptr;
  if (m_measuring) {  // every worker's times were written before its decrement of m_running, which this saw
    const auto end = std::chrono::steady_clock::now();
    ++m_stats.rounds;
    m_stats.inRounds += std::chrono::duration<double>(end - published).count();
    m_stats.tail += std::chrono::duration<double>(end - callerDone).count();
    double longest = 0;
    for (const ThreadTimes& t : m_times) m_stats.busy += t.busy, m_stats.tasks += t.tasks, longest = std::max(longest, t.longest);
    m_stats.longestTask += longest;
  }
  // Every task's error was stored before its worker's decrement of m_running, which this saw.
  if (std::exception_ptr error = std::exchange(m_error, nullptr)) std::rethrow_exception(error);
}

}  // namespace gem
