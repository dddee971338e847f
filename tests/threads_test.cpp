// simulation.threads: one field stepped by several CPU threads gives, bit for bit, the run of one
// thread (docs/architecture.md "Determinism"): each task writes its own part of a phase and the
// parts are joined in order, so the contacts, the records and every sum are the same.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "broadphase/kept_list/neighbour_list.hpp"
#include "framework/api/parallel.hpp"
#include "framework/api/registry.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/step/thread_pool.hpp"
#include "test_support.hpp"

namespace gem {
namespace {

struct ThreadedRun {
  std::vector<std::int64_t> ids;
  std::vector<Real> state;
  long contacts = 0, impactRows = 0, broken = 0;
  int mostContacts = 0;  // in one step
  // Every record's tag (event, contact, world), stream by stream, step by step: the rows' order
  // and the contacts they name (the pair events run over ranges of contacts, their rows joined).
  std::vector<std::int32_t> tags;
  int candidates = 0;  // the last step's
  long rebuilds = 0;   // the broadphase's
  // Over the run: candidates passed over in resting ranges, and the steps that passed over some
  // and still read enough for the box pass to be split over the pool.
  long resting = 0, splitAroundRest = 0;
};

// rebuildEvery: the broadphase is invalidated every that many steps (0: never), so that its
// parallel build runs on a field in motion too, not only on the first step's.
ThreadedRun runWithThreads(const Scenario& base, int threads, int steps, int rebuildEvery = 0) {
  Scenario s = base;
  s.threads = threads;
  CpuStepper sim(s);
  ThreadedRun r;
  for (int k = 0; k < steps; ++k) {
    if (rebuildEvery > 0 && k > 0 && k % rebuildEvery == 0) sim.broadphase().invalidate();
    sim.step();
    r.contacts += sim.contactCount();
    r.resting += sim.restingCandidates();
    r.splitAroundRest += sim.restingCandidates() > 0 && sim.candidateCount() - sim.restingCandidates() >= CpuStepper::kParallelPairs;
    r.mostContacts = std::max(r.mostContacts, sim.contactCount());
    for (int q = 0; q < sim.records().streams().count(); ++q) {
      r.impactRows += sim.records().rowCount(q);
      for (int row = 0; row < sim.records().rowCount(q); ++row) {
        const RecordTag& tag = sim.records().tag(q, row);
        r.tags.insert(r.tags.end(), {q, tag.event, tag.contact, tag.world});
      }
    }
  }
  EXPECT_EQ(sim.threads(), threads);
  r.broken = sim.floesBroken();
  r.candidates = sim.candidateCount();
  r.rebuilds = sim.broadphase().rebuilds();
  const World& w = sim.world();
  r.ids = w.id;
  for (const std::vector<Real>* v : {&w.x, &w.y, &w.angle, &w.vx, &w.vy, &w.omega}) r.state.insert(r.state.end(), v->begin(), v->end());
  return r;
}

void expectSame(const ThreadedRun& one, const ThreadedRun& many, int threads) {
  SCOPED_TRACE(::testing::Message() << threads << " threads");
  ASSERT_EQ(one.ids, many.ids);
  ASSERT_EQ(one.state.size(), many.state.size());
  EXPECT_EQ(0, std::memcmp(one.state.data(), many.state.data(), one.state.size() * sizeof(Real)));
  EXPECT_EQ(one.contacts, many.contacts);
  EXPECT_EQ(one.impactRows, many.impactRows);
  EXPECT_EQ(one.tags, many.tags);
  EXPECT_EQ(one.broken, many.broken);
  EXPECT_EQ(one.rebuilds, many.rebuilds);
}

// A field large enough that every parallel phase runs on the pool (CpuStepper::kParallelBodies),
// most of it resting, so that the box pass reads only the stretches between the resting ranges.
TEST(Threads, ALargeFieldStepsBitForBitOnOneTwoAndFourThreads) {
  const int steps = 120;
  test::TempDir dir;
  const Scenario s = test::scenarioFromToml(
      dir, test::kBusyScene, {"simulation.steps=" + std::to_string(steps), "domain.x=[0.0, 700.0]", "domain.y=[-200.0, 200.0]"});
  const ThreadedRun one = runWithThreads(s, 1, steps, 50);
  ASSERT_GE(one.ids.size(), static_cast<size_t>(CpuStepper::kParallelBodies)) << "the field is too small to run on the pool";
  ASSERT_GE(one.candidates, CpuStepper::kParallelPairs) << "too few pairs for the narrowphase to run on the pool";
  EXPECT_GT(one.contacts, 500) << "the scene must touch a lot, or it guards nothing";
  EXPECT_GT(one.impactRows, 0);
  EXPECT_GE(one.rebuilds, 3) << "the kept list was not rebuilt mid-run: its parallel build went untested";
  EXPECT_GT(one.resting, 0) << "no candidate was passed over: the resting ranges went untested";
  EXPECT_GT(one.splitAroundRest, 10) << "the box pass never split the stretches between resting ranges over the pool";
  for (int threads : {2, 4}) expectSame(one, runWithThreads(s, threads, steps, 50), threads);
}

// The kept lists' build (the sweep, the counting sort, the clean-up) and their per-step filter (the
// listed pairs, the direct pass) run over ranges of bodies and pairs on the stepper's pool
// (framework/api/parallel.hpp). On a field past every range's threshold, with floes moved so that
// the lists are rebuilt at some calls, relisted at others (NeighbourList::relistDirect) and only
// direct at the rest, every strategy gives the same list and the same candidates, bit for bit, on
// one thread and on two, three and four.
TEST(Threads, KeptListsBuildAndFilterTheSameOnAnyThreadCount) {
  test::TempDir dir;
  const Scenario s = test::scenarioFromToml(dir, test::kBusyScene, {"domain.x=[0.0, 700.0]", "domain.y=[-200.0, 200.0]"});
  const World start = buildWorld(s);
  ASSERT_GE(start.size(), 4 * NeighbourList::kBodyGrain) << "too few bodies for the body passes to be split";
  for (const char* name : {"variable_radius", "fixed_radius", "triangulation_mesh"}) {
    SCOPED_TRACE(name);
    World world = start;
    auto one = Registry::global().broadphase(name).make(s.broadphaseSettings);
    std::vector<std::unique_ptr<Broadphase>> many;
    std::vector<std::unique_ptr<ThreadPool>> pools;
    for (int threads : {2, 3, 4}) {
      many.push_back(Registry::global().broadphase(name).make(s.broadphaseSettings));
      pools.push_back(std::make_unique<ThreadPool>(threads));
    }
    std::mt19937 random(7);
    bool sawDirect = false;
    for (int call = 0; call < 12; ++call) {
      // Odd calls move 2 floes past half the skin (direct, no relist: kRelistPast), calls 2 and 6
      // 40 (relisted: within an eighth of the bodies), the other even ones a third of the bodies (a
      // rebuild).
      static_assert(NeighbourList::kRelistPast >= 3, "the vessel and 2 floes must stay direct");
      std::uniform_int_distribution<int> body(0, world.size() - 1);
      const int moves = call % 2 ? 2 : call % 4 == 2 ? 40 : world.size() / 3;
      for (int moved = 0; moved < moves; ++moved) {
        const int i = body(random);
        if (world.kind[i] != BodyKind::Floe) continue;
        world.x[i] += Real(1.5);
        world.y[i] -= Real(0.75);
      }
      std::vector<CandidatePair> expected;
      one->findCandidates(world, expected);
      const auto& list = dynamic_cast<const KeptListBroadphase&>(*one).list();
      ASSERT_GE(static_cast<int>(list.pairs().size()), 4 * NeighbourList::kPairGrain) << "too few listed pairs for them to be split";
      sawDirect = sawDirect || list.directCount() > 1;  // more than the vessel
      for (size_t k = 0; k < many.size(); ++k) {
        SCOPED_TRACE(::testing::Message() << pools[k]->size() << " threads, call " << call);
        std::vector<CandidatePair> pairs;
        {
          const ParallelScope lend(pools[k].get());
          many[k]->findCandidates(world, pairs);
        }
        ASSERT_EQ(pairs.size(), expected.size());
        EXPECT_EQ(0, std::memcmp(pairs.data(), expected.data(), pairs.size() * sizeof(CandidatePair)));
        const auto& listed = dynamic_cast<const KeptListBroadphase&>(*many[k]).list().pairs();
        ASSERT_EQ(listed.size(), list.pairs().size());
        EXPECT_EQ(0, std::memcmp(listed.data(), list.pairs().data(), listed.size() * sizeof(ListedPair)));
        const auto& side = dynamic_cast<const KeptListBroadphase&>(*many[k]).list().sidePairs();
        ASSERT_EQ(side.size(), list.sidePairs().size());
        if (!side.empty()) {  // memcmp of an empty vector's null data() is undefined behaviour
          EXPECT_EQ(0, std::memcmp(side.data(), list.sidePairs().data(), side.size() * sizeof(ListedPair)));
        }
        EXPECT_EQ(many[k]->rebuilds(), one->rebuilds());
        EXPECT_EQ(dynamic_cast<const KeptListBroadphase&>(*many[k]).list().relists(), list.relists());
      }
    }
    const NeighbourList& list = dynamic_cast<const KeptListBroadphase&>(*one).list();
    EXPECT_GE(one->rebuilds(), 3) << "the lists were not rebuilt: the build's parallel parts went untested";
    EXPECT_GE(list.relists(), 2) << "no list was relisted: relistDirect's parallel parts went untested";
    EXPECT_TRUE(sawDirect) << "no floe was direct: the direct pass went untested";
  }
}

// The side list's filter and relisting's rewrite of it (both over ranges of side pairs) on a field
// big enough to split them: 22,500 squares 0.2 m apart, 2,250 of them moved past half the skin, so
// relisted (within an eighth of the bodies); later 300 others and 225 of the relisted ones again,
// whose old side pairs the rewrite drops. One thread and three give the same side list and the
// same candidates, bit for bit.
TEST(Threads, RelistingAndTheSideListSplitTheSameOnAnyThreadCount) {
  World start;
  for (int k = 0; k < 150 * 150; ++k)
    start.addBody(test::squareFloe({Real(1.2) * static_cast<Real>(k % 150), Real(1.2) * static_cast<Real>(k / 150)}, 1, 1));
  BroadphaseSettings settings;
  settings.skin = 2;
  auto one = Registry::global().broadphase("variable_radius").make(settings);
  auto three = Registry::global().broadphase("variable_radius").make(settings);
  ThreadPool pool(3);
  std::vector<CandidatePair> expected, pairs;
  World world = start;
  for (int call = 0; call < 4; ++call) {
    if (call == 1)
      for (int i = 0; i < world.size(); i += 10) world.x[i] += Real(1.01);
    if (call == 2)
      for (int i = 5; i < world.size(); i += 10) world.y[i] -= Real(0.3);  // a step of ordinary motion after the relist
    if (call == 3) {
      for (int i = 3; i < world.size(); i += 75) world.x[i] += Real(1.01);
      for (int i = 0; i < world.size(); i += 100) world.x[i] -= Real(1.01);  // relisted again
    }
    one->findCandidates(world, expected);
    {
      const ParallelScope lend(&pool);
      three->findCandidates(world, pairs);
    }
    SCOPED_TRACE(::testing::Message() << "call " << call);
    ASSERT_EQ(pairs.size(), expected.size());
    EXPECT_EQ(0, std::memcmp(pairs.data(), expected.data(), pairs.size() * sizeof(CandidatePair)));
  }
  const NeighbourList& a = dynamic_cast<const KeptListBroadphase&>(*one).list();
  const NeighbourList& b = dynamic_cast<const KeptListBroadphase&>(*three).list();
  EXPECT_EQ(a.relists(), 2);
  EXPECT_EQ(b.relists(), 2);
  EXPECT_EQ(one->rebuilds(), 1);
  ASSERT_GE(static_cast<int>(a.sidePairs().size()), 4 * NeighbourList::kPairGrain) << "too few side pairs for the filter to be split";
  ASSERT_EQ(a.sidePairs().size(), b.sidePairs().size());
  EXPECT_EQ(0, std::memcmp(a.sidePairs().data(), b.sidePairs().data(), a.sidePairs().size() * sizeof(ListedPair)));
  EXPECT_GT(expected.size(), 10000u) << "the squares 0.2 m apart with moved ones among them must give candidates";
}

// A pack driven against a wall by a strong current: thousands of contacts a step, so the pair
// events run over ranges of contacts on the pool, their records joined in order
// (CpuStepper::kParallelContacts).
TEST(Threads, APackPressedAgainstAWallStepsBitForBitOnOneAndThreeThreads) {
  test::TempDir dir;
  const Scenario s =
      test::scenarioFromToml(dir, std::string(test::kBusyScene) + "[events.current]\nspeed = 3.0\nspeed_direction_deg = -90.0\n",
                             {"simulation.steps=150", "field.concentration=0.8", "domain.x=[0.0, 300.0]", "domain.y=[-150.0, 150.0]"});
  const ThreadedRun one = runWithThreads(s, 1, 150);
  ASSERT_GE(one.mostContacts, CpuStepper::kParallelContacts) << "too few contacts for the pair events to run on the pool";
  EXPECT_GT(one.impactRows, 0);
  expectSame(one, runWithThreads(s, 3, 150), 3);
}

// A field that a current moves whole: every pair whose boxes overlap is tested each step, so the
// narrowphase's parts hold tens of thousands of separated pairs and are joined on the pool
// (CpuStepper::kParallelJoin); the next step's search for each pair's last separating edge reads
// the joined list.
TEST(Threads, AFieldMovedWholeByACurrentJoinsItsNarrowphaseOnThePool) {
  test::TempDir dir;
  const Scenario s =
      test::scenarioFromToml(dir, std::string(test::kBusyScene) + "[events.current]\nspeed = 1.0\nspeed_direction_deg = 30.0\n",
                             {"simulation.steps=30", "field.concentration=0.6", "domain.x=[0.0, 2000.0]", "domain.y=[-500.0, 500.0]"});
  Scenario probe = s;
  probe.threads = 1;
  CpuStepper sim(probe);
  for (int k = 0; k < 3; ++k) sim.step();
  ASSERT_GE(static_cast<size_t>(sim.separatedCount()), CpuStepper::kParallelJoin) << "too few separated pairs to join on the pool";
  const ThreadedRun one = runWithThreads(s, 1, 30);
  EXPECT_GT(one.contacts, 0);
  expectSame(one, runWithThreads(s, 3, 30), 3);
}

// GEM_CPU_TIMING=1 (docs/performance.md 1.4): one line on stderr when the stepper goes, its steps
// and each phase's milliseconds a step, which add up to the total it states, and one of the steps
// by kind.
TEST(CpuTiming, OneLineOfPhasesThatAddUpToTheStep) {
  test::TempDir dir;
  const Scenario s = test::scenarioFromToml(dir, test::kBusyScene, {"simulation.steps=20"});
  ::setenv("GEM_CPU_TIMING", "1", 1);
  ::testing::internal::CaptureStderr();
  {
    CpuStepper sim(s);
    for (int k = 0; k < 5; ++k) sim.step();
    sim.restartPhaseClock();  // as gem bench does after its warm-up: the five steps are left out
    for (int k = 0; k < 12; ++k) sim.step();
  }
  const std::string line = ::testing::internal::GetCapturedStderr();
  ::unsetenv("GEM_CPU_TIMING");
  ASSERT_NE(line.find("gem cpu timing, 12 steps, "), std::string::npos) << line;
  const size_t at = line.find(" ms a step; of it");
  ASSERT_NE(at, std::string::npos) << line;
  const double total = std::stod(line.substr(line.rfind(' ', at - 1) + 1));
  double sum = 0;
  for (const char* phase : {"broadphase", "narrowphase tests", "narrowphase join", "pair views and events", "body updates", "topology"}) {
    const size_t p = line.find(std::string(phase) + " ", at);
    ASSERT_NE(p, std::string::npos) << phase << " missing in: " << line;
    sum += std::stod(line.substr(p + std::string(phase).size() + 1));
  }
  EXPECT_GT(total, 0);
  EXPECT_NEAR(sum, total, 1e-3 + 1e-3 * total);  // each figure is rounded to 0.1 us
  // The steps by kind (plain, breaking or re-sorting, right after those): their counts are the
  // steps timed, and their shares of the mean step add up to it.
  const size_t kinds = line.find("gem cpu steps by kind: ");
  ASSERT_NE(kinds, std::string::npos) << line;
  long counted = 0;
  double shares = 0;
  for (const char* kind : {" plain at ", " breaking or re-sorting at ", " right after those at "}) {
    const size_t k = line.find(kind, kinds);
    ASSERT_NE(k, std::string::npos) << kind << " missing in: " << line;
    counted += std::stol(line.substr(line.rfind(' ', k - 1) + 1));
    const size_t share = line.find(" ms, ", k);
    shares += std::stod(line.substr(share + 5));
  }
  EXPECT_EQ(counted, 12);
  EXPECT_NEAR(shares, total, 2e-3 + 1e-2 * total);
  // On several threads a second line tells where the pool's time went: the rounds and the calling
  // thread's time between them add up to the step.
  Scenario threaded = s;
  threaded.threads = 2;
  ::setenv("GEM_CPU_TIMING", "1", 1);
  ::testing::internal::CaptureStderr();
  {
    CpuStepper sim(threaded);
    for (int k = 0; k < 12; ++k) sim.step();
  }
  const std::string lines = ::testing::internal::GetCapturedStderr();
  ::unsetenv("GEM_CPU_TIMING");
  const size_t pool = lines.find("gem cpu pool, 2 threads: ");
  ASSERT_NE(pool, std::string::npos) << lines;
  auto figureBefore = [&](const std::string& words) {
    const size_t w = lines.find(words, pool);
    EXPECT_NE(w, std::string::npos) << words << " missing in: " << lines;
    return w == std::string::npos ? -1.0 : std::stod(lines.substr(lines.rfind(' ', w - 1) + 1));
  };
  const double threadedTotal = std::stod(lines.substr(lines.rfind(' ', lines.find(" ms a step; of it") - 1) + 1));
  const double inRounds = figureBefore(" ms a step in rounds"), between = figureBefore(" ms a step between rounds");
  EXPECT_GE(inRounds, 0);
  EXPECT_GE(between, 0);
  EXPECT_NEAR(inRounds + between, threadedTotal, 1e-3 + 1e-3 * threadedTotal);
  // And phase by phase: the time each phase spent between rounds, which adds up to the same.
  const size_t byPhase = lines.find("gem cpu pool, between rounds by phase, ms a step: ");
  ASSERT_NE(byPhase, std::string::npos) << lines;
  double phasesBetween = 0;
  for (const char* phase : {"broadphase", "narrowphase tests", "narrowphase join", "pair views and events", "body updates", "topology"}) {
    const size_t p = lines.find(std::string(phase) + " ", byPhase);
    ASSERT_NE(p, std::string::npos) << phase << " missing in: " << lines;
    const double figure = std::stod(lines.substr(p + std::string(phase).size() + 1));
    EXPECT_GE(figure, -1e-4) << phase;
    phasesBetween += figure;
  }
  EXPECT_NEAR(phasesBetween, between, 1e-3 + 1e-3 * between);
  // Off, nothing is printed.
  ::testing::internal::CaptureStderr();
  {
    CpuStepper sim(s);
    sim.step();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

TEST(Threads, ABrokenFieldStepsBitForBitOnThreeThreads) {
  // Thin ice: floes break, the world changes size, the vessel pushes through.
  test::TempDir dir;
  const Scenario s = test::scenarioFromToml(
      dir, test::kBusyScene, {"simulation.steps=420", "field.thickness=0.25", "domain.x=[0.0, 700.0]", "domain.y=[-200.0, 200.0]"});
  const ThreadedRun one = runWithThreads(s, 1, 420);
  EXPECT_GT(one.broken, 0) << "no floe broke: the test guards nothing of the topology phase";
  expectSame(one, runWithThreads(s, 3, 420), 3);
}

// A break removes bodies from the world: inside a threaded step (the pool lent to the topology
// phase, flexural breaking passes parallelEach) every array is compacted by a task of its own. The
// world left must be the one a single thread leaves, array by array.
TEST(Threads, RemovingBodiesOnThePoolLeavesTheWorldOneThreadLeaves) {
  World start;
  for (int k = 0; k < 40000; ++k)
    start.addBody(test::squareFloe({Real(1.5) * static_cast<Real>(k % 200), Real(1.5) * static_cast<Real>(k / 200)},
                                   Real(0.5) + Real(0.001) * static_cast<Real>(k % 499), 0.5, {Real(0.001) * static_cast<Real>(k % 7), 0},
                                   Real(0.01) * static_cast<Real>(k % 3)));  // sizes that differ, so that each body's vertices do
  // Every seventh body (a range of the vertices then holds fewer kept rows than it sets aside), and
  // a break's few (each range sets aside a row or two that the range before it would overwrite).
  std::vector<char> everySeventh(start.id.size(), 0), aFew(start.id.size(), 0);
  for (size_t i = 3; i < everySeventh.size(); i += 7) everySeventh[i] = 1;
  for (const size_t i : {1200u, 9999u, 10000u, 27001u}) aFew[i] = 1;
  for (const std::vector<char>* remove : {&everySeventh, &aFew}) {
    World alone = start, pooled = start;
    alone.removeBodies(*remove);
    ThreadPool pool(3);
    {
      const ParallelScope lend(&pool);
      ASSERT_GT(parallelTasks(static_cast<long>(remove->size()), 4096), 1) << "too few bodies for the pool to be used";
      pooled.removeBodies(*remove, parallelEach);
    }
    ASSERT_EQ(pooled.size(), alone.size());
    EXPECT_EQ(alone.size(), 40000 - static_cast<int>(std::count(remove->begin(), remove->end(), 1)));
    EXPECT_EQ(pooled.id, alone.id);
    EXPECT_EQ(pooled.kind, alone.kind);
    EXPECT_EQ(pooled.vertexCount, alone.vertexCount);
    for (auto member : {&World::x, &World::y, &World::angle, &World::vx, &World::vy, &World::omega, &World::area, &World::thickness,
                        &World::mass, &World::invMass, &World::invInertia, &World::gyration2, &World::gyrationX2, &World::gyrationY2,
                        &World::principalAngle, &World::radius})
      EXPECT_EQ(pooled.*member, alone.*member);
    ASSERT_EQ(pooled.localVertices.size(), alone.localVertices.size());
    EXPECT_EQ(0, std::memcmp(pooled.localVertices.data(), alone.localVertices.data(), alone.localVertices.size() * sizeof(Vec2)));
  }
  World alone = start;
  alone.removeBodies(everySeventh);
  EXPECT_EQ(alone.id[3], start.id[4]) << "the bodies after a removed one move down, in order";
}

TEST(ThreadPool, RunsEveryTaskOnceAndRethrowsTheFirstError) {
  ThreadPool pool(4);
  EXPECT_EQ(pool.size(), 4);
  for (int round = 0; round < 200; ++round) {
    std::vector<std::atomic<int>> seen(37);
    pool.run(37, [&](int k) { ++seen[static_cast<size_t>(k)]; });
    for (const auto& s : seen) ASSERT_EQ(s.load(), 1) << "round " << round;
  }
  // Rounds of fewer tasks than threads wake only some workers; the others must not miss a round.
  for (int round = 0; round < 300; ++round) {
    const int tasks = round % 6;
    std::vector<std::atomic<int>> seen(static_cast<size_t>(tasks));
    pool.run(tasks, [&](int k) { ++seen[static_cast<size_t>(k)]; });
    for (const auto& s : seen) ASSERT_EQ(s.load(), 1) << "round " << round;
  }
  EXPECT_THROW(pool.run(10,
                        [](int k) {
                          if (k == 7) throw std::runtime_error("task 7");
                        }),
               std::runtime_error);
  std::atomic<int> after{0};
  pool.run(5, [&](int) { ++after; });  // the pool still works after an error
  EXPECT_EQ(after.load(), 5);
}

// The workers spin a while for the next round, then sleep; the caller likewise for a round's end.
// Rounds with pauses longer than the spin between them, and tasks longer than it, take the sleeping
// paths; rounds back to back, the spinning ones.
TEST(ThreadPool, RoundsAfterTheWorkersSleptAndTasksThatOutlastTheSpin) {
  ThreadPool pool(3);
  for (int round = 0; round < 40; ++round) {
    if (round % 4 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    const int tasks = 1 + round % 5;
    std::vector<std::atomic<int>> seen(static_cast<size_t>(tasks));
    pool.run(tasks, [&](int k) {
      if (round % 3 == 0 && k == tasks - 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      ++seen[static_cast<size_t>(k)];
    });
    for (const auto& s : seen) ASSERT_EQ(s.load(), 1) << "round " << round;
  }
}

// Each thread takes its own contiguous group of a round's tasks first (ThreadPool::Group), so that
// a phase's ranges land on the same thread, and in its cache, round after round. Every task here
// waits until each thread has started one: none can have run out of its own group and stolen yet,
// so each thread's first task is the head of its own group, and the caller's is the last group's.
TEST(ThreadPool, EachThreadStartsWithTheHeadOfItsOwnGroupOfTasks) {
  constexpr int kThreads = 4, kTasks = 8;
  ThreadPool pool(kThreads);
  for (int round = 0; round < 20; ++round) {
    std::atomic<int> started{0};
    std::vector<std::thread::id> ranBy(kTasks);
    std::vector<std::atomic<int>> seen(kTasks);
    pool.run(kTasks, [&](int k) {
      ranBy[static_cast<size_t>(k)] = std::this_thread::get_id();
      ++seen[static_cast<size_t>(k)];
      if (started.fetch_add(1) < kThreads)
        while (started.load() < kThreads) std::this_thread::yield();
    });
    for (const auto& s : seen) ASSERT_EQ(s.load(), 1) << "round " << round;
    // The heads 0, 2, 4 and 6 ran on four different threads, the last group's on the caller.
    std::vector<std::thread::id> heads;
    for (int k = 0; k < kTasks; k += kTasks / kThreads) heads.push_back(ranBy[static_cast<size_t>(k)]);
    std::sort(heads.begin(), heads.end());
    EXPECT_EQ(std::unique(heads.begin(), heads.end()), heads.end()) << "two groups' heads on one thread, round " << round;
    EXPECT_EQ(ranBy[kTasks - kTasks / kThreads], std::this_thread::get_id()) << "round " << round;
  }
}

// GEM_CPU_TIMING's account of the pool: off, nothing is counted; on, every round and task is, and
// the parts add up (the wait on the last tasks is part of a round, a task lies within its round).
TEST(ThreadPool, CountsItsRoundsAndTasksOnlyWhenMeasuring) {
  ThreadPool pool(3);
  pool.run(9, [](int) {});
  EXPECT_EQ(pool.stats().rounds, 0);
  pool.setMeasuring(true);
  for (int round = 0; round < 10; ++round)
    pool.run(9, [](int k) {
      if (k == 8) std::this_thread::sleep_for(std::chrono::microseconds(200));
    });
  pool.run(1, [](int) {});  // one task runs on the caller alone: not a round on the pool
  const ThreadPool::Stats& stats = pool.stats();
  EXPECT_EQ(stats.rounds, 10);
  EXPECT_EQ(stats.tasks, 90);
  EXPECT_GE(stats.longestTask, 10 * 200e-6);
  EXPECT_LE(stats.longestTask, stats.inRounds);
  EXPECT_LE(stats.tail, stats.inRounds);
  EXPECT_GE(stats.busy, stats.longestTask);
  EXPECT_LE(stats.busy, 3 * stats.inRounds);
  pool.resetStats();
  EXPECT_EQ(pool.stats().rounds, 0);
  EXPECT_EQ(pool.stats().busy, 0);
}

TEST(Threads, TheScenarioKeyAndTheCommandLineOption) {
  test::TempDir dir;
  EXPECT_EQ(test::scenarioFromToml(dir, test::kBusyScene).threads, 0);
  EXPECT_EQ(test::scenarioFromToml(dir, test::kBusyScene, {"simulation.threads=3"}).threads, 3);
  EXPECT_THROW(test::scenarioFromToml(dir, test::kBusyScene, {"simulation.threads=-1"}), InputError);
  const auto scene = dir.write("busy.toml", test::kBusyScene);
  const auto log = dir.path() / "log.txt";
  ASSERT_EQ(test::runGem("run " + scene.string() + " --backend cpu --threads 2 --steps 20 --out " + (dir.path() / "out").string(), log), 0)
      << test::readFile(log);
  EXPECT_EQ(test::runGem("run " + scene.string() + " --threads -2 --steps 20 --out " + (dir.path() / "out2").string(), log), 2);
}

}  // namespace
}  // namespace gem
