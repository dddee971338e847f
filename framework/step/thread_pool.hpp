// A fixed pool of threads for the CPU stepper's parallel phases (simulation.threads). The caller
// is one of the threads: run(tasks, task) hands task(0 .. tasks - 1) out over all of them and
// returns when every one is done. Which thread runs a task never matters to the results: each
// task writes its own part, and the stepper joins the parts in task order (docs/architecture.md
// "Determinism").
#pragma once
#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace gem {

class ThreadPool {
 public:
  // threads: all of them, the caller included (at least 1: then run() is a plain loop).
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return static_cast<int>(m_workers.size()) + 1; }
  // Only tasks - 1 workers are woken to take part (fewer tasks than threads, fewer threads busy).
  // The first exception a task threw is rethrown here, once every task has ended.
  void run(int tasks, const std::function<void(int)>& task);

 private:
  void work(int index);
  void drain();

  std::vector<std::thread> m_workers;
  std::mutex m_mutex;
  std::condition_variable m_wake, m_done;
  const std::function<void(int)>* m_task = nullptr;
  int m_tasks = 0;
  std::atomic<int> m_next{0};
  int m_participants = 0;  // the workers taking part in the current round: the first tasks - 1
  int m_running = 0;       // of them, those that have not ended it
  long m_round = 0;
  bool m_stop = false;
  std::exception_ptr m_error;
};

// The threads a run uses for simulation.threads = `requested` (0: every core of the machine).
int threadsFor(int requested);

}  // namespace gem
