#include "broadphase/kept_list/neighbour_list.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>

#include "framework/api/errors.hpp"
#include "framework/api/parallel.hpp"
#include "framework/api/still_bodies.hpp"

namespace gem {

namespace {

// Whether the kFlagBlock flags at `flags` all say kRestingBody: eight at a load.
static_assert(NeighbourList::kFlagBlock % 8 == 0, "a block is whole words of flags");
bool allResting(const char* flags) {
  constexpr std::uint64_t kAllResting = 0x0101010101010101ull * static_cast<unsigned char>(kRestingBody);
  std::uint64_t differ = 0;
  for (int k = 0; k < NeighbourList::kFlagBlock; k += 8) {
    std::uint64_t word;
    std::memcpy(&word, flags + k, sizeof word);
    differ |= word ^ kAllResting;
  }
  return differ == 0;
}

}  // namespace

NeighbourList::Need NeighbourList::update(const World& world) {
  m_stillKnown = false, m_still = nullptr;
  if (!m_valid) return Need::Rebuild;
  if (m_renamed) {
    m_renamed = false;
    if (!followRenamed(world)) return Need::Rebuild;
  }
  const int n = world.size();
  if (n != static_cast<int>(m_x0.size())) return Need::Rebuild;
  const Real* x = world.x.data();
  const Real* y = world.y.data();
  const Real* angle = world.angle.data();
  const Real* radius = world.radius.data();
  const std::int64_t* id = world.id.data();
  const Real limit = kRebuildTrigger * m_skin / 2;
  // A body the stepper's last step left still (framework/api/still_bodies.hpp) is in the slot, and
  // at the pose, that the last update judged: the same answer, for one byte read in place of nine
  // values. Read here, on the caller's thread: the scope is not the pool's.
  const char* still = stillBodies();
  m_stillKnown = still != nullptr;
  m_still = still;
  // Over ranges of whole blocks of bodies, each range's newly direct bodies into a part of its own,
  // appended in range order: the same list as one pass. Each block also notes whether a body of it
  // is not known to be still: the filter keeps the last answer of a chunk of pairs none of whose
  // bodies lies in such a block.
  const long blocks = (n + kFlagBlock - 1) / kFlagBlock;
  m_movingBlocks.clear(blocks), m_restlessBlocks.clear(blocks);
  const int tasks = parallelCrowdedTasks(blocks, kBodyGrain / kFlagBlock);
  m_newlyDirect.resize(static_cast<size_t>(tasks));
  std::vector<char> renamed(static_cast<size_t>(tasks), 0);
  // Finer ranges than most passes: the moving bodies, whose checks are the work, crowd around the
  // vessel.
  parallelCrowdedRanges(blocks, kBodyGrain / kFlagBlock, [&](int t, long firstBlock, long endBlock) {
    std::vector<int>& part = m_newlyDirect[static_cast<size_t>(t)];
    part.clear();
    // The range's flags for the word of blocks it is in, ORed into the shared word when it moves
    // on to the next word and at its end: a few atomic operations a range, and nothing for a
    // resting block.
    auto word = static_cast<unsigned long>(firstBlock) / 64;
    std::uint64_t movingBits = 0, restlessBits = 0;
    auto flush = [&] {
      m_movingBlocks.orWord(static_cast<long>(word), movingBits), m_restlessBlocks.orWord(static_cast<long>(word), restlessBits);
    };
    auto note = [&](long block, bool moving, bool restless) {
      const auto b = static_cast<unsigned long>(block);
      if (b / 64 != word) flush(), word = b / 64, movingBits = restlessBits = 0;
      movingBits |= std::uint64_t{moving} << (b % 64), restlessBits |= std::uint64_t{restless} << (b % 64);
    };
    for (long block = firstBlock; block < endBlock; ++block) {
      const long begin = block * kFlagBlock, end = std::min<long>(n, begin + kFlagBlock);
      bool moving = still == nullptr;
      // A whole block of resting bodies, most of a resting pack, in a load of eight flags at a
      // time: neither moving nor restless. Body by body, the two flags were an eighth of the
      // steps' instructions at 10^5 floes.
      if (still && end - begin == kFlagBlock && allResting(still + begin)) continue;
      int restless = 0;  // bodies not resting (restingPairs), counted without a branch
      if (still)
        for (long i = begin; i < end; ++i) restless += still[i] != kRestingBody;
      const bool restlessBlock = restless != 0 || !still;
      for (long i = begin; i < end; ++i) {
        if (still && (i - begin) % 8 == 0 && i + 8 <= end && allEightStill(still + i)) {
          i += 7;  // eight still bodies at once
          continue;
        }
        if (still && still[i]) continue;
        moving = true;
        // A reorder or an in-place replacement without invalidate() would make the list point at the
        // wrong bodies: the ids guard against it for the price of one load per body.
        if (id[i] != m_id0[static_cast<size_t>(i)]) {
          renamed[static_cast<size_t>(t)] = 1;
          return;
        }
        if (m_direct[static_cast<size_t>(i)]) continue;  // its pairs are found afresh every step
        const Real dx = x[i] - m_x0[static_cast<size_t>(i)], dy = y[i] - m_y0[static_cast<size_t>(i)];
        // The farthest a point at distance R from the centroid moves under a turn of da is the chord
        // 2 R |sin(da / 2)| <= R |da wrapped to [-pi, pi]|: an angle that was wrapped by the motion
        // code (a jump of 2 pi) then counts as no turn, as it should. The wrap is rare, so branched.
        Real da = std::fabs(angle[i] - m_angle0[static_cast<size_t>(i)]);
        if (da > kPi) da = std::fabs(std::remainder(da, Real(2) * kPi));
        if (std::sqrt(dx * dx + dy * dy) + radius[i] * da > limit) {
          m_direct[static_cast<size_t>(i)] = 1;  // masked below, where the masked bodies are counted
          part.push_back(static_cast<int>(i));
        }
      }
      note(block, moving, restlessBlock);
    }
    flush();
  });
  for (char r : renamed)
    if (r) {
      m_stillKnown = false;  // the block flags are unfinished: no still chunk is reused, no resting range named
      return Need::Rebuild;
    }
  for (const std::vector<int>& part : m_newlyDirect) {
    m_directList.insert(m_directList.end(), part.begin(), part.end());
    for (const int i : part) m_maskedBodies += !m_masked[static_cast<size_t>(i)], m_masked[static_cast<size_t>(i)] = 1;
  }
  const int direct = static_cast<int>(m_directList.size());
  if (direct <= kRelistPast) return Need::Nothing;
  return m_maskedBodies > n / 8 ? Need::Rebuild : Need::Relist;
}

// After bodiesRenamed(): a break removed some bodies and added others, or the re-sort moved every
// body to another slot, and the rest kept their ids, shapes and states. A full build costs several
// steps at 10^5 floes, and the vessel's breaks and the re-sort asked for one every 50 to 100 steps
// (docs/performance.md 3.12). Instead each listed pair is renamed to its bodies' new slots (a pair of a removed body
// goes) and each body takes its reference state with it, so the list stays what the rule of
// docs/model.md 9 needs: every pair within reach of the references, the references within half a
// skin of where the bodies are. A new body has no pairs listed: it is direct from now on (the
// direct pass finds its pairs every step until it is relisted), its reference where it is now. The
// candidates, the pairs whose circles overlap, are the same as after a build. Returns false (the
// caller rebuilds) when the ids cannot be followed: negative, repeated, or too sparse for a table.
bool NeighbourList::followRenamed(const World& world) {
  const int n = world.size();
  const long oldCount = static_cast<long>(m_id0.size());
  const std::int64_t* id = world.id.data();
  // Each id's new slot, in a table up to the world's next id (an id of the world past it, set by
  // hand, makes the list build afresh; an old id past it is of a body that went). Over ranges of
  // bodies: a repeated id makes two ranges write one entry, and the check after finds the entry
  // naming the other body (the stores are atomic, so the race is only over which one).
  const std::int64_t ids = world.nextId;
  if (ids >= 4 * static_cast<std::int64_t>(n + oldCount) + 1024) return false;
  m_slotOfId.resize(static_cast<size_t>(std::max<std::int64_t>(ids, 0)));
  parallelRanges(static_cast<long>(m_slotOfId.size()), kBodyGrain,
                 [&](int, long begin, long end) { std::fill(m_slotOfId.begin() + begin, m_slotOfId.begin() + end, -1); });
  std::atomic<bool> unfollowable{false};
  parallelRanges(n, kBodyGrain, [&](int, long begin, long end) {
    for (long i = begin; i < end; ++i) {
      if (id[i] < 0 || id[i] >= ids) {
        unfollowable.store(true, std::memory_order_relaxed);
        return;
      }
      std::atomic_ref<int>(m_slotOfId[static_cast<size_t>(id[i])]).store(static_cast<int>(i), std::memory_order_relaxed);
    }
  });
  if (unfollowable.load()) return false;
  // Where each old slot's body went (-1: removed), and which new slots hold a new body.
  m_newSlot.resize(static_cast<size_t>(oldCount));
  m_isNew.assign(static_cast<size_t>(n), 1);
  parallelRanges(n, kBodyGrain, [&](int, long begin, long end) {
    for (long i = begin; i < end; ++i)
      if (m_slotOfId[static_cast<size_t>(id[i])] != i) unfollowable.store(true, std::memory_order_relaxed);  // a repeated id
  });
  parallelRanges(oldCount, kBodyGrain, [&](int, long begin, long end) {
    for (long j = begin; j < end; ++j) {
      const std::int64_t old = m_id0[static_cast<size_t>(j)];
      const int i = old < 0 || old >= ids ? -1 : m_slotOfId[static_cast<size_t>(old)];
      m_newSlot[static_cast<size_t>(j)] = i;
      if (i >= 0) m_isNew[static_cast<size_t>(i)] = 0;
    }
  });
  if (unfollowable.load()) return false;
  // The reference state and the flags move with their bodies; a new body starts direct, its
  // reference where it is now. Into buffers kept from one rename to the next, then swapped.
  const size_t bodies = static_cast<size_t>(n);
  m_x0Next.resize(bodies), m_y0Next.resize(bodies), m_angle0Next.resize(bodies), m_id0Next.resize(bodies);
  m_directNext.resize(bodies), m_maskedNext.resize(bodies);
  parallelRanges(oldCount, kBodyGrain, [&](int, long begin, long end) {
    for (long j = begin; j < end; ++j) {
      const int i = m_newSlot[static_cast<size_t>(j)];
      if (i < 0) continue;
      const size_t k = static_cast<size_t>(i), from = static_cast<size_t>(j);
      m_x0Next[k] = m_x0[from], m_y0Next[k] = m_y0[from], m_angle0Next[k] = m_angle0[from], m_id0Next[k] = m_id0[from];
      m_directNext[k] = m_direct[from], m_maskedNext[k] = m_masked[from];
    }
  });
  size_t keptDirect = 0;
  for (const int v : m_directList)
    if (const int i = m_newSlot[static_cast<size_t>(v)]; i >= 0) m_directList[keptDirect++] = i;
  m_directList.resize(keptDirect);
  // The new bodies, each range's into a part of its own, joined in slot order: a break's few.
  m_newlyDirect.resize(static_cast<size_t>(parallelTasks(n, kBodyGrain)));
  parallelRanges(n, kBodyGrain, [&](int t, long begin, long end) {
    std::vector<int>& part = m_newlyDirect[static_cast<size_t>(t)];
    part.clear();
    for (long i = begin; i < end; ++i) {
      const size_t k = static_cast<size_t>(i);
      if (!m_isNew[k]) continue;
      m_x0Next[k] = world.x[k], m_y0Next[k] = world.y[k], m_angle0Next[k] = world.angle[k], m_id0Next[k] = world.id[k];
      m_directNext[k] = m_maskedNext[k] = 1;
      part.push_back(static_cast<int>(i));
    }
  });
  for (const std::vector<int>& part : m_newlyDirect) m_directList.insert(m_directList.end(), part.begin(), part.end());
  m_x0.swap(m_x0Next), m_y0.swap(m_y0Next), m_angle0.swap(m_angle0Next), m_id0.swap(m_id0Next);
  m_direct.swap(m_directNext), m_masked.swap(m_maskedNext);
  m_maskedBodies = static_cast<int>(std::count(m_masked.begin(), m_masked.end(), 1));
  m_relisting.assign(bodies, 0);
  m_grid.follow(m_newSlot, m_isNew, m_x0.data(), m_y0.data(), world.radius.data());
  // The pairs renamed, each with its reach (the two shapes are the same), range by range into the
  // build's parts. Removing bodies keeps the order of the others, and the parts joined are sorted;
  // a re-sort's are sorted again by rows (sortRaw), as a build's.
  auto before = [](const ListedPair& p, const ListedPair& q) { return p.a < q.a || (p.a == q.a && p.b < q.b); };
  auto renamed = [&](const ListedPair& p, ListedPair& q) {
    const int a = m_newSlot[static_cast<size_t>(p.a)], b = m_newSlot[static_cast<size_t>(p.b)];
    q = ListedPair{std::min(a, b), std::max(a, b), p.reach2};
    return a >= 0 && b >= 0;
  };
  const long listed = static_cast<long>(m_pairs.size());
  begin(parallelTasks(listed, kPairGrain));
  std::vector<char> partSorted(m_raw.size(), 1);
  parallelRanges(listed, kPairGrain, [&](int t, long first, long last) {
    std::vector<ListedPair>& part = m_raw[static_cast<size_t>(t)];
    // Whether the part is in order, kept here and stored once: after a re-sort nearly no pair is,
    // and a store a pair into the flags the other ranges write made their cache line travel
    // between the threads.
    bool sorted = true;
    for (long k = first; k < last; ++k) {
      ListedPair q;
      if (!renamed(m_pairs[static_cast<size_t>(k)], q)) continue;
      sorted = sorted && (part.empty() || before(part.back(), q));
      part.push_back(q);
    }
    partSorted[static_cast<size_t>(t)] = sorted;
  });
  if (partsInOrder(partSorted))
    joinRaw();
  else
    sortRaw(n);
  size_t keptSide = 0;
  bool sideSorted = true;
  for (const ListedPair& p : m_sidePairs) {
    ListedPair q;
    if (!renamed(p, q)) continue;
    if (keptSide > 0 && !before(m_sidePairs[keptSide - 1], q)) sideSorted = false;
    m_sidePairs[keptSide++] = q;
  }
  m_sidePairs.resize(keptSide);
  if (!sideSorted) std::sort(m_sidePairs.begin(), m_sidePairs.end(), before);
  m_chunksKnown = false;  // the pairs were renamed
  ++m_follows;
  return true;
}

// Whether the build's parts joined in order are sorted by (a, b), given whether each part is:
// each part's first pair against the last pair of the part before it (empty parts skipped).
bool NeighbourList::partsInOrder(const std::vector<char>& partSorted) const {
  auto before = [](const ListedPair& p, const ListedPair& q) { return p.a < q.a || (p.a == q.a && p.b < q.b); };
  if (!std::all_of(partSorted.begin(), partSorted.end(), [](char c) { return c != 0; })) return false;
  const ListedPair* last = nullptr;
  for (const std::vector<ListedPair>& part : m_raw) {
    if (part.empty()) continue;
    if (last && !before(*last, part.front())) return false;
    last = &part.back();
  }
  return true;
}

// The build's parts, in order, as the list: each part copied to its place on the pool.
void NeighbourList::joinRaw() {
  if (m_raw.size() == 1) {
    m_pairs.swap(m_raw[0]);
    return;
  }
  std::vector<size_t> at(m_raw.size() + 1, 0);
  for (size_t t = 0; t < m_raw.size(); ++t) at[t + 1] = at[t] + m_raw[t].size();
  m_pairs.resize(at.back());
  parallelEach(static_cast<int>(m_raw.size()), [&](int t) {
    const std::vector<ListedPair>& part = m_raw[static_cast<size_t>(t)];
    std::copy(part.begin(), part.end(), m_pairs.begin() + static_cast<std::ptrdiff_t>(at[static_cast<size_t>(t)]));
  });
}

void NeighbourList::binReferences(const World& world) {
  m_grid.layOut(m_x0.data(), m_y0.data(), world.radius.data(), world.size(), (kRelistReach + Real(0.5)) * m_skin);
}

// The half-width of the square of references that holds every body not direct within
// r + R_j + beyond of (x, y), R_j a binned body's radius: such a body is within half the skin of
// its reference. Widened by a millionth, and a millionth of the coordinates, for the rounding of
// the distances the tests compute.
Real NeighbourList::searchReach(Real x, Real y, Real r, Real beyond) const {
  const Real reach = r + m_grid.largestRadius() + beyond + m_skin / 2;
  return reach * (1 + Real(1e-6)) + Real(1e-6) * (std::fabs(x) + std::fabs(y)) + Real(1e-9);
}

// The relisted floes' new pairs (each floe against the bodies near it, like the direct pass, then
// sorted) replace their pairs in the side list. The main list is left as it is: its pairs of a
// relisted floe are masked from then on (m_masked), so a pair is in one list only, and relisting
// costs a search per floe plus a pass over the side list, never one over the whole list. (Until
// 2026-12-06 each floe was tested against every body: at 10^5 floes that pass was the largest item
// of a one-thread step, docs/performance.md 3.15.)
void NeighbourList::relistDirect(const World& world) {
  const int n = world.size();
  const Real* x = world.x.data();
  const Real* y = world.y.data();
  const Real* radius = world.radius.data();
  std::vector<int> relisted, vessels;
  for (int v : m_directList) (world.kind[v] == BodyKind::Vessel ? vessels : relisted).push_back(v);
  std::sort(relisted.begin(), relisted.end());
  m_relisting.resize(static_cast<size_t>(n), 0);  // all 0 between relists: only the relisted floes' flags are set and reset
  for (int v : relisted) m_relisting[static_cast<size_t>(v)] = 1;

  // Each relisted floe against the bodies near it (ReferenceGrid): every body that is not direct
  // is within half the skin of its reference, so the square around the floe that reaches its
  // radius, the largest binned radius, the relisting reach and half the skin holds the reference of
  // every body it could list. The direct bodies are the relisted floes and the vessels (never listed).
  // On the pool over ranges of the relisted floes (a few dozen searches, the serial part of a step
  // at 10^5 floes that relists nearly every step), each range's pairs into a part of its own; the
  // parts are joined and sorted, so the list is the same on any thread count.
  const Real margin = kRelistReach * m_skin;
  const long relistedCount = static_cast<long>(relisted.size());
  m_relistedParts.resize(static_cast<size_t>(parallelTasks(relistedCount, kRelistGrain)));
  parallelRanges(relistedCount, kRelistGrain, [&](int t, long first, long last) {
    std::vector<ListedPair>& part = m_relistedParts[static_cast<size_t>(t)];
    part.clear();
    for (long k = first; k < last; ++k) {
      const int v = relisted[static_cast<size_t>(k)];
      auto test = [&](int j) {
        if (j == v || (m_relisting[static_cast<size_t>(j)] && j < v)) return;  // a pair of two relisted floes once
        // As finish(): wall-wall pairs never interact, vessel pairs are found by the direct pass.
        if (world.kind[j] == BodyKind::Vessel || (world.kind[v] == BodyKind::Wall && world.kind[j] == BodyKind::Wall)) return;
        const Real dx = x[v] - x[j], dy = y[v] - y[j], touch = radius[v] + radius[j], reach = touch + margin;
        if (dx * dx + dy * dy <= reach * reach) part.push_back({j < v ? j : v, j < v ? v : j, touch * touch});
      };
      m_grid.near(x[v], y[v], searchReach(x[v], y[v], radius[v], margin), [&](int j) {
        if (!m_direct[static_cast<size_t>(j)]) test(j);
      });
      for (const int j : relisted) test(j);
    }
  });
  m_relisted.clear();
  for (const std::vector<ListedPair>& part : m_relistedParts) m_relisted.insert(m_relisted.end(), part.begin(), part.end());
  auto before = [](const ListedPair& p, const ListedPair& q) { return p.a < q.a || (p.a == q.a && p.b < q.b); };
  std::sort(m_relisted.begin(), m_relisted.end(), before);
  // The side list without the relisted floes' old pairs, merged with their new ones: relisting runs
  // nearly every step while the vessel shoves floes, and the side list holds the pairs of every
  // floe relisted since the build. On one thread in one pass; on the pool over ranges of the side
  // list, in two (each range's kept pairs counted, then written merged with the new pairs that fall
  // before the next range's first pair): the same list either way.
  const long side = static_cast<long>(m_sidePairs.size());
  const int tasks = parallelTasks(side, kPairGrain);
  auto old = [&](const ListedPair& p) { return (m_relisting[static_cast<size_t>(p.a)] | m_relisting[static_cast<size_t>(p.b)]) != 0; };
  // Range t's pairs merged with the new pairs [freshBegin, freshEnd) from m_merged[out] on; returns the end.
  auto mergeRange = [&](long first, long last, size_t freshBegin, size_t freshEnd, size_t out) {
    auto fresh = m_relisted.cbegin() + static_cast<std::ptrdiff_t>(freshBegin);
    const auto freshStop = m_relisted.cbegin() + static_cast<std::ptrdiff_t>(freshEnd);
    for (long k = first; k < last; ++k) {
      const ListedPair& p = m_sidePairs[static_cast<size_t>(k)];
      if (old(p)) continue;
      while (fresh != freshStop && before(*fresh, p)) m_merged[out++] = *fresh++;
      m_merged[out++] = p;
    }
    while (fresh != freshStop) m_merged[out++] = *fresh++;
    return out;
  };
  m_merged.resize(m_sidePairs.size() + m_relisted.size());
  if (tasks == 1) {
    m_merged.resize(mergeRange(0, side, 0, m_relisted.size(), 0));
  } else {
    std::vector<size_t> keptBefore(static_cast<size_t>(tasks) + 1, 0), freshFrom(static_cast<size_t>(tasks) + 1, 0);
    for (int t = 1; t < tasks; ++t)
      freshFrom[static_cast<size_t>(t)] = static_cast<size_t>(
          std::lower_bound(m_relisted.begin(), m_relisted.end(), m_sidePairs[static_cast<size_t>(side * t / tasks)], before) -
          m_relisted.begin());
    freshFrom[static_cast<size_t>(tasks)] = m_relisted.size();
    parallelRanges(side, kPairGrain, [&](int t, long first, long last) {
      size_t kept = 0;
      for (long k = first; k < last; ++k) kept += !old(m_sidePairs[static_cast<size_t>(k)]);
      keptBefore[static_cast<size_t>(t) + 1] = kept;
    });
    for (size_t t = 1; t < keptBefore.size(); ++t) keptBefore[t] += keptBefore[t - 1];
    parallelRanges(side, kPairGrain, [&](int t, long first, long last) {
      const size_t range = static_cast<size_t>(t);
      mergeRange(first, last, freshFrom[range], freshFrom[range + 1], keptBefore[range] + freshFrom[range]);
    });
    m_merged.resize(keptBefore.back() + m_relisted.size());
  }
  m_sidePairs.swap(m_merged);

  for (int v : relisted) {
    m_x0[static_cast<size_t>(v)] = x[v], m_y0[static_cast<size_t>(v)] = y[v], m_angle0[static_cast<size_t>(v)] = world.angle[v];
    m_direct[static_cast<size_t>(v)] = 0;
    m_masked[static_cast<size_t>(v)] = 1;
    m_relisting[static_cast<size_t>(v)] = 0;
    m_grid.move(v, x[v], y[v]);  // to the cell of its new reference
  }
  m_directList = vessels;
  ++m_relists;
}

void NeighbourList::begin(int parts) {
  m_raw.resize(static_cast<size_t>(parts));
  for (std::vector<ListedPair>& part : m_raw) part.clear();
}

// A long row (a wall's: its bounding circle covers much of the field, 22,000 to 45,000 floes of
// 10^5) sorted by b in O(bodies): each pair's place noted by its b in a bitmap of the slots, the
// row read back in slot order. After a re-sort every wall's row is out of order, and std::sort of
// it, inside one task, held the whole pool for milliseconds. The b of a row are distinct (a pair
// is listed once), so the order is the one std::sort gives; a repeated b (a build's raw rows may
// hold a pair twice) returns false, and the caller sorts the row as before.
bool NeighbourList::placeLongRowBySlot(int begin, int end, size_t bodyCount) {
  thread_local std::vector<std::uint64_t> taken;  // a bit a slot, all clear between calls
  thread_local std::vector<int> placeOfSlot;
  thread_local std::vector<ListedPair> row;
  taken.resize((bodyCount + 63) / 64, 0), placeOfSlot.resize(bodyCount);
  row.assign(m_pairs.begin() + begin, m_pairs.begin() + end);
  bool repeated = false;
  for (size_t k = 0; k < row.size(); ++k) {
    const auto b = static_cast<size_t>(row[k].b);
    if (b >= bodyCount) {  // not a slot: left to std::sort
      repeated = true;
      break;
    }
    const std::uint64_t bit = std::uint64_t{1} << (b % 64);
    repeated |= (taken[b / 64] & bit) != 0;
    taken[b / 64] |= bit, placeOfSlot[b] = static_cast<int>(k);
  }
  auto out = static_cast<size_t>(begin);
  for (size_t w = 0; w < taken.size(); ++w)
    for (std::uint64_t bits = taken[w]; bits != 0; bits &= bits - 1) {
      if (!repeated) m_pairs[out++] = row[static_cast<size_t>(placeOfSlot[w * 64 + static_cast<size_t>(std::countr_zero(bits))])];
      taken[w] = 0;
    }
  return !repeated;
}

// A counting sort by a (O(bodies + pairs)), then each row sorted by b: most rows hold a handful of
// pairs, and an insertion sort beats std::sort's log factor on them; a long row (a wall's: its
// bounding circle covers the field, so at 10^5 floes it lists every floe, in sweep order) takes
// std::sort, which an insertion sort would make quadratic (it was a third of a 10^5-floe step),
// or, longer than a thirty-second of the bodies, placeLongRowBySlot.
// Equal pairs are equal records (add() leaves reach2 0), so a row's sort by b gives the same row
// whatever order its pairs were scattered in, and whichever sort runs.
// That is what lets the parts count and scatter in parallel into one shared count per row, with
// integer atomics: the counts are exact, and the order in which parts claim places in a row is
// undone by the row's sort. (Counts kept part by part made the pass over the rows cost bodies x
// parts, strided through memory: with 64 parts on 16 threads it was 6 % of a 10^5-floe run.)
void NeighbourList::sortRaw(int bodyCount) {
  const int parts = static_cast<int>(m_raw.size());
  const size_t n = static_cast<size_t>(bodyCount);
  size_t total = 0;
  for (const std::vector<ListedPair>& part : m_raw) total += part.size();
  m_pairs.resize(total);
  m_count.assign(n + 1, 0);  // m_count[a + 1]: row a's pairs
  if (parts == 1) {
    for (const ListedPair& p : m_raw[0]) ++m_count[static_cast<size_t>(p.a) + 1];
  } else {
    // A part lists a row's pairs in runs (a grid body's pairs one after another, a wall's in its
    // range likewise): one atomic addition a run. One a pair made every thread wait on the line of
    // a wall's count, which every part adds to.
    parallelEach(parts, [&](int t) {
      const std::vector<ListedPair>& part = m_raw[static_cast<size_t>(t)];
      for (size_t k = 0; k < part.size();) {
        const int a = part[k].a;
        size_t end = k + 1;
        while (end < part.size() && part[end].a == a) ++end;
        std::atomic_ref<int>(m_count[static_cast<size_t>(a) + 1]).fetch_add(static_cast<int>(end - k), std::memory_order_relaxed);
        k = end;
      }
    });
  }
  for (size_t a = 0; a < n; ++a) m_count[a + 1] += m_count[a];
  // m_count[a] is now the start of row a; m_cursor[a] the next free place in it.
  m_cursor.assign(m_count.begin(), m_count.end() - 1);
  if (parts == 1) {
    for (const ListedPair& p : m_raw[0]) m_pairs[static_cast<size_t>(m_cursor[static_cast<size_t>(p.a)]++)] = p;
  } else {
    parallelEach(parts, [&](int t) {  // a run's places claimed at once
      const std::vector<ListedPair>& part = m_raw[static_cast<size_t>(t)];
      for (size_t k = 0; k < part.size();) {
        const int a = part[k].a;
        size_t end = k + 1;
        while (end < part.size() && part[end].a == a) ++end;
        const int at =
            std::atomic_ref<int>(m_cursor[static_cast<size_t>(a)]).fetch_add(static_cast<int>(end - k), std::memory_order_relaxed);
        std::copy(part.begin() + static_cast<std::ptrdiff_t>(k), part.begin() + static_cast<std::ptrdiff_t>(end), m_pairs.begin() + at);
        k = end;
      }
    });
  }
  parallelRanges(bodyCount, kBodyGrain, [&](int, long first, long last) {
    for (long a = first; a < last; ++a) {
      const int begin = m_count[static_cast<size_t>(a)], end = m_count[static_cast<size_t>(a) + 1];
      if (end - begin > kShortRow) {
        if (!(static_cast<size_t>(end - begin) > n / 32 && placeLongRowBySlot(begin, end, n)))
          std::sort(m_pairs.begin() + begin, m_pairs.begin() + end, [](const ListedPair& p, const ListedPair& q) { return p.b < q.b; });
        continue;
      }
      for (int k = begin + 1; k < end; ++k) {
        const ListedPair v = m_pairs[static_cast<size_t>(k)];
        int q = k - 1;
        while (q >= begin && m_pairs[static_cast<size_t>(q)].b > v.b) {
          m_pairs[static_cast<size_t>(q) + 1] = m_pairs[static_cast<size_t>(q)];
          --q;
        }
        m_pairs[static_cast<size_t>(q) + 1] = v;
      }
    }
  });
}

void NeighbourList::finish(const World& world) {
  const int n = world.size();
  // Whether the parts joined in order are sorted by (a, b): each part checked on its own range.
  const int parts = static_cast<int>(m_raw.size());
  auto before = [](const ListedPair& p, const ListedPair& q) { return p.a < q.a || (p.a == q.a && p.b < q.b); };
  std::vector<char> partSorted(static_cast<size_t>(parts), 1);
  parallelEach(parts, [&](int t) {
    const std::vector<ListedPair>& part = m_raw[static_cast<size_t>(t)];
    for (size_t k = 1; k < part.size(); ++k)
      if (!before(part[k - 1], part[k])) {
        partSorted[static_cast<size_t>(t)] = 0;
        return;
      }
  });
  if (partsInOrder(partSorted))
    joinRaw();
  else
    sortRaw(n);
  // Drop wall-wall pairs and duplicates, and fix each pair's reach for the per-step filter, range by
  // range into m_kept, then the ranges' survivors joined in order. The pairs are sorted, so a
  // duplicate follows its twin: "equal to the pair before it" is "equal to the last one kept".
  const long listed = static_cast<long>(m_pairs.size());
  m_kept.resize(m_pairs.size());
  m_rangeCount.assign(static_cast<size_t>(parallelTasks(listed, kPairGrain)), 0);
  auto keep = [&](int t, long begin, long end) {
    size_t out = static_cast<size_t>(begin);
    for (long k = begin; k < end; ++k) {
      ListedPair p = m_pairs[static_cast<size_t>(k)];
      if (world.kind[p.a] == BodyKind::Wall && world.kind[p.b] == BodyKind::Wall) continue;
      if (world.kind[p.a] == BodyKind::Vessel || world.kind[p.b] == BodyKind::Vessel) continue;  // direct
      if (k > 0 && m_pairs[static_cast<size_t>(k) - 1].a == p.a && m_pairs[static_cast<size_t>(k) - 1].b == p.b) continue;
      const Real reach = world.radius[p.a] + world.radius[p.b];
      p.reach2 = reach * reach;
      m_kept[out++] = p;
    }
    m_rangeCount[static_cast<size_t>(t)] = out - static_cast<size_t>(begin);
  };
  parallelRanges(listed, kPairGrain, keep);
  size_t kept = 0;
  for (size_t& count : m_rangeCount) kept += std::exchange(count, kept);  // now each range's offset
  parallelRanges(listed, kPairGrain, [&](int t, long begin, long) {
    const size_t at = m_rangeCount[static_cast<size_t>(t)];
    const size_t next = static_cast<size_t>(t) + 1 < m_rangeCount.size() ? m_rangeCount[static_cast<size_t>(t) + 1] : kept;
    std::copy(m_kept.begin() + begin, m_kept.begin() + begin + static_cast<std::ptrdiff_t>(next - at),
              m_pairs.begin() + static_cast<std::ptrdiff_t>(at));
  });
  m_pairs.resize(kept);
  // The reference state and the direct flags, over ranges of bodies (at 10^5 floes these copies
  // were a few milliseconds of one thread at every rebuild, while the others waited).
  const size_t bodies = static_cast<size_t>(n);
  m_x0.resize(bodies), m_y0.resize(bodies), m_angle0.resize(bodies), m_id0.resize(bodies);
  m_direct.resize(bodies), m_masked.resize(bodies);
  parallelRanges(n, kBodyGrain, [&](int, long begin, long end) {
    for (long i = begin; i < end; ++i) {
      const size_t k = static_cast<size_t>(i);
      m_x0[k] = world.x[k], m_y0[k] = world.y[k], m_angle0[k] = world.angle[k], m_id0[k] = world.id[k];
      m_direct[k] = m_masked[k] = world.kind[k] == BodyKind::Vessel;
    }
  });
  m_directList.clear();
  for (int i = 0; i < n; ++i)
    if (m_direct[static_cast<size_t>(i)]) m_directList.push_back(i);
  m_maskedBodies = static_cast<int>(m_directList.size());
  binReferences(world);
  m_sidePairs.clear();
  m_chunksKnown = false;
  m_valid = true;
  m_renamed = false;  // built from the bodies as they are
  ++m_rebuilds;
}

void NeighbourList::filterByCircles(const World& world, std::vector<CandidatePair>& out, std::vector<CandidateRange>* resting) {
  // Branch-free: every listed pair is written to a scratch row and kept by advancing the count;
  // about a third pass, so a branch would mispredict often. The scratch never shrinks. Pairs of a
  // direct body are skipped here: the direct pass below finds them; so are those of a relisted
  // floe: the side list holds them. By chunks of kChunkPairs pairs, each compacting into its own
  // stretch of the scratch; the stretches are joined in order below.
  //
  // A chunk none of whose bodies has moved since the last filter gives the last answer, which its
  // stretch still holds: the answer depends on the pairs (the same until a build or a rename, which
  // forget every chunk), the bodies' x and y, and their masks (which change only when a body moves
  // past half the skin, or at a build). Whether its bodies are still is told by update(), block by
  // block of kFlagBlock slots; a chunk's bodies lie in two spans of blocks, its first bodies' (the
  // pairs are sorted by them) and its second bodies' (ChunkSpan: a wall's row names floes far from
  // the wall's own slot, and one span over both covered the field between them). Most of a
  // resting pack is skipped without reading its pairs.
  const long listed = static_cast<long>(m_pairs.size());
  if (m_filtered.size() < m_pairs.size()) m_filtered.resize(m_pairs.size());
  const Real* x = world.x.data();
  const Real* y = world.y.data();
  const char* direct = m_direct.data();
  const char* masked = m_masked.data();
  const long chunks = (listed + kChunkPairs - 1) / kChunkPairs;
  const bool reuse = m_chunksKnown && m_stillKnown && static_cast<long>(m_chunkCount.size()) == chunks;
  m_chunkCount.resize(static_cast<size_t>(chunks)), m_chunkSpan.resize(static_cast<size_t>(chunks));
  m_chunkHead.resize(static_cast<size_t>(chunks)), m_chunkAnswers.resize(static_cast<size_t>(chunks) * kAnswerWords);
  m_answersKnown.resize(static_cast<size_t>(chunks), 0);
  const char* still = m_still;
  // Whether few blocks hold a body that moved (under an eighth): then a chunk to judge has few
  // pairs of a moving body, and its pairs of two still bodies keep their answers below. Where
  // many moved (the 824-floe field's channel), judging every pair of the chunk is cheaper than
  // telling them apart first.
  const long flagBlocks = m_movingBlocks.blocks;
  const bool fewMoved = flagBlocks > 0 && 8L * m_movingBlocks.count() < flagBlocks;
  // Finer ranges than most passes: the chunks to judge crowd around the vessel.
  const int chunkTasks = parallelCrowdedTasks(chunks, kPairGrain / kChunkPairs);
  m_rangeKept.resize(static_cast<size_t>(chunkTasks) + 1);
  auto judgeChunks = [&](int t, long firstChunk, long endChunk) {
    for (long c = firstChunk; c < endChunk; ++c) {
      const size_t chunk = static_cast<size_t>(c);
      if (reuse && m_chunkSpan[chunk].quiet(m_movingBlocks)) continue;
      const long begin = c * kChunkPairs, end = std::min(listed, begin + kChunkPairs);
      CandidatePair* dst = m_filtered.data() + begin;
      std::uint64_t* answers = &m_chunkAnswers[chunk * kAnswerWords];
      if (reuse && fewMoved && m_answersKnown[chunk]) {
        // A chunk with a body that moved: a pair of two still bodies keeps its last answer (its
        // bodies, and so its masks, are as they were), the others are judged afresh, and the
        // chunk's stretch is written again only if an answer changed. Where the vessel passes at
        // 10^5 floes, 99 % of these chunks' pairs are of two still bodies (25,000 a step), and
        // judging every pair afresh was a quarter of a step's instructions.
        bool changed = false;
        for (long k = begin; k < end; ++k) {
          const ListedPair& p = m_pairs[static_cast<size_t>(k)];
          if (still[p.a] && still[p.b]) continue;
          const Real dx = x[p.a] - x[p.b], dy = y[p.a] - y[p.b];
          const std::uint64_t keep = (dx * dx + dy * dy <= p.reach2) & !(masked[p.a] | masked[p.b]);
          const auto q = static_cast<size_t>(k - begin);
          const std::uint64_t bit = std::uint64_t{1} << (q % 64), last = answers[q / 64] & bit;
          if ((last != 0) != (keep != 0)) answers[q / 64] ^= bit, changed = true;
        }
        if (!changed) continue;  // the stretch, its count and its head hold
        int count = 0;
        for (long k = begin; k < end; ++k) {
          const auto q = static_cast<size_t>(k - begin);
          const ListedPair& p = m_pairs[static_cast<size_t>(k)];
          dst[count] = {p.a, p.b};
          count += static_cast<int>(answers[q / 64] >> (q % 64) & 1);
        }
        m_chunkCount[chunk] = count;
        m_chunkHead[chunk] = dst[0];
        continue;
      }
      // Every pair judged: keeping the answers only where few bodies moved (they cost 2 % of the
      // 824-floe field's instructions, where many do), and finding the chunk's blocks only when
      // the pairs are new (a build or a rename).
      auto judgeAll = [&](auto keepAnswers, auto findSpan) {
        std::uint64_t fresh[kAnswerWords] = {};
        int count = 0, firstB = m_pairs[static_cast<size_t>(begin)].b, lastB = firstB;
        for (long k = begin; k < end; ++k) {
          const ListedPair& p = m_pairs[static_cast<size_t>(k)];
          const Real dx = x[p.a] - x[p.b], dy = y[p.a] - y[p.b];
          const std::uint64_t keep = (dx * dx + dy * dy <= p.reach2) & !(masked[p.a] | masked[p.b]);
          if constexpr (keepAnswers) {
            const auto q = static_cast<size_t>(k - begin);
            fresh[q / 64] |= keep << (q % 64);
          }
          dst[count] = {p.a, p.b};
          count += static_cast<int>(keep);
          if constexpr (findSpan) firstB = std::min(firstB, p.b), lastB = std::max(lastB, p.b);
        }
        if constexpr (keepAnswers) std::copy(fresh, fresh + kAnswerWords, answers);
        m_answersKnown[chunk] = keepAnswers;
        m_chunkCount[chunk] = count;
        m_chunkHead[chunk] = dst[0];  // its first pair when count > 0, read by the join's walk
        if constexpr (findSpan)
          m_chunkSpan[chunk] = ChunkSpan{m_pairs[static_cast<size_t>(begin)].a / kFlagBlock,  // the pairs are sorted by a
                                         m_pairs[static_cast<size_t>(end - 1)].a / kFlagBlock, firstB / kFlagBlock, lastB / kFlagBlock};
      };
      using Yes = std::true_type;
      using No = std::false_type;
      if (!reuse)
        fewMoved ? judgeAll(Yes{}, Yes{}) : judgeAll(No{}, Yes{});
      else
        fewMoved ? judgeAll(Yes{}, No{}) : judgeAll(No{}, No{});
    }
    size_t kept = 0;  // the range's pairs, reused chunks' included: the join places the ranges with them
    for (long c = firstChunk; c < endChunk; ++c) kept += static_cast<size_t>(m_chunkCount[static_cast<size_t>(c)]);
    m_rangeKept[static_cast<size_t>(t) + 1] = kept;
  };

  // Direct bodies (the vessel, and floes that moved more than half the skin since the build) are
  // tested against the bodies near them, instead of a rebuild of the whole list every few steps
  // while the vessel shoves floes at its own speed: the bodies that are not direct through the grid
  // of references (as relisting), the direct ones in turn. The pairs are sorted afterwards, so the
  // order of the tests does not matter.
  const Real* radius = world.radius.data();
  auto directPass = [&] {
    m_directPairs.clear();
    for (const int v : m_directList) {
      const Real xv = x[v], yv = y[v], rv = radius[v];
      const bool wall = world.kind[v] == BodyKind::Wall;
      auto test = [&](int j) {
        const Real dx = xv - x[j], dy = yv - y[j], reach = rv + radius[j];
        if (!(dx * dx + dy * dy <= reach * reach)) return;
        if (j == v || (direct[j] && j < v)) return;  // a pair of two direct bodies is found once
        if (wall && world.kind[j] == BodyKind::Wall) return;
        m_directPairs.push_back(j < v ? CandidatePair{j, v} : CandidatePair{v, j});
      };
      m_grid.near(xv, yv, searchReach(xv, yv, rv, 0), [&](int j) {
        if (!direct[j]) test(j);
      });
      for (const int j : m_directList) test(j);
    }
  };
  // The side list's pairs whose circles overlap now, but those of a direct body (the direct pass
  // has them): over ranges of the side list, each range's survivors into a part of its own.
  const long side = static_cast<long>(m_sidePairs.size());
  const int sideTasks = side > 0 ? parallelTasks(side, kSidePairGrain) : 0;
  m_sideParts.resize(static_cast<size_t>(sideTasks));
  auto filterSide = [&](int t, long begin, long end) {
    std::vector<CandidatePair>& part = m_sideParts[static_cast<size_t>(t)];
    part.clear();
    for (long k = begin; k < end; ++k) {
      const ListedPair& p = m_sidePairs[static_cast<size_t>(k)];
      const Real dx = x[p.a] - x[p.b], dy = y[p.a] - y[p.b];
      if (dx * dx + dy * dy <= p.reach2 && !(direct[p.a] | direct[p.b])) part.push_back({p.a, p.b});
    }
  };
  // The three read only this step's positions and the lists, each writes its own buffers: one round
  // of the pool does them all, the chunks' ranges, the side list's and the direct pass as tasks of
  // it. Apart, the side list's filter and the direct pass ran on the calling thread while the
  // others waited (a side list under four grains is one range): at 10^5 floes, after a few
  // thousand steps, a tenth of a two-thread step.
  parallelEach(chunkTasks + sideTasks + 1, [&](int task) {
    if (task < chunkTasks) {
      judgeChunks(task, chunks * task / chunkTasks, chunks * (task + 1) / chunkTasks);
    } else if (const int t = task - chunkTasks; t < sideTasks) {
      filterSide(t, side * t / sideTasks, side * (t + 1) / sideTasks);
    } else {
      directPass();
    }
  });
  m_chunksKnown = true;
  auto before = [](CandidatePair p, CandidatePair q) { return p.a < q.a || (p.a == q.a && p.b < q.b); };
  std::sort(m_directPairs.begin(), m_directPairs.end(), before);
  // The side list's survivors, in list order, merged in: a side pair has no direct body, a direct
  // pair has one, so none is both.
  if (sideTasks > 0) {
    const size_t directCount = m_directPairs.size();
    for (const std::vector<CandidatePair>& part : m_sideParts) m_directPairs.insert(m_directPairs.end(), part.begin(), part.end());
    std::inplace_merge(m_directPairs.begin(), m_directPairs.begin() + static_cast<std::ptrdiff_t>(directCount), m_directPairs.end(),
                       before);
  }

  // The join: chunk c's pairs, merged with the direct and side pairs that fall before the next
  // non-empty chunk's first pair, go after everything of the earlier chunks. A pair is in one of
  // the three only. Each range of chunks (the same ranges as the chunks' pass above) places its
  // own: its kept pairs start after the earlier ranges' (a sum over the ranges, the only serial
  // part), and a chunk's direct pairs start at the first one not before its first pair (a search
  // of the few direct pairs). The serial walk along every chunk this replaced read what the other
  // threads had just written, a cache miss every few chunks: 11 us a step at 10^5 floes.
  // Where the caller asks (restingPairs, framework/api/still_bodies.hpp), the join also notes the
  // stretches of the output that are a chunk's pairs alone, every body of the chunk resting, and
  // leaves them unwritten.
  if (resting) resting->clear();
  if (!m_stillKnown) resting = nullptr;
  if (chunks == 0) {
    out.assign(m_directPairs.begin(), m_directPairs.end());
    return;
  }
  m_rangeKept[0] = 0;
  for (size_t t = 1; t < m_rangeKept.size(); ++t) m_rangeKept[t] += m_rangeKept[t - 1];
  const size_t directCount = m_directPairs.size();
  out.resize(m_rangeKept.back() + directCount);
  // Where chunk c's direct pairs start: none before chunk 0's, and an empty chunk takes the next
  // non-empty one's start (all of them after the last chunk).
  auto directBefore = [&](size_t c) {
    return static_cast<size_t>(std::lower_bound(m_directPairs.begin(), m_directPairs.end(), m_chunkHead[c], before) -
                               m_directPairs.begin());
  };
  // The same from a place not after the answer: steps of 1, 2, 4, ... over the pairs before the
  // head, then a search inside the last step.
  auto gallopFrom = [&](size_t from, CandidatePair head) {
    size_t lo = from, step = 1;
    while (lo + step <= directCount && before(m_directPairs[lo + step - 1], head)) lo += step, step *= 2;
    const size_t hi = std::min(lo + step - 1, directCount);
    return static_cast<size_t>(std::lower_bound(m_directPairs.begin() + static_cast<std::ptrdiff_t>(lo),
                                                m_directPairs.begin() + static_cast<std::ptrdiff_t>(hi), head, before) -
                               m_directPairs.begin());
  };
  m_directFrom.resize(static_cast<size_t>(chunks));
  m_restingParts.resize(m_rangeKept.size() - 1);
  parallelCrowdedRanges(chunks, kPairGrain / kChunkPairs, [&](int t, long firstChunk, long endChunk) {  // the ranges above
    const size_t first = static_cast<size_t>(firstChunk), end = static_cast<size_t>(endChunk), all = static_cast<size_t>(chunks);
    size_t next = end;  // the first non-empty chunk after the range: where the range's direct pairs end
    while (next < all && m_chunkCount[next] == 0) ++next;
    const size_t afterRange = next == all ? directCount : directBefore(next);
    // The range's non-empty chunks in order (their heads in pair order, as the direct pairs are):
    // a search for the first, then a gallop on from the last answer. A search of all the direct
    // pairs for every chunk was a third of this pass at 10^5 floes (906 chunks a step).
    size_t found = directCount + 1;  // none yet
    for (size_t c = first; c < end; ++c)
      if (c == 0)
        m_directFrom[c] = found = 0;
      else if (m_chunkCount[c] > 0)
        m_directFrom[c] = found = found > directCount ? directBefore(c) : gallopFrom(found, m_chunkHead[c]);
    size_t startOfNext = afterRange;
    for (size_t c = end; c-- > first;) {
      if (c != 0 && m_chunkCount[c] == 0) m_directFrom[c] = startOfNext;
      startOfNext = m_directFrom[c];
    }
    size_t kept = m_rangeKept[static_cast<size_t>(t)];
    std::vector<CandidateRange>& restingPart = m_restingParts[static_cast<size_t>(t)];
    restingPart.clear();
    for (size_t c = first; c < end; ++c) {
      const auto from = m_filtered.begin() + static_cast<std::ptrdiff_t>(c * kChunkPairs);
      const size_t directEnd = c + 1 < end ? m_directFrom[c + 1] : afterRange;
      const auto direct0 = m_directPairs.begin() + static_cast<std::ptrdiff_t>(m_directFrom[c]);
      const auto direct1 = m_directPairs.begin() + static_cast<std::ptrdiff_t>(directEnd);
      const size_t at = kept + m_directFrom[c];
      // No body restless in the chunk's blocks, and no direct pair merged in: its stretch of the
      // output is pairs of resting bodies only, which the caller reads none of, and it is left as
      // it was (restingPairs' contract): at 10^5 floes that is most of the 1.2 MB copied a step.
      const bool restingChunk = resting && m_chunkCount[c] > 0 && directEnd == m_directFrom[c] && m_chunkSpan[c].quiet(m_restlessBlocks);
      if (!restingChunk) std::merge(from, from + m_chunkCount[c], direct0, direct1, out.begin() + static_cast<std::ptrdiff_t>(at), before);
      if (restingChunk) {
        const long begin = static_cast<long>(at), stop = begin + m_chunkCount[c];
        if (!restingPart.empty() && restingPart.back().end == begin)
          restingPart.back().end = stop;
        else
          restingPart.push_back({begin, stop});
      }
      kept += static_cast<size_t>(m_chunkCount[c]);
    }
  });
  if (!resting) return;
  for (const std::vector<CandidateRange>& part : m_restingParts)
    for (const CandidateRange& r : part) {
      if (!resting->empty() && resting->back().end == r.begin)
        resting->back().end = r.end;
      else
        resting->push_back(r);
    }
}

void KeptListBroadphase::findCandidates(const World& world, std::vector<CandidatePair>& pairs) {
  switch (m_list.update(world)) {
    case NeighbourList::Need::Rebuild:
      m_list.begin();
      build(world, m_list);
      m_list.finish(world);
      break;
    case NeighbourList::Need::Relist:
      m_list.relistDirect(world);
      break;
    case NeighbourList::Need::Nothing:
      break;
  }
  filter(world, pairs);
}

void PairsWithinReach::build(const World& world, const std::vector<Real>& h, Real floor, NeighbourList& list) {
  const int n = world.size();
  if (n < 2) {
    list.begin();
    return;
  }
  // Below a few thousand bodies the grid cannot pay for its binning. Above, the grid bins and counts
  // its tests, the sweep's are estimated from a sample (without its sort), and the cheaper runs; a
  // grid test gathers its body's data, about twice a sweep test.
  m_byGrid = m_method == Method::Grid ||
             (m_method == Method::Cheaper && n >= 4096 && 2 * binInGrid(world, h, floor) < estimateSweep(world, h, floor));
  if (m_byGrid) {
    if (m_method == Method::Grid) binInGrid(world, h, floor);
    scanGrid(world, h, floor, list);
  } else {
    sortAlongX(world, h, floor);
    sweep(world, h, floor, list);
  }
}

double PairsWithinReach::estimateSweep(const World& world, const std::vector<Real>& h, Real floor) {
  // Every 16th body's span start, sorted; each sampled body's later span starts inside its span,
  // counted in the sample and scaled by 16 twice (its own weight, and the sample's).
  const int n = world.size();
  constexpr int kEvery = 16;
  m_scratch.clear();
  for (int i = 0; i < n; i += kEvery) m_scratch.push_back(world.x[i] - std::max(floor / 2, h[i]));
  std::sort(m_scratch.begin(), m_scratch.end());
  double tests = 0;
  for (int i = 0; i < n; i += kEvery) {
    const Real e = std::max(floor / 2, h[i]), lo = world.x[i] - e, hi = world.x[i] + e;
    tests += static_cast<double>(std::upper_bound(m_scratch.begin(), m_scratch.end(), hi) -
                                 std::upper_bound(m_scratch.begin(), m_scratch.end(), lo));
  }
  return tests * kEvery * kEvery;
}

void PairsWithinReach::sortAlongX(const World& world, const std::vector<Real>& h, Real floor) {
  const int n = world.size();
  const Real* x = world.x.data();
  m_lo.resize(n);
  for (int i = 0; i < n; ++i) m_lo[i] = x[i] - std::max(floor / 2, h[i]);
  if (static_cast<int>(m_order.size()) != n) {
    m_order.resize(n);
    for (int i = 0; i < n; ++i) m_order[i] = i;
  }
  // Insertion sort by lo, O(n + inversions); after a reorder of the world the old order means
  // nothing, so past a work budget sort afresh.
  long moves = 0;
  const long budget = 16L * n + 1024;
  for (int k = 1; k < n && moves <= budget; ++k) {
    const int v = m_order[k];
    const Real key = m_lo[v];
    int q = k - 1;
    while (q >= 0 && m_lo[m_order[q]] > key) {
      m_order[q + 1] = m_order[q];
      --q;
      ++moves;
    }
    m_order[q + 1] = v;
  }
  if (moves > budget) std::sort(m_order.begin(), m_order.end(), [&](int p, int q) { return m_lo[p] < m_lo[q]; });

  m_slot.resize(n), m_x.resize(n), m_y.resize(n), m_h.resize(n), m_sortedLo.resize(n), m_hi.resize(n);
  parallelRanges(n, NeighbourList::kBodyGrain, [&](int, long begin, long end) {
    for (int k = static_cast<int>(begin); k < end; ++k) {
      const int i = m_order[k];
      m_slot[k] = i, m_x[k] = x[i], m_y[k] = world.y[i], m_h[k] = h[i], m_sortedLo[k] = m_lo[i];
      m_hi[k] = x[i] + std::max(floor / 2, h[i]);
    }
  });
}

void PairsWithinReach::sweep(const World&, const std::vector<Real>&, Real floor, NeighbourList& list) {
  const int n = static_cast<int>(m_slot.size());
  // Over contiguous ranges of sorted positions, each range into its own part.
  list.begin(parallelTasks(n, kGrain));
  parallelRanges(n, kGrain, [&](int t, long begin, long end) {
    for (int k = static_cast<int>(begin); k < end; ++k) {
      const Real hi = m_hi[k];
      for (int q = k + 1; q < n && m_sortedLo[q] <= hi; ++q) {
        const Real dx = m_x[k] - m_x[q], dy = m_y[k] - m_y[q], reach = std::max(floor, m_h[k] + m_h[q]);
        if (dx * dx + dy * dy <= reach * reach) list.add(t, m_slot[k], m_slot[q]);
      }
    }
  });
}

double PairsWithinReach::binInGrid(const World& world, const std::vector<Real>& h, Real floor) {
  const int n = world.size();
  const Real* x = world.x.data();
  const Real* y = world.y.data();
  m_extent.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) m_extent[i] = std::max(floor / 2, h[i]);
  // Large: more than twice the 99th percentile of the extents (walls, the odd giant floe). The
  // cell: twice the largest of the others, so any pair of them within reach is in adjacent cells.
  const Real cut = grid_cells::largeCut(m_extent.data(), n, m_scratch);
  m_large.clear();
  m_isLarge.assign(static_cast<size_t>(n), 0);
  Real largest = 0, x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  bool any = false;
  for (int i = 0; i < n; ++i) {
    // A body at no finite place is tested the plain way too.
    if (m_extent[i] > cut || !std::isfinite(x[i]) || !std::isfinite(y[i])) {
      m_large.push_back(i), m_isLarge[static_cast<size_t>(i)] = 1;
      continue;
    }
    largest = std::max(largest, m_extent[i]);
    x0 = any ? std::min(x0, x[i]) : x[i], x1 = any ? std::max(x1, x[i]) : x[i];
    y0 = any ? std::min(y0, y[i]) : y[i], y1 = any ? std::max(y1, y[i]) : y[i];
    any = true;
  }
  // A hair wider than 2 e: a pair exactly at reach stays within one cell of each other however the
  // division rounds.
  const grid_cells::Layout cells = grid_cells::layOut(x0, x1, y0, y1, 2 * largest * (1 + Real(1e-9)), n);
  const Real cell = cells.cell;
  m_nx = cells.nx, m_ny = cells.ny;

