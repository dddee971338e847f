// Cases handed out across MPI ranks as they finish (issue 5: `mpirun -np K gem sweep ...`). Built
// only when MPI is found (GEM_HAVE_MPI); otherwise a single process is the whole "world".
// The counter of the next case lives in a one-sided window on rank 0: each rank fetches and
// increments it when it is ready for more work, so fast ranks take more cases.
#pragma once
#include <cstddef>

namespace gem {

class MpiWork {
 public:
  // Initialises MPI when this process was started by mpirun (and GEM has MPI); a no-op otherwise.
  MpiWork();
  ~MpiWork();
  MpiWork(const MpiWork&) = delete;
  MpiWork& operator=(const MpiWork&) = delete;

  bool active() const { return m_size > 1; }
  int rank() const { return m_rank; }
  int size() const { return m_size; }
  // This rank's index among the ranks on its node (MPI_COMM_TYPE_SHARED), and their count: a node's
  // GPUs are dealt out by it.
  int localRank() const { return m_localRank; }
  int localSize() const { return m_localSize; }
  // The next unclaimed index in [0, count) for this rank, or count when none is left. Thread-safe.
  std::size_t next(std::size_t count);
  // Waits for every rank; returns the sum of `value` over ranks.
  long sumOverRanks(long value);

 private:
  int m_rank = 0, m_size = 1, m_localRank = 0, m_localSize = 1;
  bool m_initialised = false;
  struct State;
  State* m_state = nullptr;
};

// True when the environment says this process was launched by an MPI starter.
bool launchedByMpi();
// True when this build of GEM has MPI (gem info says so; the MPI sweep test needs it).
bool mpiBuilt();

}  // namespace gem
