// The broadphase interface: proposes candidate pairs, knows nothing about events
// (docs/architecture.md "The one idea"). Every strategy must be conservative: it may propose pairs that
// do not touch (the narrowphase drops them) but must never miss a pair whose polygons overlap.
// Pairs come out as (a, b) slot indices with a < b, sorted by (a, b): so the contact set and the
// order in which each body sums its contacts do not depend on the strategy (bit-identical runs).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "framework/world/world.hpp"

namespace gem {

struct CandidatePair {
  int a, b;  // slot indices, a < b
};

// Settings every strategy understands; strategy-specific ones have defaults derived from the world.
struct BroadphaseSettings {
  Real skin = 2;           // m: extra margin of a kept neighbour list (docs/model.md 9)
  Real fixedRadius = 0;    // m: fixed_radius's global radius; 0 = 2 x the largest bounding radius
  Real cellSize = 0;       // m: uniform_grid's cell size; 0 = the largest bounding diameter + skin
};

class Broadphase {
 public:
  virtual ~Broadphase() = default;
  virtual std::string name() const = 0;
  // Candidate pairs for the world as it is now (sorted, a < b). A strategy that keeps a list
  // between steps rebuilds it itself when the never-miss rule of docs/model.md 9 asks.
  virtual void findCandidates(const World& world, std::vector<CandidatePair>& pairs) = 0;
  // Bodies were added, removed or reordered: any kept list is stale.
  virtual void invalidate() = 0;
  // How many times the strategy has (re)built its structure: for benchmarks and tests.
  virtual long rebuilds() const { return 0; }
};

}  // namespace gem
