#include "framework/app/mpi_work.hpp"

#include <cstdlib>
#include <mutex>

#if defined(GEM_HAVE_MPI)
#include <mpi.h>
#endif

namespace gem {

bool launchedByMpi() { return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK"); }

bool mpiBuilt() {
#if defined(GEM_HAVE_MPI)
  return true;
#else
  return false;
#endif
}

#if defined(GEM_HAVE_MPI)

struct MpiWork::State {
  MPI_Win window = MPI_WIN_NULL;
  long* counter = nullptr;  // rank 0's next case index
  std::mutex mutex;         // MPI is initialised for serialized threads: one call at a time
};

MpiWork::MpiWork() {
  if (!launchedByMpi()) return;
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
  m_initialised = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &m_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &m_size);
  MPI_Comm node = MPI_COMM_NULL;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, m_rank, MPI_INFO_NULL, &node);
  MPI_Comm_rank(node, &m_localRank);
  MPI_Comm_size(node, &m_localSize);
  MPI_Comm_free(&node);
  m_state = new State;
  MPI_Win_allocate(m_rank == 0 ? sizeof(long) : 0, sizeof(long), MPI_INFO_NULL, MPI_COMM_WORLD, &m_state->counter, &m_state->window);
  if (m_rank == 0) *m_state->counter = 0;
  MPI_Barrier(MPI_COMM_WORLD);
}

MpiWork::~MpiWork() {
  if (!m_initialised) return;
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Win_free(&m_state->window);
  delete m_state;
  MPI_Finalize();
}

std::size_t MpiWork::next(std::size_t count) {
  if (!active()) return count;  // not used without MPI: the caller's own counter hands out cases
  std::lock_guard lock(m_state->mutex);
  const long one = 1;
  long claimed = 0;
  MPI_Win_lock(MPI_LOCK_SHARED, 0, 0, m_state->window);
  MPI_Fetch_and_op(&one, &claimed, MPI_LONG, 0, 0, MPI_SUM, m_state->window);
  MPI_Win_unlock(0, m_state->window);
  return claimed < static_cast<long>(count) ? static_cast<std::size_t>(claimed) : count;
}

long MpiWork::sumOverRanks(long value) {
  if (!active()) return value;
  std::lock_guard lock(m_state->mutex);
  long total = 0;
  MPI_Allreduce(&value, &total, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return total;
}

#else

struct MpiWork::State {};
MpiWork::MpiWork() {}
MpiWork::~MpiWork() {}
std::size_t MpiWork::next(std::size_t count) { return count; }
long MpiWork::sumOverRanks(long value) { return value; }

#endif

}  // namespace gem
