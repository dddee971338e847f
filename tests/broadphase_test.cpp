// Broadphase strategies (docs/model.md 9): every strategy, reached through the registry by name, must
// propose a superset of the truly overlapping pairs (exact separating axes, written here), sorted,
// unique, a < b, never two walls; keep doing so while bodies move (the rebuild rule), rebuild only
// when the rule asks, and after invalidate(). Filtered by exact overlap, all agree with all_pairs.
#include "framework/api/broadphase.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "broadphase/kept_list/neighbour_list.hpp"
#include "broadphase/kept_list/reference_grid.hpp"
#include "framework/api/errors.hpp"
#include "framework/api/parallel.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/still_bodies.hpp"
#include "framework/step/thread_pool.hpp"
#include "framework/world/world.hpp"

namespace gem {
namespace {

const std::vector<std::string> kStrategies = {"all_pairs", "fixed_radius", "variable_radius", "uniform_grid", "triangulation_mesh"};
// Strategies whose per-step output is exactly "bounding circles overlap" (the same set as all_pairs).
const std::vector<std::string> kCircleStrategies = {"fixed_radius", "variable_radius"};

std::unique_ptr<Broadphase> make(const std::string& name, BroadphaseSettings s = {}) { return Registry::global().broadphase(name).make(s); }

// ------------------------------------------------------------------------------------ worlds
BodySpec spec(BodyKind kind, std::vector<Vec2> vertices) {
  BodySpec s;
  s.kind = kind;
  s.vertices = std::move(vertices);
  return s;
}

std::vector<Vec2> regularPolygon(Vec2 c, Real r, int n, Real rot) {
  std::vector<Vec2> v;
  for (int k = 0; k < n; ++k) {
    Real a = rot + 2 * kPi * k / n;
    v.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
  }
  return v;
}

std::vector<Vec2> rectangle(Vec2 c, Real w, Real h, Real rot) {
  std::vector<Vec2> v;
  const Real hx[4] = {-w / 2, w / 2, w / 2, -w / 2}, hy[4] = {-h / 2, -h / 2, h / 2, h / 2};
  for (int k = 0; k < 4; ++k) v.push_back(c + rotate(Vec2{hx[k], hy[k]}, rot));
  return v;
}

// Random rectangles and hexagons (some overlapping) in a square of side `side`, a vessel, and
// `walls` long thin walls: the channel sides and diagonals across the field.
World randomWorld(unsigned seed, int floes, Real side, int walls = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(0, 1);
  World w;
  for (int k = 0; k < walls; ++k) {
    Vec2 c{side / 2, k == 0 ? Real(-3) : k == 1 ? side + 3 : side * u(rng)};
    Real rot = k < 2 ? Real(0) : kPi * u(rng);
    w.addBody(spec(BodyKind::Wall, rectangle(c, side * Real(1.2), 2, rot)));
  }
  w.addBody(spec(BodyKind::Vessel, {{side / 2 - 20, side / 2 - 4},
                                    {side / 2 + 15, side / 2 - 4},
                                    {side / 2 + 22, side / 2},
                                    {side / 2 + 15, side / 2 + 4},
                                    {side / 2 - 20, side / 2 + 4}}));
  for (int k = 0; k < floes; ++k) {
    Vec2 c{side * u(rng), side * u(rng)};
    Real size = 1 + 7 * u(rng) * u(rng);
    if (u(rng) < 0.5)
      w.addBody(spec(BodyKind::Floe, rectangle(c, size * (0.5 + u(rng)), size * (0.3 + u(rng)), 2 * kPi * u(rng))));
    else
      w.addBody(spec(BodyKind::Floe, regularPolygon(c, size / 2, 3 + static_cast<int>(u(rng) * 7), 2 * kPi * u(rng))));
  }
  return w;
}

// ------------------------------------------------------------------------------------ truth
// Exact separating-axis test of two convex polygons, closed sets: touching counts as overlapping.
bool polygonsOverlap(const Vec2* p, int n, const Vec2* q, int m) {
  for (int pass = 0; pass < 2; ++pass) {
    for (int i = 0; i < n; ++i) {
      Vec2 axis = perpLeft(p[(i + 1) % n] - p[i]);
      Real pmin = dot(axis, p[0]), pmax = pmin, qmin = dot(axis, q[0]), qmax = qmin;
      for (int k = 1; k < n; ++k) pmin = std::min(pmin, dot(axis, p[k])), pmax = std::max(pmax, dot(axis, p[k]));
      for (int k = 1; k < m; ++k) qmin = std::min(qmin, dot(axis, q[k])), qmax = std::max(qmax, dot(axis, q[k]));
      if (pmax < qmin || qmax < pmin) return false;
    }
    std::swap(p, q);
    std::swap(n, m);
  }
  return true;
}

using PairSet = std::vector<std::pair<int, int>>;

bool overlapping(const World& w, int a, int b) {
  Vec2 pa[kMaxVertices], pb[kMaxVertices];
  const int na = w.worldVertices(a, pa), nb = w.worldVertices(b, pb);
  return polygonsOverlap(pa, na, pb, nb);
}

PairSet truthPairs(const World& w) {
  PairSet out;
  for (int a = 0; a < w.size(); ++a)
    for (int b = a + 1; b < w.size(); ++b) {
      if (w.kind[a] == BodyKind::Wall && w.kind[b] == BodyKind::Wall) continue;
      Real dx = w.x[a] - w.x[b], dy = w.y[a] - w.y[b], r = w.radius[a] + w.radius[b];
      if (dx * dx + dy * dy > r * r * (1 + 1e-9)) continue;
      if (overlapping(w, a, b)) out.push_back({a, b});
    }
  return out;
}

PairSet toSet(const std::vector<CandidatePair>& pairs) {
  PairSet out;
  for (auto p : pairs) out.push_back({p.a, p.b});
  return out;
}

PairSet exactOnly(const World& w, const PairSet& pairs) {
  PairSet out;
  for (auto p : pairs)
    if (overlapping(w, p.first, p.second)) out.push_back(p);
  return out;
}

// Sorted strictly (so unique), a < b, in range, no wall-wall pair, and a superset of truth.
void checkCandidates(const World& w, const PairSet& got, const PairSet& truth, const std::string& what) {
  for (size_t k = 0; k < got.size(); ++k) {
    auto [a, b] = got[k];
    ASSERT_TRUE(0 <= a && a < b && b < w.size()) << what << ": bad pair " << a << "," << b;
    ASSERT_FALSE(w.kind[a] == BodyKind::Wall && w.kind[b] == BodyKind::Wall) << what << ": wall-wall pair";
    if (k > 0) {
      ASSERT_LT(got[k - 1], got[k]) << what << ": not sorted or not unique at " << k;
    }
  }
  for (auto p : truth)
    ASSERT_TRUE(std::binary_search(got.begin(), got.end(), p)) << what << ": missed overlapping pair " << p.first << "," << p.second;
}

// One query of every strategy on w: candidate checks, and agreement with all_pairs.
void checkAll(const World& w, std::vector<std::unique_ptr<Broadphase>>& strategies, const std::string& what) {
  const PairSet truth = truthPairs(w);
  std::vector<CandidatePair> pairs;
  PairSet reference;
  for (auto& s : strategies) {
    s->findCandidates(w, pairs);
    const PairSet got = toSet(pairs);
    checkCandidates(w, got, truth, what + " " + s->name());
    if (s->name() == "all_pairs") reference = got;
    ASSERT_EQ(exactOnly(w, got), truth) << what << " " << s->name();
    if (std::find(kCircleStrategies.begin(), kCircleStrategies.end(), s->name()) != kCircleStrategies.end()) {
      ASSERT_EQ(got, reference) << what << " " << s->name() << ": circle-overlap set differs from all_pairs";
    }
  }
}

std::vector<std::unique_ptr<Broadphase>> makeAll(BroadphaseSettings s = {}) {
  std::vector<std::unique_ptr<Broadphase>> out;
  for (const auto& name : kStrategies) out.push_back(make(name, s));
  return out;
}

// Moves every movable body by a random step of length up to `step` and turns it by up to `turn`.
void jiggle(World& w, std::mt19937& rng, Real step, Real turn) {
  std::uniform_real_distribution<Real> u(-1, 1);
  for (int i = 0; i < w.size(); ++i) {
    if (w.kind[i] == BodyKind::Wall) continue;
    Real s = step * std::fabs(u(rng)), dir = kPi * u(rng);
    w.x[i] += s * std::cos(dir);
    w.y[i] += s * std::sin(dir);
    w.angle[i] += turn * u(rng);
  }
}

// ------------------------------------------------------------------------------------ tests
TEST(Broadphase, RegistryHasEveryStrategy) {
  for (const auto& name : kStrategies) {
    auto s = make(name);
    ASSERT_NE(s, nullptr);
    EXPECT_EQ(s->name(), name);
  }
}

TEST(Broadphase, SmallExactCases) {
  // Two unit squares side by side: apart, touching along an edge, overlapping.
  for (Real gap : {Real(0.5), Real(0), Real(-0.25)}) {
    World w;
    w.addBody(spec(BodyKind::Floe, rectangle({0, 0}, 1, 1, 0)));
    w.addBody(spec(BodyKind::Floe, rectangle({1 + gap, 0}, 1, 1, 0)));
    auto all = makeAll();
    checkAll(w, all, "squares gap " + std::to_string(gap));
    std::vector<CandidatePair> pairs;
    all.back()->findCandidates(w, pairs);  // triangulation_mesh
    EXPECT_EQ(pairs.size(), gap <= 0 ? 1u : 0u) << gap;
  }
  // Two squares 0.2 m apart side by side, one shifted up: their bounding circles overlap, the
  // polygons do not. The circle strategies propose the pair; the triangle mesh drops it.
  World w;
  w.addBody(spec(BodyKind::Floe, rectangle({0, 0}, 2, 2, 0)));
  w.addBody(spec(BodyKind::Floe, rectangle({2.2, 1.5}, 2, 2, 0)));
  std::vector<CandidatePair> pairs;
  make("variable_radius")->findCandidates(w, pairs);
  EXPECT_EQ(pairs.size(), 1u);
  make("triangulation_mesh")->findCandidates(w, pairs);
  EXPECT_EQ(pairs.size(), 0u);
  // Two walls crossing are never a pair.
  World walls;
  walls.addBody(spec(BodyKind::Wall, rectangle({0, 0}, 100, 2, 0)));
  walls.addBody(spec(BodyKind::Wall, rectangle({0, 0}, 100, 2, kPi / 2)));
  for (const auto& name : kStrategies) {
    make(name)->findCandidates(walls, pairs);
    EXPECT_TRUE(pairs.empty()) << name;
  }
}

TEST(Broadphase, RandomWorldsSupersetOfTruth) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    World w = randomWorld(seed, 250, 150, 2 + seed % 3);
    auto all = makeAll();
    checkAll(w, all, "seed " + std::to_string(seed));
  }
}

