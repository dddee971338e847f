// The machinery every kept-list broadphase shares (docs/model.md 9, thesis 5.1 and 5.4): a flat list of
// pairs built with a skin, the never-miss rebuild rule, and the per-step filter that turns the kept
// list into this step's candidates.
//
// Why a skin makes a kept list safe: a strategy lists every pair whose centroids were within
// R_a + R_b + skin at the build. Two bodies can only touch while their bounding circles overlap,
// |c_a - c_b| <= R_a + R_b, and since the build the centroid distance has changed by at most
// d_a + d_b, d the bound on how far any point of a body has moved. So while d_a + d_b <= skin for
// every pair, every touching pair is still listed. docs/model.md's rule ("rebuild before any body can
// have moved more than half the skin") keeps every d <= skin / 2, which guarantees that.
//
// Here a body that passes half the skin does not force a rebuild at once: it becomes *direct*,
// its listed pairs are ignored, and each step it is tested against the bodies near it (their
// bounding circles, merged into the sorted candidates; "near" through a grid of the references,
// reference_grid.hpp, since every body not direct is within half the skin of its reference). For
// the bodies still listed every d stays
// <= skin / 2, so the list stays complete for them, and the direct pass covers the rest: nothing
// is missed. The vessel is always direct (it moves at several m/s through resting ice and would
// set the rebuild rate alone), and so are the few floes it is shoving.
//
// When more than kRelistPast bodies are direct, the direct floes are *relisted* rather than the
// whole list rebuilt (at 10^5 floes the vessel's wake passed 8 direct bodies every 5 steps, and a
// rebuild cost two steps): each one's pairs are listed afresh from where it is now, with the reach
// R_a + R_b + 1.5 skin, into a side list, its pairs in the main list are masked from then on, and
// its reference state becomes its state now. Why 1.5 skin: take a pair and the last time T it was
// judged, by the build or by relisting either body. If neither is direct now, neither has been
// relisted since T, and each was within half the skin of its reference at T and is now (a body
// direct at T was relisted at T), so since T the relisted one has moved at most skin / 2 and the
// other at most skin / 2 + skin / 2: 1.5 skin in all (a full build judges both from their
// references, so the skin suffices there). Extra listed pairs cost only filter time: the
// candidates (listed pairs whose circles overlap now, plus the direct pass) are the same pairs in
// the same order, so trajectories do not change. The list is rebuilt whole when the bodies
// change, or once the bodies direct or relisted since the build pass an eighth of all of them (the
// side list grows with each floe relisted for the first time, and each relist rewrites it; a floe
// relisted again only replaces its pairs, so it is counted once: counted at each relist, the wake
// of the vessel at 10^5 floes spent the budget every 400 steps).
#pragma once
#include <cstddef>
#include <atomic>
#include <bit>
#include <cstdint>
#include <vector>

#include "broadphase/kept_list/reference_grid.hpp"
#include "framework/api/broadphase.hpp"
#include "framework/api/still_bodies.hpp"

namespace gem {

// The rebuild fires a hair before d_1st + d_2nd reaches the skin, so that rounding in the distances
// of the build and of the check can never let a pair on the very edge of the list slip out. Shared
// with the device lists (device_neighbour_list.cuh).
constexpr Real kRebuildTrigger = Real(1) - Real(1e-6);

// A listed pair: the two slots and the square of R_a + R_b, fixed between builds (a body keeps its
// shape while it keeps its id), so the per-step filter streams one array and gathers only x, y.
struct ListedPair {
  int a, b;
  Real reach2;
};

class NeighbourList {
 public:
  explicit NeighbourList(Real skin) : m_skin(skin) {}

