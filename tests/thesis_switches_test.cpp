// The modelling choices of the issue "Fidelity to the thesis" as scenario parameters (docs/scenario.md
// 2.6, docs/validation/sensitivity.md): each test fails if its switch does nothing.
//   - [events.ship_impact] hull_friction: the one ship-ice friction coefficient, in the impact's
//     kinematics too (thesis 3.2.1 L425, A.1.5 L1624);
//   - [events.elastic_contact] vessel: whether pairs with the vessel get the elastic stress (the
//     thesis defines it between floes, 3.2.1 L399, A.1.5 L1622);
//   - summary.json's impacts_in_ice / impact_force_in_ice_n: the impacts of the transit only
//     (thesis 6.2.2.2 L1268).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "events/ship_impact.hpp"
#include "framework/analysis/sweep_summary.hpp"
#include "framework/app/runner.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/world/vessel.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::eventsOnly;
using gem::test::TempDir;

namespace {

const char* kBase = "[simulation]\ndt = 0.1\nsteps = 10\nmorton_sort = false\n";

Real stemX(const Scenario& s) { return s.vessel.position.x + hullGeometry(s.vessel).stemX; }

// A vessel at rest with a floe pressed 0.1 m into its stem, elastic contact alone: the floe's
// velocity after one step.
Vec2 floePushedByTheStem(const std::vector<std::string>& overrides) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(
      dir, std::string(kBase) + eventsOnly({"elastic_contact"}) + "[vessel]\nposition = [0.0, 0.0]\nspeed = 0.0\n", overrides);
  World w;
  addVessel(w, s.vessel);
  const int floe = w.addBody(test::squareFloe({stemX(s) + 4.9, 0}, 10, 1.0));
  CpuStepper sim(s, std::move(w));
  sim.step();
  EXPECT_EQ(sim.contactCount(), 1);
  return sim.world().velocity(floe);
}

// The 1-DOF vessel at 3 m/s strikes a floe on its starboard bow (an oblique bow edge) with the
// impact alone: the floe's velocity and spin after the strike.
struct Struck {
  Vec2 velocity;
  Real omega;
  int impacts;
};

Struck floeStruckOnTheBow(const std::vector<std::string>& overrides) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(
      dir, std::string(kBase) + eventsOnly({"impact", "ship_impact"}) + "[vessel]\nposition = [0.0, 0.0]\nspeed = 3.0\n", overrides);
  World w;
  addVessel(w, s.vessel);
  // Centred 6 m to starboard of the centreline, 7 m ahead of the stem's x: the shoulder edges
  // meet it obliquely.
  const int floe = w.addBody(test::squareFloe({stemX(s) + 1.5, -6.5}, 4, 2.0));
  CpuStepper sim(s, std::move(w));
  int impacts = 0;
  for (int i = 0; i < 40; ++i) {
    sim.step();
    impacts += static_cast<int>(test::impactsOf(sim).size());
  }
  return {sim.world().velocity(floe), sim.world().omega[floe], impacts};
}

}  // namespace

TEST(ThesisSwitches, ElasticContactWithVesselFalseGivesAVesselPressedOnAFloeNoElasticForce) {
  const Vec2 with = floePushedByTheStem({"events.elastic_contact.vessel=true"});
  const Vec2 without = floePushedByTheStem({"events.elastic_contact.vessel=false"});
  EXPECT_EQ(floePushedByTheStem({}).x, 0) << "the default is the thesis's: ice-ice only";
  EXPECT_GT(with.x, 1e-4) << "the elastic stress pushes the floe off the stem";
  EXPECT_EQ(without.x, 0);
  EXPECT_EQ(without.y, 0);
}

TEST(ThesisSwitches, ElasticContactWithVesselFalseStillActsBetweenFloes) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(dir, std::string(kBase) + eventsOnly({"elastic_contact"}), {"events.elastic_contact.vessel=false"});
  World w;
  w.addBody(test::squareFloe({0, 0}, 10, 1.0));
  w.addBody(test::squareFloe({7.8, 0}, 6, 0.5));
  CpuStepper sim(s, std::move(w));
  sim.step();
  EXPECT_GT(sim.world().vx[1], 0);
  EXPECT_LT(sim.world().vx[0], 0);
}

