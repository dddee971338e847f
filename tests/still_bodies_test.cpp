// The CPU stepper leaves out of the body updates a body that the last updates left exactly as it
// was and that touches nothing, while every solo and motion event of the run declares itself time
// invariant (CpuStepper's m_stillness, docs/performance.md 3.12), and the narrowphase then takes
// the pose flags, vertices and boxes the body updates left ready (3.18). Leaving it out must change
// no bit of any run.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "framework/api/registry.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "test_support.hpp"

namespace gem {

// A solo event that changes nothing and does not declare itself time invariant: with it on, every
// body is updated every step, the stepper as it was before bodies were left out.
struct TestUndeclaredNothing {
  struct Params {
    int unused;
  };
  static void apply(const Params&, const SoloBody&, VelocityChange&, const StepContext&) {}
};
static TestUndeclaredNothing::Params parseUndeclaredNothing(EventConfig&) { return {0}; }
GEM_REGISTER_SOLO_EVENT(TestUndeclaredNothing, "test_undeclared_nothing", "test: changes nothing, not declared time invariant", false,
                        parseUndeclaredNothing);

// A solo event that depends on the step: every floe gets 0.5 m/s along x at step 5 only.
struct TestKickAtStepFive {
  struct Params {
    int unused;
  };
  static void apply(const Params&, const SoloBody& body, VelocityChange& change, const StepContext& ctx) {
    if (ctx.step == 5 && body.kind == BodyKind::Floe) change.dv.x += Real(0.5);
  }
};
static TestKickAtStepFive::Params parseKickAtStepFive(EventConfig&) { return {0}; }
GEM_REGISTER_SOLO_EVENT(TestKickAtStepFive, "test_kick_at_step_five", "test: every floe gets 0.5 m/s along x at step 5", false,
                        parseKickAtStepFive);

namespace {

struct StillRun {
  std::vector<std::int64_t> ids;
  std::vector<Real> state;
  long updated = 0;  // body updates over the run
  long bodySteps = 0;
  long contacts = 0;
};

StillRun run(const Scenario& base, int threads, int steps) {
  Scenario s = base;
  s.threads = threads;
  CpuStepper sim(s);
  StillRun r;
  for (int k = 0; k < steps; ++k) {
    const int bodies = sim.hostWorld().size();
    sim.step();
    r.updated += sim.updatedBodies();
    r.bodySteps += bodies;
    r.contacts += sim.contactCount();
  }
  const World& w = sim.hostWorld();
  r.ids = w.id;
  for (const std::vector<Real>* v : {&w.x, &w.y, &w.angle, &w.vx, &w.vy, &w.omega}) r.state.insert(r.state.end(), v->begin(), v->end());
  return r;
}

void expectSameBits(const StillRun& a, const StillRun& b) {
  ASSERT_EQ(a.ids, b.ids);
  ASSERT_EQ(a.state.size(), b.state.size());
  EXPECT_EQ(0, std::memcmp(a.state.data(), b.state.data(), a.state.size() * sizeof(Real)));
  EXPECT_EQ(a.contacts, b.contacts);
}

// The vessel shoving through a pack that breaks (bodies added and removed) and is re-sorted at
// step 200, on one thread and on three (a field large enough for the pool): leaving the resting
// floes out gives the run of every body every step, bit for bit.
TEST(StillBodies, LeavingThemOutChangesNoBitOfARun) {
  test::TempDir dir;
  const std::vector<std::string> large{"simulation.steps=210", "domain.x=[0.0, 700.0]", "domain.y=[-200.0, 200.0]"};
  std::vector<std::string> undeclared = large;
  undeclared.push_back("events.test_undeclared_nothing.enabled=true");
  const Scenario leftOut = test::scenarioFromToml(dir, test::kBusyScene, large);
  const Scenario everyBody = test::scenarioFromToml(dir, test::kBusyScene, undeclared);
  const StillRun all = run(everyBody, 1, 210);
  EXPECT_EQ(all.updated, all.bodySteps) << "an undeclared event must have every body updated";
  EXPECT_GE(all.ids.size(), static_cast<size_t>(CpuStepper::kParallelBodies)) << "the field is too small to run on the pool";
  EXPECT_GT(all.contacts, 500) << "the run must touch, or it guards little";
  for (int threads : {1, 3}) {
    SCOPED_TRACE(::testing::Message() << threads << " threads");
    const StillRun some = run(leftOut, threads, 210);
    EXPECT_LT(some.updated, all.updated / 2) << "most of the pack rests: most bodies should have been left out";
    expectSameBits(all, some);
  }
}

// After a break (bodies removed and added, the later slots shifted) and the re-sort at step 200
// (nearly every slot changed), what the last body updates left follows each body to its new slot
// (CpuStepper::followBodiesToNewSlots), so the next step leaves the resting floes out as any step
// does. The run must be, bit for bit, the run whose stepper reads every body afresh every step (an
// edit through world() before each step), on one thread and on three.
TEST(StillBodies, FlagsFollowTheirBodiesThroughBreaksAndReSorts) {
  test::TempDir dir;
  const Scenario s0 =
      test::scenarioFromToml(dir, test::kBusyScene, {"simulation.steps=230", "domain.x=[0.0, 700.0]", "domain.y=[-200.0, 200.0]"});
  auto runIt = [&](int threads, bool afresh, int* renames, int* keptAfterRename) {
    Scenario s = s0;
    s.threads = threads;
    CpuStepper sim(s);
    long broken = 0;
    bool renamed = false;
    for (int k = 0; k < 230; ++k) {
      if (afresh) sim.world();  // takes nothing for still: every body read afresh
      sim.step();
      if (renamed && renames) {
        ++*renames;
        *keptAfterRename += sim.updatedBodies() < sim.hostWorld().size() / 2;
      }
      renamed = sim.floesBroken() != broken || sim.stepIndex() == 200;
      broken = sim.floesBroken();
    }
    StillRun r;
    const World& w = sim.hostWorld();
    r.ids = w.id;
    for (const std::vector<Real>* v : {&w.x, &w.y, &w.angle, &w.vx, &w.vy, &w.omega}) r.state.insert(r.state.end(), v->begin(), v->end());
    r.contacts = sim.contactCount();
    return r;
  };
  const StillRun afresh = runIt(1, true, nullptr, nullptr);
  for (int threads : {1, 3}) {
    SCOPED_TRACE(::testing::Message() << threads << " threads");
    int renames = 0, kept = 0;
    const StillRun followed = runIt(threads, false, &renames, &kept);
    EXPECT_GE(renames, 2) << "the run must break floes and re-sort, or it guards little";
    EXPECT_EQ(kept, renames) << "a step after a break or a re-sort updated most bodies: the still flags did not follow them";
    expectSameBits(afresh, followed);
  }
}

// A resting pack, no vessel: a solo event that reads the step, not declared time invariant, must
// still reach every floe at its step, though none of them moved before it.
TEST(StillBodies, AnEventThatReadsTheStepReachesEveryRestingFloe) {
  test::TempDir dir;
  Scenario s = test::scenarioFromToml(dir, test::kBusyScene, {"simulation.steps=20", "events.test_kick_at_step_five.enabled=true"});
  s.vessel.present = false;
  CpuStepper sim(s);
  for (int k = 0; k < 6; ++k) sim.step();
  const World& w = sim.hostWorld();
  int floes = 0;
  for (int i = 0; i < w.size(); ++i) {
    if (w.kind[i] != BodyKind::Floe) continue;
    ++floes;
    EXPECT_GT(w.vx[i], 0) << "floe " << w.id[i] << " was not kicked";
  }
  EXPECT_GT(floes, 20);
}

// An edit of a resting floe through CpuStepper::world() between steps is seen by the next step.
TEST(StillBodies, AnEditThroughWorldIsSeenByTheNextStep) {
  test::TempDir dir;
  Scenario s = test::scenarioFromToml(dir, test::kBusyScene, {"simulation.steps=20"});
  s.vessel.present = false;
  CpuStepper sim(s);
  for (int k = 0; k < 5; ++k) sim.step();
  ASSERT_EQ(sim.updatedBodies(), 0) << "a pack at rest under drag alone: every body should have been left out";
  int floe = -1;
  for (int i = 0; i < sim.hostWorld().size() && floe < 0; ++i)
    if (sim.hostWorld().kind[i] == BodyKind::Floe) floe = i;
  ASSERT_GE(floe, 0);
  const Real x = sim.hostWorld().x[floe];
  sim.world().vx[floe] = Real(0.2);
  sim.step();
  EXPECT_NE(sim.hostWorld().x[floe], x) << "the floe given a velocity did not move";
  EXPECT_EQ(sim.updatedBodies(), sim.hostWorld().size()) << "after an edit every body is read afresh";
}

}  // namespace
}  // namespace gem