// The kept lists themselves, right after a build: exactly the pairs within R_a + R_b + skin (and,
// for fixed_radius, also those within the fixed radius), never two walls, never the vessel.
// The kept lists' build has two exact methods, a sweep along x and a uniform grid with the few
// very large bodies tested against all (neighbour_list.hpp, PairsWithinReach): on fields that
// give the grid every case (walls across the field, giant floes, bodies at about the reach of each
// other, a huge box), both list exactly the pairs the rule accepts, on 1 to
// 4 threads. The cheaper one runs: a square field of thousands of floes takes the grid, a channel
// long in x the sweep.
TEST(Broadphase, KeptListBuildsBySweepAndByGridListTheSamePairs) {
  for (int field = 0; field < 3; ++field) {
    World w = randomWorld(29 + field, field == 2 ? 300 : 5000, field == 2 ? Real(1e7) : Real(900));
    if (field == 1) {
      w.addBody(spec(BodyKind::Floe, regularPolygon({450, 450}, 60, 8, 0)));  // two giants
      w.addBody(spec(BodyKind::Floe, regularPolygon({200, 700}, 45, 6, 0)));
      // Two floes at about their reach (centres 2 (R + skin / 2) apart along x).
      w.addBody(spec(BodyKind::Floe, regularPolygon({100, 100}, 1, 4, 0)));
      w.addBody(spec(BodyKind::Floe, regularPolygon({100, 100}, 1, 4, 0)));
      w.x[static_cast<size_t>(w.size() - 1)] = 100 + 2 * (w.radius[static_cast<size_t>(w.size() - 1)] + Real(0.75));
    }
    std::vector<Real> h(static_cast<size_t>(w.size()));
    for (int i = 0; i < w.size(); ++i) h[static_cast<size_t>(i)] = w.radius[static_cast<size_t>(i)] + Real(0.75);
    for (Real floor : {Real(0), Real(12)}) {
      SCOPED_TRACE(::testing::Message() << "field " << field << " floor " << floor);
      PairSet expected;
      for (int a = 0; a < w.size(); ++a)
        for (int b = a + 1; b < w.size(); ++b) {
          if (w.kind[a] == BodyKind::Wall && w.kind[b] == BodyKind::Wall) continue;
          if (w.kind[a] == BodyKind::Vessel || w.kind[b] == BodyKind::Vessel) continue;  // direct
          const Real dx = w.x[a] - w.x[b], dy = w.y[a] - w.y[b], reach = std::max(floor, h[a] + h[b]);
          if (dx * dx + dy * dy <= reach * reach) expected.push_back({a, b});
        }
      for (auto method : {PairsWithinReach::Method::Sweep, PairsWithinReach::Method::Grid})
        for (int threads : {1, 2, 4}) {
          ThreadPool pool(threads);
          const ParallelScope lend(&pool);
          PairsWithinReach build;
          build.use(method);
          NeighbourList list(Real(1.5));
          build.build(w, h, floor, list);
          list.finish(w);
          EXPECT_EQ(build.lastBuiltByGrid(), method == PairsWithinReach::Method::Grid);
          PairSet listed;
          for (const ListedPair& p : list.pairs()) listed.push_back({p.a, p.b});
          EXPECT_EQ(listed, expected) << (method == PairsWithinReach::Method::Grid ? "grid" : "sweep") << ", " << threads << " threads";
        }
    }
  }
  // Which one runs by itself.
  std::vector<Real> h;
  auto chosen = [&](const World& w) {
    h.assign(w.radius.begin(), w.radius.end());
    PairsWithinReach build;
    NeighbourList list(Real(1.5));
    build.build(w, h, 0, list);
    return build.lastBuiltByGrid();
  };
  EXPECT_TRUE(chosen(randomWorld(5, 20000, 2000)));  // square: the sweep's tests grow as n^1.5
  World channel;
  for (int k = 0; k < 8000; ++k) channel.addBody(spec(BodyKind::Floe, regularPolygon({Real(3) * k, Real(k % 3)}, 1, 5, 0)));
  EXPECT_FALSE(chosen(channel));  // one row along x: the sweep meets only its neighbours
}

