// The broadphase interface: proposes candidate pairs, knows nothing about events
// (docs/architecture.md "The one idea"). Every strategy must be conservative: it may propose pairs that
// do not touch (the narrowphase drops them) but must never miss a pair whose polygons overlap.
// Every pair whose bounding circles overlap is enough, and so is every pair whose world boxes
// overlap (each set holds every pair whose polygons overlap; neither holds the other).
// The narrowphase gets the pairs as (a, b) slot indices with a < b, sorted by (a, b), each once: so
// the contact set and the order in which each body sums its contacts do not depend on the strategy
// (bit-identical runs). The built-in strategies return them so; a plugin's may return them in any
// order and orientation, repeated, and the CPU stepper normalises them (normalizeCandidatePairs).
#pragma once
#include <algorithm>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "framework/world/world.hpp"

namespace gem {

struct CandidatePair {
  int a, b;  // slot indices; a < b once normalised (normalizeCandidatePairs)
};

// The settings of the built-in strategies, as a scenario gives them ([broadphase.NAME], or the
// older [simulation] keys; docs/scenario.md). Each strategy declares the keys it reads
// (`static constexpr const char* kSettings[] = {"skin", "cell_size"};` in its class, the CPU and
// the device part each for itself): a key given for a strategy that does not declare it is refused
// when the scenario is read, and one that a backend's part of the strategy does not honour is
// refused by that backend, never silently ignored. A plugin's strategy may declare only these keys
// (broadphaseSettingKeys): it cannot add keys of its own. Every strategy gets the whole struct,
// with the defaults below where the scenario gives nothing.
struct BroadphaseSettings {
  Real skin = 2;                   // m: extra margin of a kept neighbour list (docs/model.md 9)
  Real fixedRadius = 0;            // m: fixed_radius's global radius; 0 = 2 x the largest floe bounding radius + skin
  Real cellSize = 0;               // m: uniform_grid's cell size; 0 = 2 x the largest floe bounding radius (no skin)
  std::vector<std::string> given;  // the keys the scenario set ("skin", "cell_size", ...)
};

// Every setting key any built-in strategy reads.
inline const std::vector<std::string>& broadphaseSettingKeys() {
  static const std::vector<std::string> keys{"skin", "fixed_radius", "cell_size"};
  return keys;
}

// The keys a strategy class declares (its kSettings), or none.
template <class Strategy>
std::vector<std::string> declaredBroadphaseSettings() {
  if constexpr (requires { Strategy::kSettings; })
    return {std::begin(Strategy::kSettings), std::end(Strategy::kSettings)};
  else
    return {};
}

// A plugin strategy's pairs made what the contract above asks: each pair a < b (a pair of one slot
// dropped), sorted by (a, b), each once. The CPU stepper applies it to strategies from plugins, so a
// strategy that proposes its pairs in any order, or twice, still gives the built-ins' trajectories;
// the built-ins already keep the contract (checked in their tests) and skip it.
inline void normalizeCandidatePairs(std::vector<CandidatePair>& pairs) {
  auto before = [](const CandidatePair& x, const CandidatePair& y) { return x.a < y.a || (x.a == y.a && x.b < y.b); };
  bool ordered = true;
  size_t kept = 0;
  for (size_t k = 0; k < pairs.size(); ++k) {
    CandidatePair p = pairs[k];
    if (p.a > p.b) std::swap(p.a, p.b);
    if (p.a == p.b) continue;
    if (kept > 0 && !before(pairs[kept - 1], p)) ordered = false;
    pairs[kept++] = p;
  }
  pairs.resize(kept);
  if (ordered) return;
  std::sort(pairs.begin(), pairs.end(), before);
  pairs.erase(
      std::unique(pairs.begin(), pairs.end(), [](const CandidatePair& x, const CandidatePair& y) { return x.a == y.a && x.b == y.b; }),
      pairs.end());
}

class Broadphase {
 public:
  virtual ~Broadphase() = default;
  virtual std::string name() const = 0;
  // Candidate pairs for the world as it is now; `pairs` still holds the last step's: clear it
  // first. The built-ins return them sorted by (a, b) with a < b, each once; a plugin's may come in
  // any order and orientation, repeated, or as (i, i) (normalizeCandidatePairs, above). A strategy
  // that keeps a list between steps rebuilds it itself when the never-miss rule of docs/model.md 9 asks.
  virtual void findCandidates(const World& world, std::vector<CandidatePair>& pairs) = 0;
  // Bodies were added, removed or reordered: any kept list is stale.
  virtual void invalidate() = 0;
  // Bodies were added, removed or moved to other slots (a break, the re-sort), and every other
  // body kept its id, shape and state: a strategy that can follow the bodies by id may keep its
  // list (the kept lists do, docs/model.md 9); by default it is invalidate().
  virtual void bodiesRenamed() { invalidate(); }
  // How many times the strategy has (re)built its structure: for benchmarks and tests.
  virtual long rebuilds() const { return 0; }
};

}  // namespace gem
