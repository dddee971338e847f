// A fixed pool of threads for the CPU stepper's parallel phases (simulation.threads). The caller
// is one of the threads: run(tasks, task) hands task(0 .. tasks - 1) out over all of them and
// returns when every one is done. Which thread runs a task never matters to the results: each
// task writes its own part, and the stepper joins the parts in task order (docs/architecture.md
// "Determinism").
//
// A round is cheap (docs/performance.md 3.8): the caller publishes it by bumping one atomic word
// (the round's number and how many workers take part), the workers spin on that word for a short
// while before they sleep on a condition variable, and the caller, which takes tasks too, spins on
// the count of workers still busy the same way. A step at 10^5 floes runs about ten rounds, most of
// them a few hundred microseconds apart: the workers then never sleep, and a round costs a few
// cache-line transfers instead of a mutex, a futex wake and a context switch per worker.
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "framework/api/parallel.hpp"

namespace gem {

class ThreadPool final : public ParallelRunner {
 public:
  // threads: all of them, the caller included (at least 1: then run() is a plain loop).
  explicit ThreadPool(int threads);
  ~ThreadPool() override;
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const override { return static_cast<int>(m_workers.size()) + 1; }
  // Only tasks - 1 workers are woken to take part (fewer tasks than threads, fewer threads busy).
  // The first exception a task threw is rethrown here, once every task has ended.
  void run(int tasks, const std::function<void(int)>& task) override;

  // GEM_CPU_TIMING=1: where the rounds' time goes (docs/performance.md 1.4). Off, a round reads no
  // clock; on, each task is timed, which costs two clock reads a task.
  struct Stats {
    long rounds = 0, tasks = 0;
    double inRounds = 0;     // s, the caller's time from publishing a round to its end
    double tail = 0;         // s, of it after the caller found no task left: waiting on the last tasks
    double longestTask = 0;  // s, each round's longest task, summed over the rounds
    double busy = 0;         // s, all threads' time inside tasks
  };
  void setMeasuring(bool on) { m_measuring = on; }
  const Stats& stats() const { return m_stats; }
  void resetStats() { m_stats = {}; }

 private:
  void work(int index);
  void drain(int self);

  // The round word: the round's number times kRoundUnit plus the number of workers taking part
  // (the first of them by index). One word, so a worker never pairs one round's number with
  // another's participants.
  static constexpr std::uint64_t kRoundUnit = 1u << 16;

  std::vector<std::thread> m_workers;
  // Read by the workers only after they see a new round word (release / acquire), written by the
  // caller only while no worker is in a round.
  const std::function<void(int)>* m_task = nullptr;
  int m_tasks = 0;
  alignas(64) std::atomic<std::uint64_t> m_round{0};
  // The round's tasks in one contiguous group per taking thread: a thread takes its own group's
  // tasks first, in order, then the other groups' (threads that run out help the rest). A phase
  // cuts its work into ranges in order, so the same thread takes the same stretch of the field in
  // every phase and step, and can find it in its own cache (with one shared counter, which thread
  // took which range changed every round). On a 16-thread Xeon it changed the step by less than the
  // noise (docs/performance.md 3.16).
  struct alignas(64) Group {
    std::atomic<int> next{0};
    int end = 0;
  };
  std::vector<Group> m_groups;                // one per thread, the caller's last
  int m_groupCount = 0;                       // this round's
  alignas(64) std::atomic<int> m_running{0};  // the round's workers that have not ended it
  // Sleepers: the workers waiting on m_wake, and whether the caller waits on m_done. The side that
  // changes the condition checks them afterwards and takes the mutex to notify only when someone
  // sleeps (both sides use sequentially consistent operations, so one of them always sees the other).
  alignas(64) std::atomic<int> m_sleepingWorkers{0};
  std::atomic<bool> m_callerSleeping{false};
  std::atomic<bool> m_stop{false};
  std::mutex m_mutex;
  std::condition_variable m_wake, m_done;
  std::exception_ptr m_error;  // under m_mutex
  // Per thread (the workers by index, the caller last), written by that thread during a round and
  // read by the caller after it: its time inside tasks and its longest task of the round.
  struct alignas(64) ThreadTimes {
    double busy = 0, longest = 0;
    long tasks = 0;
  };
  bool m_measuring = false;
  std::vector<ThreadTimes> m_times;
  Stats m_stats;
};

// The threads a run uses for simulation.threads = `requested` (0: every core of the machine).
int threadsFor(int requested);

}  // namespace gem