  // The counting sort of the ordinary bodies by cell.
  m_cellOf.assign(static_cast<size_t>(n), -1);
  m_cellStart.assign(static_cast<size_t>(m_nx) * static_cast<size_t>(m_ny) + 1, 0);
  for (int i = 0; i < n; ++i) {
    if (m_isLarge[static_cast<size_t>(i)]) continue;
    const int c = grid_cells::cellAlong(y[i], y0, cell, m_ny) * m_nx + grid_cells::cellAlong(x[i], x0, cell, m_nx);
    m_cellOf[static_cast<size_t>(i)] = c;
    ++m_cellStart[static_cast<size_t>(c) + 1];
  }
  for (size_t c = 1; c < m_cellStart.size(); ++c) m_cellStart[c] += m_cellStart[c - 1];
  m_sorted.resize(static_cast<size_t>(m_cellStart.back()));
  std::vector<int> fill(m_cellStart.begin(), m_cellStart.end() - 1);
  for (int i = 0; i < n; ++i)
    if (const int c = m_cellOf[static_cast<size_t>(i)]; c >= 0) m_sorted[static_cast<size_t>(fill[static_cast<size_t>(c)]++)] = i;

  // The grid's tests: each cell's bodies against its 9 cells' (about half of them are skipped as
  // found from the other side), and each large body against every body.
  double tests = static_cast<double>(m_large.size()) * n;
  for (int cy = 0; cy < m_ny; ++cy)
    for (int cx = 0; cx < m_nx; ++cx) {
      const int c = cy * m_nx + cx, here = m_cellStart[static_cast<size_t>(c) + 1] - m_cellStart[static_cast<size_t>(c)];
      if (!here) continue;
      int around = 0;
      for (int gy = std::max(cy - 1, 0); gy <= std::min(cy + 1, m_ny - 1); ++gy)
        around += m_cellStart[static_cast<size_t>(gy * m_nx + std::min(cx + 1, m_nx - 1)) + 1] -
                  m_cellStart[static_cast<size_t>(gy * m_nx + std::max(cx - 1, 0))];
      tests += 0.5 * here * around;
    }
  return tests;
}