TEST(Broadphase, KeptListsHoldExactlyTheSkinPairs) {
  World w = randomWorld(17, 300, 140);
  Real largestFloe = 0;
  for (int i = 0; i < w.size(); ++i)
    if (w.kind[i] == BodyKind::Floe) largestFloe = std::max(largestFloe, w.radius[i]);
  for (Real fixedSetting : {Real(0), Real(25)}) {
    BroadphaseSettings s;
    s.skin = Real(1.5);
    s.fixedRadius = fixedSetting;
    for (const auto& name : kStrategies) {
      if (name == "all_pairs" || name == "uniform_grid") continue;  // no kept list
      auto b = make(name, s);
      std::vector<CandidatePair> pairs;
      b->findCandidates(w, pairs);
      const auto* kept = dynamic_cast<const KeptListBroadphase*>(b.get());
      ASSERT_NE(kept, nullptr) << name;
      PairSet listed;
      for (const ListedPair& p : kept->list().pairs()) listed.push_back({p.a, p.b});
      const Real fixed = name != "fixed_radius" ? Real(0) : fixedSetting > 0 ? fixedSetting : 2 * largestFloe + s.skin;
      PairSet expected;
      for (int a = 0; a < w.size(); ++a)
        for (int b2 = a + 1; b2 < w.size(); ++b2) {
          if (w.kind[a] == BodyKind::Wall && w.kind[b2] == BodyKind::Wall) continue;
          // The vessel is never listed: it is tested directly every step.
          if (w.kind[a] == BodyKind::Vessel || w.kind[b2] == BodyKind::Vessel) continue;
          const Real dx = w.x[a] - w.x[b2], dy = w.y[a] - w.y[b2];
          const Real reach = std::max(fixed, (w.radius[a] + s.skin / 2) + (w.radius[b2] + s.skin / 2));
          if (dx * dx + dy * dy <= reach * reach) expected.push_back({a, b2});
        }
      EXPECT_EQ(listed, expected) << name << " fixedRadius " << fixedSetting;
    }
  }
}

TEST(Broadphase, EmptyAndSingleBody) {
  World w;
  std::vector<CandidatePair> pairs{{0, 1}};
  for (const auto& name : kStrategies) {
    auto s = make(name);
    s->findCandidates(w, pairs);
    EXPECT_TRUE(pairs.empty()) << name;
    w.addBody(spec(BodyKind::Floe, rectangle({0, 0}, 1, 1, 0)));
    s->findCandidates(w, pairs);
    EXPECT_TRUE(pairs.empty()) << name;
    w = World{};
  }
}