  Real skin() const { return m_skin; }
  // What the list needs before this step's filter. Rebuild: never built, invalidated, body count or
  // identities changed, or more than kRelistPast bodies are direct and the bodies direct or
  // relisted since the build pass an eighth of all of them. Relist: more than kRelistPast are direct,
  // within the budget (relistDirect()). Otherwise marks every body that has moved more than half
  // the skin since its reference as direct. One pass over the bodies, but those the stepper says
  // are still (framework/api/still_bodies.hpp): their answer is the last one.
  enum class Need { Nothing, Relist, Rebuild };
  Need update(const World& world);
  // The direct floes' rows listed afresh from where they are now (see above); they stop being direct.
  void relistDirect(const World& world);
  int directCount() const { return static_cast<int>(m_directList.size()); }
  // Direct bodies (the vessel among them) past which the CPU list relists the floes. A direct floe
  // costs a search of the bodies near it each step, its relisting one such search and a pass over
  // the side list (docs/performance.md 3.13, 3.15). The candidates are the same whenever it relists.
  static constexpr int kRelistPast = 3;
  // The direct bodies the device list holds beyond the always-direct ones before it rebuilds
  // (device_neighbour_list.cuh: the device does not relist).
  static constexpr int kMaxDirect = 8;
  static constexpr Real kRelistReach = Real(1.5);  // skins
  long relists() const { return m_relists; }
  // Items a parallel range takes at least (framework/api/parallel.hpp): pairs of a stream (a few
  // nanoseconds each), bodies of an O(1) pass.
  static constexpr int kPairGrain = 4096, kBodyGrain = 1024;
  // The side list's pairs name relisted floes all over the field: each reads two bodies' x and y
  // from far apart, several times a stream pair's cost.
  static constexpr int kSidePairGrain = 1024;
  // The filter's chunks of listed pairs, and the blocks of slots that say whether a chunk's bodies
  // are all still (filterByCircles). Both divide the grains above.
  static constexpr int kChunkPairs = 256, kFlagBlock = 64;
  void invalidate() { m_valid = false; }
  // Bodies were added, removed or moved to other slots, the rest unchanged: the next update()
  // follows them by id (followRenamed) instead of rebuilding.
  void bodiesRenamed() { m_renamed = true; }
  long rebuilds() const { return m_rebuilds; }
  long follows() const { return m_follows; }  // renames followed without a rebuild

  // Building: begin, add each pair once (a != b, either order), finish. finish() drops wall-wall
  // pairs (two immovable bodies never interact), sorts by (a, b) when the pairs did not come in
  // order, and records the reference state of every body. A build split over parallel ranges
  // (framework/api/parallel.hpp) adds each range's pairs to a part of its own, begin(parts) and
  // add(part, a, b): the parts in order are the pairs in the order of one pass, so the list is the
  // same whatever the thread count.
  void begin(int parts = 1);
  void add(int a, int b) { add(0, a, b); }
  void add(int part, int a, int b) { m_raw[static_cast<size_t>(part)].push_back({a < b ? a : b, a < b ? b : a, 0}); }
  void finish(const World& world);

  // This step's candidates: the listed pairs whose bounding circles overlap now, in list order
  // (sorted), with the direct and side lists' pairs merged in. Clears out first. A chunk of listed
  // pairs whose bodies update() was told are all still keeps its last answer unread. Where
  // `resting` is given and update() was told which bodies rest, it gets the ranges of `out` that
  // hold pairs of two resting bodies only, left unwritten (framework/api/still_bodies.hpp), else
  // it is emptied.
  void filterByCircles(const World& world, std::vector<CandidatePair>& out, std::vector<CandidateRange>* resting = nullptr);
  const std::vector<ListedPair>& pairs() const { return m_pairs; }
  const std::vector<ListedPair>& sidePairs() const { return m_sidePairs; }  // those of the relisted floes