void PairsWithinReach::scanGrid(const World& world, const std::vector<Real>& h, Real floor, NeighbourList& list) {
  const int n = world.size(), nx = m_nx, ny = m_ny, ordinary = static_cast<int>(m_sorted.size());
  const Real* x = world.x.data();
  const Real* y = world.y.data();
  // The rule's exact test (the sweep's, operand for operand up to the order of a sum and a square).
  auto within = [&](int a, int b) {
    const Real dx = x[a] - x[b], dy = y[a] - y[b], reach = std::max(floor, h[a] + h[b]);
    return dx * dx + dy * dy <= reach * reach;
  };
  // Each ordinary body against the later bodies (by slot) of its 9 cells, cell by cell; then each
  // large body against every body (a pair of two large ones once).
  const int gridTasks = parallelTasks(ordinary, kGrain);
  const int largeTasks = m_large.empty() ? 0 : parallelTasks(n, kGrain);
  list.begin(gridTasks + largeTasks);
  parallelRanges(ordinary, kGrain, [&](int t, long begin, long end) {
    for (long p = begin; p < end; ++p) {
      const int i = m_sorted[static_cast<size_t>(p)];
      const int c = m_cellOf[static_cast<size_t>(i)], cx = c % nx, cy = c / nx;
      // The 3 cells of a row are consecutive in the sorted bodies: one run each.
      for (int gy = std::max(cy - 1, 0); gy <= std::min(cy + 1, ny - 1); ++gy) {
        const int from = m_cellStart[static_cast<size_t>(gy * nx + std::max(cx - 1, 0))];
        const int to = m_cellStart[static_cast<size_t>(gy * nx + std::min(cx + 1, nx - 1)) + 1];
        for (int q = from; q < to; ++q) {
          const int j = m_sorted[static_cast<size_t>(q)];
          if (j > i && within(i, j)) list.add(t, i, j);
        }
      }
    }
  });
  if (largeTasks)
    parallelRanges(n, kGrain, [&](int t, long begin, long end) {
      for (int l : m_large)
        for (int j = static_cast<int>(begin); j < end; ++j)
          if (j != l && !(m_isLarge[static_cast<size_t>(j)] && j < l) && within(l, j)) list.add(gridTasks + t, l, j);
    });
}

BroadphaseSettings checkedSettings(const BroadphaseSettings& settings) {
  auto check = [](Real value, const char* key) {
    if (!std::isfinite(value) || value < 0)
      throw InputError(std::string("broadphase ") + key + " must be a finite length >= 0 m, got " + std::to_string(value));
  };
  check(settings.skin, "skin");
  check(settings.fixedRadius, "fixed_radius");
  check(settings.cellSize, "cell_size");
  return settings;
}

Real largestFloeRadius(const World& world) {
  Real floe = 0, movable = 0;
  for (int i = 0; i < world.size(); ++i) {
    if (world.kind[i] == BodyKind::Floe && world.radius[i] > floe) floe = world.radius[i];
    if (world.kind[i] != BodyKind::Wall && world.radius[i] > movable) movable = world.radius[i];
  }
  return floe > 0 ? floe : movable;
}

}  // namespace gem