// The rebuild rule under motion: every body drifts at its own steady velocity (so pairs close in
// at up to twice the step, the worst case for a kept list) plus a little noise, and turns; steps
// below skin / 2 for most phases, beyond it for some (a rebuild at every step).
TEST(Broadphase, MovingBodiesNeverMissed) {
  World w = randomWorld(42, 300, 120);
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  std::vector<Vec2> velocity(w.size());
  for (auto& v : velocity) v = rotate(Vec2{std::fabs(u(rng)), 0}, kPi * u(rng));
  BroadphaseSettings s;
  s.skin = 2;
  auto all = makeAll(s);
  long truthTotal = 0;
  for (int step = 0; step < 240; ++step) {
    const bool big = (step / 30) % 4 == 3;
    const Real speed = big ? Real(1.3) : Real(0.17);
    for (int i = 0; i < w.size(); ++i) {
      if (w.kind[i] == BodyKind::Wall) continue;
      // Bounce back every 60 steps so that the field neither disperses nor piles up.
      const Real sign = (step / 60) % 2 == 0 ? Real(1) : Real(-1);
      w.x[i] += sign * speed * velocity[i].x + Real(0.02) * u(rng);
      w.y[i] += sign * speed * velocity[i].y + Real(0.02) * u(rng);
      w.angle[i] += (big ? Real(0.2) : Real(0.02)) * u(rng);
    }
    truthTotal += static_cast<long>(truthPairs(w).size());
    checkAll(w, all, "step " + std::to_string(step));
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(truthTotal, 240 * 20);  // the test means something only if bodies do touch
  for (auto& b : all)
    if (b->name() != "all_pairs" && b->name() != "uniform_grid") {  // those two keep no list
      EXPECT_LT(b->rebuilds(), 160) << b->name();
    }
}

// Relisting (NeighbourList::relistDirect) under the motion it is for and the motion that tests its
// 1.5-skin reach: each step a few floes jump 1.2 m (past half the skin: direct, then relisted once
// more than kRelistPast are), while every floe swings about its own base by up to 0.49 m, each in
// its own phase and direction, so that a floe listed at a relist can close in on a relisted one from
// the far end of its swing. Every step, every kept-list strategy gives all_pairs' candidates.
TEST(Broadphase, RelistedFloesNeverMissAPair) {
  World w = randomWorld(17, 400, 130);
  std::mt19937 rng(5);
  std::uniform_real_distribution<Real> u(-1, 1);
  std::uniform_int_distribution<int> pick(0, w.size() - 1);
  std::vector<Vec2> base(w.size()), swing(w.size());
  std::vector<Real> phase(w.size());
  for (int i = 0; i < w.size(); ++i) {
    base[i] = {w.x[i], w.y[i]};
    swing[i] = rotate(Vec2{Real(0.49), 0}, kPi * u(rng));  // peak to peak just under half the 2 m skin
    phase[i] = kPi * u(rng);
  }
  BroadphaseSettings s;
  s.skin = 2;
  auto all = makeAll(s);
  for (int step = 0; step < 200; ++step) {
    for (int jumps = 0; jumps < 4; ++jumps) {
      const int i = pick(rng);
      if (w.kind[i] == BodyKind::Floe) base[i] = base[i] + rotate(Vec2{Real(1.2), 0}, kPi * u(rng));
    }
    for (int i = 0; i < w.size(); ++i) {
      if (w.kind[i] != BodyKind::Floe) continue;
      const Real t = std::sin(phase[i] + Real(0.7) * static_cast<Real>(step));
      w.x[i] = base[i].x + t * swing[i].x, w.y[i] = base[i].y + t * swing[i].y;
    }
    checkAll(w, all, "step " + std::to_string(step));
    if (HasFatalFailure()) return;
  }
  for (auto& b : all) {
    const auto* kept = dynamic_cast<const KeptListBroadphase*>(b.get());
    if (!kept) continue;
    EXPECT_GE(kept->list().relists(), 40) << b->name() << ": relisting went untested";
    EXPECT_LT(b->rebuilds(), 20) << b->name() << ": relisting should spare most rebuilds";
  }
}

// The worst case of the relist reach, by hand (skin 2 m; squares of side sqrt 2, so R = 1 m and the
// circles touch at 2 m): floe B, 0.9 m beyond touching A at the build, swings 0.99 m away; A and
// 8 far floes jump 1.01 m, so 9 are direct and their rows are relisted, with A and B 2.9 m beyond
// touching: past one skin, within 1.5. Then B swings 1.98 m back and A 0.99 m towards it: their
// circles overlap, and neither has passed half the skin since its reference, so only A's relisted
// row can hold the pair. A reach of one skin would miss it.
TEST(Broadphase, ARelistedRowCoversWhatItsNeighboursCanStillTravel) {
  World w;
  const Real side = std::sqrt(Real(2)), touch = 2;                                    // R_a + R_b
  w.addBody(spec(BodyKind::Floe, rectangle({0, 0}, side, side, 0)));                  // A
  w.addBody(spec(BodyKind::Floe, rectangle({touch + Real(0.9), 0}, side, side, 0)));  // B
  for (int k = 0; k < 80; ++k)
    w.addBody(spec(BodyKind::Floe, rectangle({Real(100 + 10 * (k % 10)), Real(100 + 10 * (k / 10))}, side, side, 0)));
  BroadphaseSettings s;
  s.skin = 2;
  auto all = makeAll(s);
  checkAll(w, all, "build");
  w.x[1] += Real(0.99);
  w.x[0] -= Real(1.01);
  for (int k = 2; k < 10; ++k) w.y[k] += Real(1.01);
  checkAll(w, all, "relist");
  w.x[1] -= Real(1.98);
  w.x[0] += Real(0.99);
  const Real gap = w.x[1] - w.x[0];
  ASSERT_LT(gap, touch) << "the bounding circles must overlap for the case to mean anything";
  checkAll(w, all, "closed in");
  for (auto& b : all) {
    const auto* kept = dynamic_cast<const KeptListBroadphase*>(b.get());
    if (!kept) continue;
    EXPECT_EQ(kept->list().relists(), 1) << b->name();
    EXPECT_EQ(b->rebuilds(), 1) << b->name();
    EXPECT_EQ(kept->list().directCount(), 0) << b->name();
  }
}

// The budget that ends relisting (neighbour_list.hpp): the list is rebuilt once the bodies direct
// or relisted since the build pass an eighth of all bodies, each counted once. The same ten floes
// jumping past half the skin step after step are relisted again and again without a rebuild (as the
// vessel's wake is at 10^5 floes); new floes jumping each step bring one soon.
TEST(Broadphase, KeptListsRebuildOnceAnEighthOfTheBodiesHaveBeenRelisted) {
  World w = randomWorld(47, 800, 200, 0);
  BroadphaseSettings s;
  s.skin = 2;
  auto list = make("variable_radius", s);
  const NeighbourList& kept = dynamic_cast<const KeptListBroadphase&>(*list).list();
  std::vector<CandidatePair> pairs;
  list->findCandidates(w, pairs);
  ASSERT_EQ(list->rebuilds(), 1);
  std::vector<int> floes;
  for (int i = 0; i < w.size(); ++i)
    if (w.kind[i] == BodyKind::Floe) floes.push_back(i);
  for (int step = 0; step < 60; ++step) {
    for (int k = 0; k < 10; ++k) w.x[floes[static_cast<size_t>(k)]] += step % 2 ? Real(-1.2) : Real(1.2);
    list->findCandidates(w, pairs);
  }
  EXPECT_GE(kept.relists(), 55) << "the ten floes should be relisted nearly every step";
  EXPECT_EQ(list->rebuilds(), 1) << "floes relisted again were counted again";
  int steps = 0;
  for (size_t next = 10; list->rebuilds() == 1 && next + 10 <= floes.size(); next += 10, ++steps) {
    for (size_t k = next; k < next + 10; ++k) w.y[floes[k]] += Real(1.2);
    list->findCandidates(w, pairs);
  }
  EXPECT_EQ(list->rebuilds(), 2);
  // The vessel and ten floes masked at first, ten more each step: past 801 / 8 = 100 at the ninth.
  EXPECT_EQ(steps, 9);
}

TEST(Broadphase, RebuildOnlyWhenNeeded) {
  BroadphaseSettings s;
  s.skin = 2;
  std::vector<CandidatePair> pairs;
  for (const auto& name : kStrategies) {
    if (name == "all_pairs" || name == "uniform_grid") continue;  // no kept list: rebuilt every step
    // No motion: one build, ever.
    World w = randomWorld(3, 100, 80);
    auto b = make(name, s);
    for (int k = 0; k < 20; ++k) b->findCandidates(w, pairs);
    EXPECT_EQ(b->rebuilds(), 1) << name;

    // One floe alone moving 0.3 m a step: past half the 2 m skin at k = 4 it becomes direct (tested
    // against everything each step) instead of forcing a rebuild.
    const int f = w.size() - 1;
    const NeighbourList& list = dynamic_cast<const KeptListBroadphase&>(*b).list();
    const int vessels = list.directCount();  // the vessel is always direct
    for (int k = 1; k <= 7; ++k) {
      w.x[f] += Real(0.3);
      b->findCandidates(w, pairs);
      EXPECT_EQ(list.directCount(), vessels + (k >= 4 ? 1 : 0)) << name << " k " << k;
    }
    EXPECT_EQ(b->rebuilds(), 1) << name;
    b->invalidate();
    b->findCandidates(w, pairs);
    EXPECT_EQ(b->rebuilds(), 2) << name;
    EXPECT_EQ(list.directCount(), vessels);  // a build starts afresh

    // Every movable body moving 0.3 m a step: all pass half the skin at k = 4, far more than
    // kRelistPast of them, so the list is rebuilt then.
    for (int k = 1; k <= 4; ++k) {
      for (int i = 0; i < w.size(); ++i)
        if (w.kind[i] != BodyKind::Wall) w.y[i] += Real(0.3);
      b->findCandidates(w, pairs);
      EXPECT_EQ(b->rebuilds(), k < 4 ? 2 : 3) << name << " k " << k;
    }

    // Turning counts R |d angle|: 0.9 m of rim travel on a floe is within half the skin, 1.1 m not.
    int g = -1;  // the largest floe but f: its turn stays well below half a revolution
    for (int i = 0; i < f; ++i)
      if (w.kind[i] == BodyKind::Floe && (g < 0 || w.radius[i] > w.radius[g])) g = i;
    const Real r = w.radius[g];
    w.angle[g] += Real(0.9) / r;
    b->findCandidates(w, pairs);
    EXPECT_EQ(list.directCount(), vessels) << name;
    w.angle[g] += Real(0.2) / r;
    b->findCandidates(w, pairs);
    EXPECT_EQ(list.directCount(), vessels + 1) << name;
    EXPECT_EQ(b->rebuilds(), 3) << name;
    b->invalidate();
    b->findCandidates(w, pairs);
    EXPECT_EQ(b->rebuilds(), 4) << name;

    // An angle wrapped by a whole turn (as motion code may do) is no turn at all.
    for (int i = 0; i < w.size(); ++i) w.angle[i] += 2 * kPi;
    b->findCandidates(w, pairs);
    EXPECT_EQ(b->rebuilds(), 4) << name;

    // invalidate() rebuilds at once, motion or not.
    b->invalidate();
    b->findCandidates(w, pairs);
    EXPECT_EQ(b->rebuilds(), 5) << name;
  }
}

TEST(Broadphase, InvalidateAfterTopologyChanges) {
  World w = randomWorld(11, 200, 120);
  auto all = makeAll();
  checkAll(w, all, "before");
  // Remove every third floe (the count changes), then add new floes (new ids).
  std::vector<char> remove(w.size(), 0);
  for (int i = 0; i < w.size(); i += 3)
    if (w.kind[i] == BodyKind::Floe) remove[i] = 1;
  w.removeBodies(remove);
  for (auto& b : all) b->invalidate();
  checkAll(w, all, "after removal");
  std::mt19937 rng(5);
  std::uniform_real_distribution<Real> u(0, 120);
  for (int k = 0; k < 30; ++k) w.addBody(spec(BodyKind::Floe, regularPolygon({u(rng), u(rng)}, 3, 5, u(rng))));
  for (auto& b : all) b->invalidate();
  checkAll(w, all, "after adding");
  // Reorder (same count, as a Morton re-sort does), invalidate, query.
  std::vector<int> order(w.size());
  for (int i = 0; i < w.size(); ++i) order[i] = w.size() - 1 - i;
  w.permute(order);
  for (auto& b : all) b->invalidate();
  checkAll(w, all, "after permute");
  for (auto& b : all)
    if (b->name() != "all_pairs") {
      EXPECT_EQ(b->rebuilds(), 4) << b->name();
    }
  // A reorder without invalidate() is a caller bug, but the id check still catches it.
  w.permute(order);
  checkAll(w, all, "permute, no invalidate");
}

// A break (bodies removed, new ones appended) and a re-sort (every body to another slot) told by
// bodiesRenamed(): the kept lists follow the bodies by id (NeighbourList::followRenamed) without a
// rebuild, the new floes direct and then relisted, and every strategy still proposes exactly what
// it did (the circle strategies all_pairs's set), through the moves after each.
TEST(Broadphase, KeptListsFollowRenamedBodiesWithoutARebuild) {
  World w = randomWorld(13, 300, 140);
  auto all = makeAll();
  std::mt19937 rng(9);
  checkAll(w, all, "before");
  auto keptLists = [&] {
    std::vector<const NeighbourList*> lists;
    for (auto& b : all)
      if (b->name() == "variable_radius" || b->name() == "fixed_radius") lists.push_back(&dynamic_cast<KeptListBroadphase&>(*b).list());
    return lists;
  };
  ASSERT_EQ(keptLists().size(), 2u);
  for (int k = 0; k < 4; ++k) {
    jiggle(w, rng, Real(0.05), Real(0.005));
    checkAll(w, all, "small moves " + std::to_string(k));
  }
  std::vector<long> built;
  for (const NeighbourList* list : keptLists()) built.push_back(list->rebuilds());

  // A break: every fifth floe goes, twenty new floes come at the end.
  std::vector<char> remove(w.size(), 0);
  for (int i = 0; i < w.size(); i += 5)
    if (w.kind[i] == BodyKind::Floe) remove[i] = 1;
  w.removeBodies(remove);
  std::uniform_real_distribution<Real> place(0, 140);
  for (int k = 0; k < 20; ++k) w.addBody(spec(BodyKind::Floe, regularPolygon({place(rng), place(rng)}, 2, 6, place(rng))));
  for (auto& b : all) b->bodiesRenamed();
  checkAll(w, all, "after a break");
  for (const NeighbourList* list : keptLists()) EXPECT_EQ(list->follows(), 1);
  for (int k = 0; k < 3; ++k) {
    jiggle(w, rng, Real(0.05), Real(0.005));
    checkAll(w, all, "after a break, moves " + std::to_string(k));
  }
  for (const NeighbourList* list : keptLists()) EXPECT_GE(list->relists(), 1) << "the new floes should have been relisted";

  // The re-sort: every body to another slot.
  std::vector<int> order(w.size());
  for (int i = 0; i < w.size(); ++i) order[i] = w.size() - 1 - i;
  w.permute(order);
  for (auto& b : all) b->bodiesRenamed();
  checkAll(w, all, "after a re-sort");
  for (int k = 0; k < 3; ++k) {
    jiggle(w, rng, Real(0.05), Real(0.005));
    checkAll(w, all, "after a re-sort, moves " + std::to_string(k));
  }
  // A re-sort along the curve, as the stepper's: the walls land among the floes, and a wall's row
  // (its circle covers much of the field) is put back in order by slot rather than sorted
  // (NeighbourList::placeLongRowBySlot). The whole list must be in strict (a, b) order.
  w.permute(w.curveOrder());
  for (auto& b : all) b->bodiesRenamed();
  checkAll(w, all, "after a re-sort along the curve");
  for (const NeighbourList* list : keptLists()) {
    const std::vector<ListedPair>& pairs = list->pairs();
    int longest = 0;
    for (size_t k = 0, rowStart = 0; k < pairs.size(); ++k) {
      if (k == 0) continue;
      ASSERT_TRUE(pairs[k - 1].a < pairs[k].a || (pairs[k - 1].a == pairs[k].a && pairs[k - 1].b < pairs[k].b)) << "pair " << k;
      if (pairs[k - 1].a != pairs[k].a) rowStart = k;
      longest = std::max(longest, static_cast<int>(k + 1 - rowStart));
    }
    EXPECT_GT(longest, std::max(32, w.size() / 32)) << "no row long enough to be put in order by slot";
  }
  const std::vector<const NeighbourList*> lists = keptLists();
  for (size_t k = 0; k < lists.size(); ++k) {
    EXPECT_EQ(lists[k]->follows(), 3);
    EXPECT_EQ(lists[k]->rebuilds(), built[k]) << "a rename was followed by a rebuild";
  }
}

// The CPU stepper tells the broadphase which bodies its last step left still
// (framework/api/still_bodies.hpp), and a kept list then skips their displacement checks and keeps
// the last answer of each chunk of pairs whose bodies are all still. Told truly, a list gives every
// step the candidates of a list told nothing: here a wake of floes moves
// across a resting field, a few floes jump past half the skin (direct, then relisted), and the
// rest keep still. On one thread with the exact pairs checked, and on a pool of three over 6,000
// floes (the flags are read on the caller's thread and used on the pool's), in curve order as the
// stepper keeps them; every 20 steps a swell stirs every floe, so that steps where most bodies
// moved alternate with steps where few did. Told falsely, a moved floe is not judged: the list
// really does skip what it is told is still.
TEST(Broadphase, KeptListsToldWhichBodiesAreStillGiveTheSameCandidates) {
  for (const int floes : {400, 6000}) {
    World w = randomWorld(23, floes, floes == 400 ? Real(130) : Real(500));
    if (floes == 6000) w.permute(w.curveOrder());  // as the stepper keeps them: the wake's floes in few blocks
    const Real side = floes == 400 ? Real(130) : Real(500);
    ThreadPool pool(3);
    const ParallelScope lend(floes == 400 ? nullptr : &pool);
    BroadphaseSettings s;
    s.skin = 2;
    std::vector<std::unique_ptr<Broadphase>> told, plain;
    for (const char* name : {"variable_radius", "fixed_radius", "triangulation_mesh"})
      told.push_back(make(name, s)), plain.push_back(make(name, s));
    std::mt19937 rng(31);
    std::uniform_real_distribution<Real> u(-1, 1);
    std::uniform_int_distribution<int> pick(0, w.size() - 1);
    std::vector<char> still(static_cast<size_t>(w.size()), 0);
    std::vector<CandidatePair> a, b;
    long stillSeen = 0;
    for (int step = 0; step < 60; ++step) {
      // The wake: floes within 15 m behind the front drift, on the 6,000-floe field only those
      // within 15 m of a bow at mid-height (few blocks of slots, as behind a vessel).
      const Real front = side * static_cast<Real>(step) / 60;
      for (int i = 0; i < w.size(); ++i) {
        const bool behind = w.x[i] < front && w.x[i] > front - 15;
        const bool moves = w.kind[i] != BodyKind::Wall && behind && (floes == 400 || std::abs(w.y[i] - side / 2) < 15);
        still[static_cast<size_t>(i)] = !moves;
        if (!moves) continue;
        w.x[i] += Real(0.15) + Real(0.02) * u(rng), w.y[i] += Real(0.05) * u(rng), w.angle[i] += Real(0.01) * u(rng);
      }
      for (int jumps = 0; jumps < 3; ++jumps) {
        const int i = pick(rng);
        if (w.kind[i] != BodyKind::Floe) continue;
        w.x[i] += Real(1.2) * u(rng), w.y[i] += Real(1.2) * u(rng);
        still[static_cast<size_t>(i)] = 0;
      }
      // Now and then a swell stirs every floe a little: a step where most bodies moved, which the
      // list judges without keeping pair answers, between steps where few did, which read them.
      if (step % 20 == 7)
        for (int i = 0; i < w.size(); ++i)
          if (w.kind[i] == BodyKind::Floe) w.x[i] += Real(0.05) * u(rng), w.y[i] += Real(0.05) * u(rng), still[static_cast<size_t>(i)] = 0;
      for (size_t k = 0; k < told.size(); ++k) {
        {
          const StillBodiesScope tell(step > 0 ? still.data() : nullptr);  // nothing is known before the first call
          told[k]->findCandidates(w, a);
        }
        plain[k]->findCandidates(w, b);
        ASSERT_EQ(toSet(a), toSet(b)) << told[k]->name() << " step " << step << " floes " << floes;
        if (floes == 400 && step % 10 == 0) checkCandidates(w, toSet(a), truthPairs(w), told[k]->name() + " step " + std::to_string(step));
      }
      if (step > 0) stillSeen += std::count(still.begin(), still.end(), 1);
    }
    EXPECT_GT(stillSeen, 60L * w.size() / 2) << "most bodies should have been still";
    for (size_t k = 0; k < told.size(); ++k) {
      const NeighbourList& list = dynamic_cast<const KeptListBroadphase&>(*told[k]).list();
      EXPECT_GE(list.relists(), 1) << told[k]->name() << ": relisting went untested";
    }

    // Told falsely: a floe that has moved 1.5 m, past half the skin, said to be still.
    int f = -1;
    const NeighbourList& toldList = dynamic_cast<const KeptListBroadphase&>(*told[0]).list();
    const NeighbourList& plainList = dynamic_cast<const KeptListBroadphase&>(*plain[0]).list();
    for (int i = 0; i < w.size() && f < 0; ++i)
      if (w.kind[i] == BodyKind::Floe && w.x[i] > side / 2 + 20) f = i;  // out of the wake, not direct
    ASSERT_GE(f, 0);
    std::fill(still.begin(), still.end(), 1);
    told[0]->invalidate(), plain[0]->invalidate();  // built afresh: only the vessel is direct
    told[0]->findCandidates(w, a), plain[0]->findCandidates(w, b);
    w.x[f] += Real(1.5);
    const int before = toldList.directCount();
    ASSERT_EQ(before, plainList.directCount());
    ASSERT_LE(before + 1, NeighbourList::kRelistPast) << "one more direct body must not start a relist here";
    {
      const StillBodiesScope tell(still.data());
      told[0]->findCandidates(w, a);
    }
    plain[0]->findCandidates(w, b);
    EXPECT_EQ(plainList.directCount(), before + 1) << "the moved floe is direct when judged";
    EXPECT_EQ(toldList.directCount(), before) << "a body said to be still was judged anyway";
  }
}

// Told which bodies rest (kRestingBody: still and in no contact), a kept list also tells the
// stepper the ranges of its output that hold pairs of two resting bodies only
// (RestingPairsScope), which the narrowphase then passes over unread. A vessel's wake crosses a
// field kept in curve order: the floes within 12 m of a point moving along the field drift, those
// within 18 m are still but said to be in contact (still, not resting), the rest rest. On one
// thread and on a pool of three. Against a twin of each list told the same flags but asked for no
// ranges: the output must be the twin's outside the ranges (inside, it may be left unwritten),
// every pair of the twin's in a range must be of two resting bodies, the ranges in order and
// disjoint, and over 6,000 floes they must cover most of the pairs: a list that named a pair of a
// moving body would have the narrowphase miss a contact, one that named none would save nothing.
// triangulation_mesh filters the circles' list further, so its output has no such ranges.
TEST(Broadphase, KeptListsNameTheRangesOfRestingPairs) {
  for (const int floes : {400, 6000}) {
    const Real side = floes == 400 ? Real(130) : Real(500);
    World w = randomWorld(29, floes, side);
    w.permute(w.curveOrder());  // as the stepper keeps them: neighbours in space are neighbours in slots
    ThreadPool pool(3);
    const ParallelScope lend(floes == 400 ? nullptr : &pool);
    BroadphaseSettings s;
    s.skin = 2;
    // Each list, and its twin told the same flags but asked for no ranges: the whole output.
    std::vector<std::unique_ptr<Broadphase>> lists, twins;
    for (const char* name : {"variable_radius", "fixed_radius", "triangulation_mesh"})
      lists.push_back(make(name, s)), twins.push_back(make(name, s));
    std::mt19937 rng(37);
    std::uniform_real_distribution<Real> u(-1, 1);
    std::vector<char> still(static_cast<size_t>(w.size()), 0);
    std::vector<CandidatePair> pairs, whole;
    std::vector<CandidateRange> resting;
    long covered = 0, listed = 0;
    for (int step = 0; step < 40; ++step) {
      const Real bowX = side * static_cast<Real>(step) / 40, bowY = side / 2;
      for (int i = 0; i < w.size(); ++i) {
        const Real d = std::hypot(w.x[i] - bowX, w.y[i] - bowY);
        const bool moves = w.kind[i] != BodyKind::Wall && d < 12;
        still[static_cast<size_t>(i)] = moves ? 0 : d < 18 ? 1 : kRestingBody;  // 1: still, in contact
        if (moves) w.x[i] += Real(0.15) + Real(0.02) * u(rng), w.y[i] += Real(0.05) * u(rng);
      }
      for (size_t l = 0; l < lists.size(); ++l) {
        const std::unique_ptr<Broadphase>& list = lists[l];
        resting.clear();
        {
          const StillBodiesScope tell(step > 0 ? still.data() : nullptr);
          {
            const RestingPairsScope ask(&resting);
            list->findCandidates(w, pairs);
          }
          twins[l]->findCandidates(w, whole);
        }
        // Outside the ranges the output is the whole list; inside, it may be left unwritten.
        ASSERT_EQ(pairs.size(), whole.size()) << list->name() << " step " << step;
        if (step == 0 || list->name() == "triangulation_mesh") {
          EXPECT_TRUE(resting.empty()) << list->name() << " step " << step << ": ranges named without still flags, or of another list";
          continue;
        }
        long end = 0;
        auto sameOutside = [&](long from, long to) {
          for (long k = from; k < to; ++k)
            ASSERT_TRUE(pairs[static_cast<size_t>(k)].a == whole[static_cast<size_t>(k)].a &&
                        pairs[static_cast<size_t>(k)].b == whole[static_cast<size_t>(k)].b)
                << list->name() << " step " << step << ": candidate " << k << " differs outside the ranges";
        };
        for (const CandidateRange& r : resting) {
          ASSERT_LE(end, r.begin) << list->name() << " step " << step << ": ranges out of order or overlapping";
          ASSERT_LT(r.begin, r.end);
          ASSERT_LE(r.end, static_cast<long>(pairs.size()));
          sameOutside(end, r.begin);
          for (long k = r.begin; k < r.end; ++k) {
            const CandidatePair p = whole[static_cast<size_t>(k)];
            ASSERT_TRUE(still[static_cast<size_t>(p.a)] == kRestingBody && still[static_cast<size_t>(p.b)] == kRestingBody)
                << list->name() << " step " << step << ": pair " << p.a << "-" << p.b << " named resting";
          }
          covered += r.end - r.begin;
          end = r.end;
        }
        sameOutside(end, static_cast<long>(pairs.size()));
        listed += static_cast<long>(pairs.size());
      }
    }
    // 400 floes make four chunks of 256 pairs, each a quarter of the field: the wake is in most.
    if (floes == 6000) {
      EXPECT_GT(covered, listed / 2) << "the ranges should cover most pairs of a resting field";
    }
  }
}

// The kept list's grid of references (reference_grid.hpp): near() visits every body whose
// reference lies in the square, each once, and every body in no cell; after bodies move to other
// cells (move) and are binned again by new slots (bin), and for squares and references outside the
// laid-out bounds, which are clamped into the border cells. Against a plain scan of every body.
TEST(Broadphase, ReferenceGridVisitsEveryReferenceInTheSquareOnce) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<Real> u(0, 1);
  const int n = 3000;
  std::vector<Real> x(n), y(n), radius(n);
  for (int i = 0; i < n; ++i) x[i] = 300 * u(rng), y[i] = 200 * u(rng), radius[i] = Real(0.3) + 2 * u(rng);
  radius[7] = 400, radius[1234] = 250;             // two walls' worth: in no cell
  x[99] = std::numeric_limits<Real>::quiet_NaN();  // in no cell either
  ReferenceGrid grid;
  grid.layOut(x.data(), y.data(), radius.data(), n, 3);
  EXPECT_EQ(grid.outsideCount(), 3);
  EXPECT_LE(grid.largestRadius(), Real(2.3));
  auto check = [&](const std::string& what, const std::vector<int>& inNoCell) {
    for (int query = 0; query < 300; ++query) {
      // Squares from a metre to a field wide, some reaching past the field's edges.
      const Real cx = 360 * u(rng) - 30, cy = 260 * u(rng) - 30, reach = query % 10 == 0 ? 150 * u(rng) : 1 + 9 * u(rng);
      const int bodies = static_cast<int>(x.size());
      std::vector<int> seen(bodies, 0);
      grid.near(cx, cy, reach, [&](int j) {
        ASSERT_TRUE(j >= 0 && j < bodies) << what << ": visited slot " << j;
        ++seen[j];
      });
      for (int i = 0; i < bodies; ++i) {
        ASSERT_LE(seen[i], 1) << what << ": body " << i << " visited twice";
        const bool inside = std::fabs(x[i] - cx) <= reach && std::fabs(y[i] - cy) <= reach;
        const bool outside = std::find(inNoCell.begin(), inNoCell.end(), i) != inNoCell.end();
        if (inside || outside) {
          ASSERT_EQ(seen[i], 1) << what << ": body " << i << " at (" << x[i] << ", " << y[i] << ") missed";
        }
      }
    }
  };
  check("laid out", {7, 99, 1234});
  // References move, some far past the laid-out bounds (clamped into a border cell).
  for (int k = 0; k < 2000; ++k) {
    const int i = static_cast<int>(u(rng) * n) % n;
    if (i == 99) continue;
    const bool far = k % 50 == 0;
    x[i] = far ? 500 * u(rng) - 100 : std::clamp<Real>(x[i] + 6 * (u(rng) - Real(0.5)), -20, 320);
    y[i] = far ? 400 * u(rng) - 100 : std::clamp<Real>(y[i] + 6 * (u(rng) - Real(0.5)), -20, 220);
    grid.move(i, x[i], y[i]);
  }
  check("after moves", {7, 99, 1234});
  // A break and a re-sort at once (follow): every tenth body goes (1234, in no cell, among them),
  // the rest reversed, and 40 new bodies come, two of them too large for a cell.
  std::vector<int> newSlot(n, -1);
  std::vector<Real> x2, y2, radius2;
  for (int j = n - 1; j >= 0; --j) {
    if (j % 10 == 4) continue;
    newSlot[j] = static_cast<int>(x2.size());
    x2.push_back(x[j]), y2.push_back(y[j]), radius2.push_back(radius[j]);
  }
  const int kept = static_cast<int>(x2.size());
  std::vector<char> isNew(static_cast<size_t>(kept), 0);
  for (int k = 0; k < 40; ++k) {
    x2.push_back(300 * u(rng)), y2.push_back(200 * u(rng)), radius2.push_back(k < 2 ? Real(300) : Real(1));
    isNew.push_back(1);
  }
  x.swap(x2), y.swap(y2), radius.swap(radius2);
  grid.follow(newSlot, isNew, x.data(), y.data(), radius.data());
  EXPECT_EQ(grid.outsideCount(), 4);
  check("followed to new slots", {newSlot[7], newSlot[99], kept, kept + 1});
}