TEST(ThesisSwitches, HullFrictionChangesTheTangentialImpulseOfVesselFloeImpacts) {
  const Struck none = floeStruckOnTheBow({"events.ship_impact.hull_friction=0.0"});
  const Struck some = floeStruckOnTheBow({"events.ship_impact.hull_friction=0.3"});
  ASSERT_GT(none.impacts, 0) << "the floe must be struck";
  ASSERT_GT(some.impacts, 0);
  // Friction drags the floe along the hull, forward: more surge, a different spin.
  EXPECT_GT(some.velocity.x - none.velocity.x, 1e-3);
  EXPECT_GT(std::fabs(some.omega - none.omega), 1e-5);
  // impact.friction is for ice-ice and wall pairs: it leaves a vessel-floe impact as it is.
  const Struck iceOnly = floeStruckOnTheBow({"events.ship_impact.hull_friction=0.0", "events.impact.friction=0.3"});
  EXPECT_EQ(iceOnly.velocity.x, none.velocity.x);
  EXPECT_EQ(iceOnly.velocity.y, none.velocity.y);
  EXPECT_EQ(iceOnly.omega, none.omega);
}

TEST(ThesisSwitches, InIceImpactsExcludeImpactsAfterTheHullLeavesTheField) {
  // The field is x in [0, 150]: the whole 100 m hull is in it while its centroid is in [50, 100].
  // One floe at x = 130 is struck on the transit; one at x = 260, beyond the field, only after the
  // hull has left it.
  TempDir dir;
  const std::string text = std::string("[simulation]\ndt = 0.1\nduration = 80.0\n[domain]\nx = [0.0, 150.0]\ny = [-100.0, 100.0]\n") +
                           "[vessel]\nposition = [-60.0, 0.0]\nbollard_thrust = 370e3\n[events.flexural_breaking]\nenabled = false\n"
                           "[[floes]]\nvertices = [[125.0, -5.0], [135.0, -5.0], [135.0, 5.0], [125.0, 5.0]]\nthickness = 1.0\n"
                           "[[floes]]\nvertices = [[255.0, -5.0], [265.0, -5.0], [265.0, 5.0], [255.0, 5.0]]\nthickness = 1.0\n"
                           "[output]\nframe_every = 0\n";
  Scenario s = test::scenarioFromToml(dir, text);
  s.output.dir = dir.path() / "run";
  RunOptions options;
  options.quiet = true;
  const RunSummary summary = runScenario(s, options);
  ASSERT_EQ(summary.records.size(), 1u);
  const RecordTotals& t = summary.records[0];
  EXPECT_EQ(t.countInIceKey, "impacts_in_ice");
  EXPECT_GT(t.countInIce, 0) << "the floe in the field is struck on the transit";
  EXPECT_GT(t.count, t.countInIce) << "the floe beyond the field is struck too, after the transit";

  // Every impact on the far floe is outside the window; the in-ice count is at most the rest.
  std::ifstream in(s.output.dir / "impacts.csv");
  std::string line;
  std::getline(in, line);
  long farImpacts = 0, rows = 0;
  double farForceSum = 0, allForceSum = 0;
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = test::csvCells(line);
    ++rows;
    allForceSum += std::stod(cells[13]);
    if (std::stod(cells[6]) > 200) ++farImpacts, farForceSum += std::stod(cells[13]);
  }
  EXPECT_EQ(rows, t.count);
  ASSERT_GT(farImpacts, 0);
  EXPECT_LE(t.countInIce, t.count - farImpacts);

  const auto json = readSummaryJson(s.output.dir / "summary.json");
  EXPECT_EQ(json.at("impacts_in_ice"), std::to_string(t.countInIce));
  EXPECT_EQ(json.at("impacts"), std::to_string(t.count));
  EXPECT_FALSE(json.at("impact_force_in_ice_n.mean").empty());
  EXPECT_NE(std::stod(json.at("impact_force_in_ice_n.mean")), std::stod(json.at("impact_force_n.mean")));
}
