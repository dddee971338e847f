#include "framework/step/thread_pool.hpp"

#include <algorithm>

namespace gem {

int threadsFor(int requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

ThreadPool::ThreadPool(int threads) {
  for (int t = 1; t < threads; ++t) m_workers.emplace_back([this, t] { work(t - 1); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_stop = true;
  }
  m_wake.notify_all();
  for (std::thread& t : m_workers) t.join();
}

// Tasks are taken one at a time from a shared counter until none is left.
void ThreadPool::drain() {
  for (int k = m_next++; k < m_tasks; k = m_next++) {
    try {
      (*m_task)(k);
    } catch (...) {
      std::lock_guard<std::mutex> lock(m_mutex);
      if (!m_error) m_error = std::current_exception();
    }
  }
}

void ThreadPool::work(int index) {
  long seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(m_mutex);
      m_wake.wait(lock, [&] { return m_stop || m_round != seen; });
      if (m_stop) return;
      seen = m_round;
      if (index >= m_participants) continue;  // a round of fewer tasks than threads leaves it out
    }
    drain();
    {
      std::lock_guard<std::mutex> lock(m_mutex);
      --m_running;
    }
    m_done.notify_all();
  }
}

void ThreadPool::run(int tasks, const std::function<void(int)>& task) {
  if (m_workers.empty() || tasks <= 1) {
    for (int k = 0; k < tasks; ++k) task(k);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_task = &task;
    m_tasks = tasks;
    m_next = 0;
    m_error = nullptr;
    // The round's participants (the first tasks - 1 workers) each report its end, and the next
    // round starts only once the last has: no worker can still be taking tasks from an old round.
    // The others skip it (they may wake late; they only note the round).
    m_participants = std::min(static_cast<int>(m_workers.size()), tasks - 1);
    m_running = m_participants;
    ++m_round;
  }
  m_wake.notify_all();
  drain();
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(m_mutex);
    m_done.wait(lock, [&] { return m_running == 0; });
    m_task = nullptr;
    error = m_error;
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace gem