// The direct pass and relisting search near their floes through the grid of references; a body not
// direct may be anywhere within half the skin of its reference. Small floes (radii 0.4 to 0.8 m)
// and a 4 m skin make that half skin wide against the cells, and every floe swings about its base
// by just under it, each in its own phase, while a few floes jump 1.2 m (past half the skin: direct,
// then relisted) and the vessel crosses the field; then a break and a re-sort rename the bodies.
// Every step the kept lists give all_pairs' candidates.
TEST(Broadphase, DirectAndRelistedFloesFindEveryPairNearTheirReferences) {
  World w;
  std::mt19937 rng(43);
  std::uniform_real_distribution<Real> u(0, 1);
  const Real side = 70;
  w.addBody(spec(BodyKind::Vessel, rectangle({-10, side / 2}, 12, 4, 0)));
  for (int k = 0; k < 1500; ++k)
    w.addBody(spec(BodyKind::Floe, regularPolygon({side * u(rng), side * u(rng)}, Real(0.4) + Real(0.4) * u(rng), 5, 6 * u(rng))));
  BroadphaseSettings s;
  s.skin = 4;
  std::vector<std::unique_ptr<Broadphase>> all;
  for (const char* name : {"all_pairs", "variable_radius", "fixed_radius"}) all.push_back(make(name, s));
  std::vector<Vec2> base(w.size()), swing(w.size());
  std::vector<Real> phase(w.size());
  auto setSwing = [&](int i) {
    base[i] = {w.x[i], w.y[i]};
    swing[i] = rotate(Vec2{Real(0.99), 0}, 2 * kPi * u(rng));  // peak to peak just under half the skin
    phase[i] = 2 * kPi * u(rng);
  };
  for (int i = 0; i < w.size(); ++i) setSwing(i);
  long candidates = 0;
  for (int step = 0; step < 90; ++step) {
    if (step == 30 || step == 60) {
      if (step == 30) {  // a break: every seventh floe goes, thirty come
        std::vector<char> remove(w.size(), 0);
        for (int i = 1; i < w.size(); i += 7) remove[i] = 1;
        w.removeBodies(remove);
        for (int k = 0; k < 30; ++k) w.addBody(spec(BodyKind::Floe, regularPolygon({side * u(rng), side * u(rng)}, Real(0.6), 6, u(rng))));
      } else {  // a re-sort
        std::vector<int> order(w.size());
        for (int i = 0; i < w.size(); ++i) order[i] = w.size() - 1 - i;
        w.permute(order);
      }
      base.resize(w.size()), swing.resize(w.size()), phase.resize(w.size());
      for (int i = 0; i < w.size(); ++i) setSwing(i);
      for (auto& b : all) b->bodiesRenamed();
    }
    for (int jumps = 0; jumps < 5; ++jumps) {
      const int i = static_cast<int>(u(rng) * w.size()) % w.size();
      if (w.kind[i] == BodyKind::Floe) base[i] = base[i] + rotate(Vec2{Real(1.2), 0}, 2 * kPi * u(rng));
    }
    for (int i = 0; i < w.size(); ++i) {
      if (w.kind[i] == BodyKind::Vessel) {
        w.x[i] += Real(1.1);
        continue;
      }
      const Real t = std::sin(phase[i] + Real(0.9) * static_cast<Real>(step));
      w.x[i] = base[i].x + t * swing[i].x, w.y[i] = base[i].y + t * swing[i].y;
    }
    std::vector<CandidatePair> pairs;
    all[0]->findCandidates(w, pairs);
    const PairSet reference = toSet(pairs);
    candidates += static_cast<long>(reference.size());
    for (size_t k = 1; k < all.size(); ++k) {
      all[k]->findCandidates(w, pairs);
      ASSERT_EQ(toSet(pairs), reference) << all[k]->name() << " step " << step;
    }
  }
  EXPECT_GT(candidates, 90L * 500) << "the floes should crowd";
  for (size_t k = 1; k < all.size(); ++k) {
    const auto& kept = dynamic_cast<const KeptListBroadphase&>(*all[k]);
    EXPECT_GE(kept.list().relists(), 30) << all[k]->name() << ": relisting went untested";
    EXPECT_EQ(kept.list().follows(), 2) << all[k]->name();
  }
}