 private:
  void sortRaw(int bodyCount);
  bool placeLongRowBySlot(int begin, int end, size_t bodyCount);  // sortRaw's long rows; false: left as they were
  bool followRenamed(const World& world);
  bool partsInOrder(const std::vector<char>& partSorted) const;
  void joinRaw();
  void binReferences(const World& world);
  Real searchReach(Real x, Real y, Real r, Real beyond) const;
  static constexpr int kShortRow = 32;  // rows up to this long are insertion-sorted
  Real m_skin;
  bool m_valid = false;
  bool m_renamed = false;
  long m_rebuilds = 0, m_relists = 0, m_follows = 0;
  // followRenamed's scratch: each id's new slot, each old slot's new one, whether a new slot holds a
  // new body, and the reference state and flags by the new slots before they are swapped in.
  std::vector<int> m_slotOfId, m_newSlot;
  std::vector<char> m_isNew;
  std::vector<Real> m_x0Next, m_y0Next, m_angle0Next;
  std::vector<std::int64_t> m_id0Next;
  std::vector<char> m_directNext, m_maskedNext;
  // The bodies whose pairs the main list no longer gives (direct, or relisted since the build):
  // past an eighth of the bodies, the list is rebuilt.
  int m_maskedBodies = 0;
  std::vector<std::vector<ListedPair>> m_raw;  // the build's parts
  std::vector<ListedPair> m_pairs, m_kept;
  std::vector<CandidatePair> m_filtered;
  // The filter's answer by chunks (filterByCircles): each chunk's survivors, kept at the start of its
  // stretch of m_filtered, its count, and the blocks of slots its bodies span; whether they hold the
  // last filter's answers for the pairs as they are (m_chunksKnown); whether this step's update()
  // was told which bodies are still (m_stillKnown), and then, block by block, whether one is not
  // (m_movingBlocks).
  bool m_chunksKnown = false, m_stillKnown = false;
  std::vector<int> m_chunkCount;
  // A bit a block of kFlagBlock slots, set when the block holds a flagged body. update()'s ranges
  // set them, a word at a time by an atomic OR (an OR gives the same word in any order); the
  // chunks' spans read them. At 10^5 floes the 1,563 blocks are 25 words: the running counts by
  // block they replace were two arrays of 6 kB that the calling thread rewrote between the
  // update's round and the filter's, their lines last read by other cores (on two threads that
  // pass took 2.8 times its one-thread time).
  struct BlockBits {
    std::vector<std::uint64_t> words;
    long blocks = 0;
    void clear(long count) { blocks = count, words.assign(static_cast<size_t>((count + 63) / 64), 0); }
    void orWord(long word, std::uint64_t bits) {
      if (bits) std::atomic_ref<std::uint64_t>(words[static_cast<size_t>(word)]).fetch_or(bits, std::memory_order_relaxed);
    }
    bool anyIn(int first, int last) const {  // a set bit in blocks first .. last (most spans lie in one word)
      const auto firstWord = static_cast<unsigned>(first) / 64, lastWord = static_cast<unsigned>(last) / 64;
      const std::uint64_t from = ~std::uint64_t{0} << (static_cast<unsigned>(first) % 64),
                          through = ~std::uint64_t{0} >> (63 - static_cast<unsigned>(last) % 64);
      if (firstWord == lastWord) return (words[firstWord] & from & through) != 0;
      if (words[firstWord] & from) return true;
      for (unsigned w = firstWord + 1; w < lastWord; ++w)
        if (words[w]) return true;
      return (words[lastWord] & through) != 0;
    }
    long count() const {
      long set = 0;
      for (const std::uint64_t w : words) set += std::popcount(w);
      return set;
    }
  };
  // The blocks a chunk's bodies lie in: its first bodies' and its second bodies'. quiet(flagged):
  // none of them is flagged.
  struct ChunkSpan {
    int firstA, lastA, firstB, lastB;
    bool quiet(const BlockBits& flagged) const { return !flagged.anyIn(firstA, lastA) && !flagged.anyIn(firstB, lastB); }
  };
  std::vector<ChunkSpan> m_chunkSpan;
  // Each chunk's first kept pair, beside its count: the join's walk reads these few kilobytes, where
  // the chunks' first rows in the scratch were a cache miss each (7 us a step at 10^5 floes).
  std::vector<CandidatePair> m_chunkHead;
  // Each chunk's last answers, a bit a pair (kept or not), and the still flags this step's update()
  // was told (valid while the broadphase's caller holds its scope: within findCandidates).
  static constexpr int kAnswerWords = kChunkPairs / 64;
  std::vector<std::uint64_t> m_chunkAnswers;
  std::vector<char> m_answersKnown;  // by chunk: whether its bits hold its answers
  const char* m_still = nullptr;
  BlockBits m_movingBlocks;
  // Likewise the blocks that hold a body not flagged kRestingBody, and each range of the join's
  // resting stretches of the output (restingPairs, framework/api/still_bodies.hpp).
  BlockBits m_restlessBlocks;
  std::vector<std::vector<CandidateRange>> m_restingParts;
  std::vector<size_t> m_rangeKept;   // the chunks' pass, range by range: its kept pairs (then the sum before each range)
  std::vector<size_t> m_directFrom;  // the join's: where each chunk's direct pairs start
  // The counting sort's row starts (bodies + 1) and next free places (bodies), and each range's
  // count of the filters' survivors.
  std::vector<int> m_count, m_cursor;
  std::vector<size_t> m_rangeCount;

  // Reference state at the last build, by slot.
  std::vector<Real> m_x0, m_y0, m_angle0;
  std::vector<std::int64_t> m_id0;
  // Direct bodies, tested against the bodies near them each step by filterByCircles: the vessels,
  // and the bodies that moved more than half the skin since their reference.
  std::vector<char> m_direct;
  std::vector<int> m_directList;
  std::vector<std::vector<int>> m_newlyDirect;  // update()'s and followRenamed()'s new direct bodies, range by range
  std::vector<CandidatePair> m_directPairs;
  // The references binned in cells, for the direct pass and relisting (reference_grid.hpp).
  ReferenceGrid m_grid;
  // Relisting: the side list (every pair of a floe relisted since the build, sorted), the bodies
  // whose pairs the main list no longer gives (direct or relisted, by slot), and scratch: the
  // floes being relisted (by slot), their new pairs (range by range, then all), the side pairs
  // whose circles overlap this step (range by range).
  std::vector<ListedPair> m_sidePairs;
  std::vector<char> m_masked;
  std::vector<char> m_relisting;
  std::vector<ListedPair> m_relisted, m_merged;
  std::vector<std::vector<ListedPair>> m_relistedParts;  // relisting's searches, range by range
  static constexpr int kRelistGrain = 2;                 // relisted floes a range at least
  std::vector<std::vector<CandidatePair>> m_sideParts;
};

// Base of the kept-list strategies: rebuild when the rule asks, then filter. A strategy says only
// how it builds (and, for triangulation_mesh, how it filters).
class KeptListBroadphase : public Broadphase {
 public:
  explicit KeptListBroadphase(Real skin) : m_list(skin) {}
  void findCandidates(const World& world, std::vector<CandidatePair>& pairs) override;
  void invalidate() override { m_list.invalidate(); }
  void bodiesRenamed() override { m_list.bodiesRenamed(); }
  long rebuilds() const override { return m_list.rebuilds(); }
  // The kept list itself, for tests and benchmarks.
  const NeighbourList& list() const { return m_list; }

