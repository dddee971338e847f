// Which bodies the CPU stepper's last step left exactly as they were, lent to the broadphase it
// calls next (docs/performance.md 3.13). A kept list then skips a still body's displacement check,
// and keeps the last answer of a chunk of listed pairs whose bodies are all still: their states are
// the ones the last step judged, so the answers are the ones given then. Most of a 10^5-floe pack
// rests ahead of the vessel, and those two passes read every body and every listed pair each step.
//
// A hint, never needed: without a scope on the calling thread (a test, the CUDA backend's host
// mirror, a broadphase called outside a step) stillBodies() is null and every body is checked. Not
// part of the plugin ABI: nothing here travels in a struct a plugin reads.
#pragma once
#include <cstdint>
#include <cstring>
#include <vector>

namespace gem {

// While one is alive on this thread, stillBodies() there returns `flags` (null: none known).
// flags[i] != 0 promises that the body in slot i has the same bits of position, angle and
// velocities as at this thread's previous findCandidates call, and that since then bodies were
// added, removed or moved to other slots only as the broadphase was told by bodiesRenamed(): the
// flags are by the slots the bodies hold now (a re-sort or a break moves them with their bodies).
class StillBodiesScope {
 public:
  explicit StillBodiesScope(const char* flags);
  ~StillBodiesScope();
  StillBodiesScope(const StillBodiesScope&) = delete;
  StillBodiesScope& operator=(const StillBodiesScope&) = delete;

 private:
  const char* m_previous;
};

const char* stillBodies();

// A still flag of this value says more: the body is also in no contact, and the stepper tests no
// pair of two such bodies this step (its narrowphase skips a pair unless one body moved or
// touched something at the last step: the CPU stepper's kStill).
constexpr char kRestingBody = 2;

// Pairs [begin, end) of a broadphase's output, by index.
struct CandidateRange {
  long begin, end;
};

// While one is alive on this thread, restingPairs() there returns `ranges` (null: none asked),
// which the caller empties before it calls the broadphase. A broadphase that was told the still
// flags may put there ranges of its output in which every pair is of two bodies flagged
// kRestingBody, in increasing order and disjoint: the CPU narrowphase passes over them unread. At
// 10^5 floes those are nearly all of the 155,000 candidates a step, and reading each one's two
// flags was a tenth of the step. The broadphase may leave the elements inside a range unwritten
// (they then hold whatever the vector held there): the output is the full candidate list, the
// same pairs in the same order as without the scope, everywhere outside the ranges, and its size
// is the full list's. A broadphase that puts nothing there loses nothing.
class RestingPairsScope {
 public:
  explicit RestingPairsScope(std::vector<CandidateRange>* ranges);
  ~RestingPairsScope();
  RestingPairsScope(const RestingPairsScope&) = delete;
  RestingPairsScope& operator=(const RestingPairsScope&) = delete;

 private:
  std::vector<CandidateRange>* m_previous;
};

std::vector<CandidateRange>* restingPairs();

// Whether the eight flags at `flags` are all nonzero (all still): one load, a zero byte found by
// the carry trick. A pack at rest is mostly still, and a flag a branch was most of a pass over
// 10^5 bodies; the CPU stepper's own flags are zero for a moving body as well.
inline bool allEightStill(const char* flags) {
  constexpr std::uint64_t kOnes = 0x0101010101010101ull, kHighs = 0x8080808080808080ull;
  std::uint64_t word;
  std::memcpy(&word, flags, sizeof word);
  return ((word - kOnes) & ~word & kHighs) == 0;
}

}  // namespace gem