TEST(Broadphase, SettingsVariants) {
  World w = randomWorld(21, 200, 120);
  std::mt19937 rng(3);
  // Zero skin: rebuilds at every motion, still exact; tiny cells (every body "large"), small cells
  // (many large); huge cells (walls inside the grid, where wall-wall pairs must still be dropped);
  // a fixed radius set far too small (must stay conservative); a huge skin.
  std::vector<BroadphaseSettings> variants(6);
  variants[0].skin = 0;
  variants[1].cellSize = Real(0.5);
  variants[2].cellSize = Real(3);
  variants[3].cellSize = Real(400);
  variants[4].fixedRadius = Real(0.1);
  variants[5].skin = 30;
  for (size_t v = 0; v < variants.size(); ++v) {
    auto all = makeAll(variants[v]);
    for (int step = 0; step < 15; ++step) {
      jiggle(w, rng, Real(0.4), Real(0.05));
      checkAll(w, all, "variant " + std::to_string(v) + " step " + std::to_string(step));
      if (HasFatalFailure()) return;
    }
  }
  BroadphaseSettings bad;
  bad.skin = -1;
  for (const auto& name : kStrategies)
    if (name != "all_pairs" && name != "uniform_grid") {  // uniform_grid keeps no list: it has no skin
      EXPECT_THROW(make(name, bad), InputError) << name;
    }
  BroadphaseSettings badCell;
  badCell.cellSize = -1;
  EXPECT_THROW(make("uniform_grid", badCell), InputError);
}

TEST(Broadphase, SparseFieldKilometresWide) {
  // A few clusters kilometres apart: the grid's bounding box holds millions of cells, almost all
  // empty; uniform_grid must neither allocate per cell nor lose pairs at cluster edges.
  World w;
  std::mt19937 rng(9);
  std::uniform_real_distribution<Real> u(0, 1);
  for (int cluster = 0; cluster < 6; ++cluster) {
    Vec2 c{20000 * u(rng) - 10000, 20000 * u(rng) - 10000};
    for (int k = 0; k < 30; ++k)
      w.addBody(spec(BodyKind::Floe, regularPolygon({c.x + 30 * u(rng), c.y + 30 * u(rng)}, 1 + 3 * u(rng), 6, u(rng))));
  }
  auto all = makeAll();
  for (int step = 0; step < 10; ++step) {
    jiggle(w, rng, Real(0.5), Real(0.1));
    checkAll(w, all, "sparse step " + std::to_string(step));
  }
}

}  // namespace
}  // namespace gem