 protected:
  // Adds every pair the strategy lists between m_list.begin() and m_list.finish(), which the base calls.
  virtual void build(const World& world, NeighbourList& list) = 0;
  // The default hands the stepper the resting ranges of its output (restingPairs); a strategy
  // that filters the circles' list further must not.
  virtual void filter(const World& world, std::vector<CandidatePair>& pairs) { m_list.filterByCircles(world, pairs, restingPairs()); }
  NeighbourList m_list;
};

// The settings after a check: negative or non-finite lengths are an InputError naming the key.
BroadphaseSettings checkedSettings(const BroadphaseSettings& settings);

// The largest bounding radius among floes, else among all movable bodies, else 0: the size scale
// of fixed_radius and uniform_grid. Walls (long, immovable) and the vessel would make it useless.
Real largestFloeRadius(const World& world);

// The build of variable_radius, fixed_radius and triangulation_mesh: lists every pair with
// |c_a - c_b| <= max(floor, h_a + h_b), h one length per body and floor one length for all. With
// e = max(floor / 2, h), a pair the rule accepts has |c_a - c_b| <= e_a + e_b. Two exact methods
// find them; each first counts (the sweep: estimates) the pair tests it would make, and the cheaper one runs (the list is
// the same either way: NeighbourList::finish sorts it):
// - a sweep along x: each body spans [x - e, x + e] and meets the bodies whose spans start inside
//   its own. Lean in a channel, long in x; about n^1.5 tests in a square field.
// - a uniform grid of cells at least 2 e wide: a pair within reach lies in the same cell or a
//   neighbouring one, so each body tests its 9 cells, O(n + pairs) in any field shape; but with
//   floes of very different sizes every cell is as wide as the largest, and the sweep can test less.
//   The few bodies far larger than the rest (a wall spans the field; a giant floe) are tested
//   against every body instead of widening every cell.
// At 10^5 floes in a square field the grid made the step 1.46x faster on one core; on the 824-floe
// channel the sweep stays the faster (docs/performance.md 3.8).
class PairsWithinReach {
 public:
  // Over ranges of bodies on the caller's parallel runner, each range into a part of the list
  // (NeighbourList::begin(parts)).
  void build(const World& world, const std::vector<Real>& h, Real floor, NeighbourList& list);
  static constexpr int kGrain = 512;  // bodies a range takes at least
  // Which method runs: the cheaper (always, but in tests that compare the two).
  enum class Method { Cheaper, Sweep, Grid };
  void use(Method method) { m_method = method; }
  bool lastBuiltByGrid() const { return m_byGrid; }

 private:
  double estimateSweep(const World& world, const std::vector<Real>& h, Real floor);  // its tests, from a sample
  void sortAlongX(const World& world, const std::vector<Real>& h, Real floor);
  void sweep(const World& world, const std::vector<Real>& h, Real floor, NeighbourList& list);
  double binInGrid(const World& world, const std::vector<Real>& h, Real floor);  // returns the grid's tests
  void scanGrid(const World& world, const std::vector<Real>& h, Real floor, NeighbourList& list);

  Method m_method = Method::Cheaper;
  bool m_byGrid = false;
  // The sweep: the order of the last build is kept (bodies move little, so it is nearly sorted and
  // an insertion sort fixes it in about O(n)); sorted copies of x, y, h, so that its inner loop
  // walks memory in order.
  std::vector<int> m_order, m_slot;
  std::vector<Real> m_lo, m_sortedLo, m_x, m_y, m_h, m_hi;  // m_lo by slot, the rest by sorted position
  // The grid.
  std::vector<Real> m_extent, m_scratch;
  std::vector<int> m_large;                // the bodies tested against every body
  std::vector<char> m_isLarge;             // by slot
  std::vector<int> m_cellOf;               // by slot: its cell, -1 for a large body
  std::vector<int> m_cellStart, m_sorted;  // the bodies cell by cell (a counting sort)
  int m_nx = 0, m_ny = 0;
};

}  // namespace gem
