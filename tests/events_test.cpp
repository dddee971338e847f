// The analytic validation cases of docs/model.md 10 for each event, run through the real scheduler.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "events/ship_impact.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/world/vessel.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::eventsOnly;
using gem::test::TempDir;

namespace {

// The stem's x in the world for a vessel at the origin with heading 0.
Real stemX(const Scenario& s) { return s.vessel.position.x + hullGeometry(s.vessel).stemX; }

const char* kBase = "[simulation]\ndt = 0.1\nsteps = 10\nmorton_sort = false\n";

struct Momentum {
  Vec2 linear;
  Real angular;  // about the origin
};

Momentum momentum(const World& w) {
  Momentum m{{0, 0}, 0};
  for (int i = 0; i < w.size(); ++i) {
    m.linear += w.mass[i] * w.velocity(i);
    m.angular += w.mass[i] * cross(w.position(i), w.velocity(i)) + w.mass[i] * w.gyration2[i] * w.omega[i];
  }
  return m;
}

}  // namespace

TEST(Impact, HeadOnCentredImpactOfEqualFloesLeavesBothAtTheCommonVelocity) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(dir, std::string(kBase) + eventsOnly({"impact"}));
  World w;
  w.addBody(test::squareFloe({0, 0}, 10, 1, {1, 0}));
  w.addBody(test::squareFloe({10.05, 0}, 10, 1, {0, 0}));
  CpuStepper sim(s, std::move(w));
  sim.step();  // closes the 5 cm gap
  EXPECT_EQ(sim.contactCount(), 0);
  sim.step();  // overlapping: one inelastic impulse
  ASSERT_EQ(sim.contactCount(), 1);
  const World& r = sim.world();
  EXPECT_NEAR(r.vx[0], 0.5, 1e-12);
  EXPECT_NEAR(r.vx[1], 0.5, 1e-12);
  EXPECT_NEAR(r.vy[0], 0.0, 1e-12);
  EXPECT_NEAR(r.omega[0], 0.0, 1e-12);
  EXPECT_NEAR(r.omega[1], 0.0, 1e-12);
}

TEST(Impact, EveryContactConservesLinearAndAngularMomentum) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(dir, std::string(kBase) + eventsOnly({"impact", "elastic_contact"}), {"events.impact.friction=0.3"});
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int withContact = 0;
  for (int trial = 0; trial < 200; ++trial) {
    World w;
    w.addBody(test::squareFloe({0, 0}, 4 + 2 * u(rng), 0.5 + 0.4 * u(rng), {u(rng), u(rng)}, 0.2 * u(rng)));
    BodySpec b = test::squareFloe({0, 0}, 3 + u(rng), 1 + 0.5 * u(rng), {u(rng), u(rng)}, 0.2 * u(rng));
    const Real angle = 3 * u(rng);
    const Vec2 offset{4.0 + 0.8 * u(rng), 2.5 * u(rng)};
    for (Vec2& v : b.vertices) v = rotate(v, angle) + offset;
    w.addBody(b);
    CpuStepper sim(s, std::move(w));
    const Momentum before = momentum(sim.world());
    sim.step();
    if (sim.contactCount() == 0) continue;
    ++withContact;
    const Momentum after = momentum(sim.world());
    const Real scale = std::max<Real>(1, norm(before.linear));
    EXPECT_NEAR(after.linear.x, before.linear.x, 1e-9 * scale);
    EXPECT_NEAR(after.linear.y, before.linear.y, 1e-9 * scale);
    EXPECT_NEAR(after.angular, before.angular, 1e-9 * std::max<Real>(1, std::fabs(before.angular)) * 10);
  }
  EXPECT_GT(withContact, 50);  // the trial set really exercises contacts
}

TEST(Impact, ClosingBodiesNeverGainNormalSpeedAndSeparatingOnesAreLeftAlone) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(dir, std::string(kBase) + eventsOnly({"impact"}));
  World w;
  w.addBody(test::squareFloe({0, 0}, 10, 1, {-1, 0}));  // already separating, though overlapping
  w.addBody(test::squareFloe({9.9, 0}, 10, 1, {1, 0}));
  CpuStepper sim(s, std::move(w));
  sim.step();
  ASSERT_EQ(sim.contactCount(), 1);
  EXPECT_EQ(sim.world().vx[0], -1);
  EXPECT_EQ(sim.world().vx[1], 1);
}

TEST(ElasticContact, ImpulseMatchesTheFormulaForTwoOverlappingSquaresAtRest) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(dir, std::string(kBase) + eventsOnly({"elastic_contact"}));
  World w;
  w.addBody(test::squareFloe({0, 0}, 10, 1.0));
  w.addBody(test::squareFloe({7.8, 0}, 6, 0.5));  // overlap 0.2 m x 6 m
  CpuStepper sim(s, std::move(w));
  const Real m1 = sim.world().mass[0], m2 = sim.world().mass[1];
  sim.step();
  ASSERT_EQ(sim.contactCount(), 1);
  // w = 6, A_0 = 1.2, D = sqrt(36) = 6, C = min(1.2 * 100 / 36, 1) = 1, h = 0.5
  const Real impulse = 0.05 * 1.0 * 1e6 * 6 * 0.5 * 0.1;
  EXPECT_NEAR(sim.world().vx[1], impulse / m2, 1e-12);
  EXPECT_NEAR(sim.world().vx[0], -impulse / m1, 1e-12);
  // A thin sliver: C = A_0 K / (w D) < 1 scales it down.
  World thin;
  thin.addBody(test::squareFloe({0, 0}, 10, 1.0));
  thin.addBody(test::squareFloe({7.99, 0}, 6, 0.5));  // A_0 = 0.06, C = 0.06 * 100 / 36
  CpuStepper sim2(s, std::move(thin));
  sim2.step();
  EXPECT_NEAR(sim2.world().vx[1], 0.05 * (0.06 * 100 / 36) * 1e6 * 6 * 0.5 * 0.1 / m2, 1e-9);
}

TEST(Drag, OneStepIsTheFormulaAndAFloeSlowsAsTheClosedForm) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(dir, "[simulation]\ndt = 0.01\nsteps = 10\nmorton_sort = false\n" + eventsOnly({"drag"}));
  World w;
  w.addBody(test::squareFloe({0, 0}, 5, 1.0, {1.0, -0.5}, 0.2));
  CpuStepper sim(s, std::move(w));
  const Real k = 0.5 * 1025 * 0.05 / (900 * 1.0);  // 1/m
  sim.step();
  EXPECT_NEAR(sim.world().vx[0], 1.0 - k * 1.0 * 1.0 * 0.01, 1e-15);
  EXPECT_NEAR(sim.world().vy[0], -0.5 + k * 0.25 * 0.01, 1e-15);
  EXPECT_NEAR(sim.world().omega[0], 0.2 - k * 1.0 * 0.04 * 0.01, 1e-15);
  // v(t) = v0 / (1 + k v0 t) for dv/dt = -k v^2.
  for (int i = 1; i < 10000; ++i) sim.step();
  const Real t = 100;
  EXPECT_NEAR(sim.world().vx[0], 1.0 / (1 + k * 1.0 * t), 2e-3 * 1.0 / (1 + k * t));
  EXPECT_NEAR(sim.world().vy[0], -0.5 / (1 + k * 0.5 * t), 2e-3 * 0.5 / (1 + k * 0.5 * t));
}

TEST(Propulsion, VesselAloneSettlesAtTheOpenWaterSpeed) {
  TempDir dir;
  Scenario s =
      test::scenarioFromToml(dir, std::string(kBase) + eventsOnly({"propulsion"}) +
                                      "[vessel]\nposition = [0.0, 0.0]\nspeed = 0.0\nbollard_thrust = 370e3\nopen_water_speed = 4.9\n");
  World w;
  addVessel(w, s.vessel);
  CpuStepper sim(s, std::move(w));
  for (int i = 0; i < 6000; ++i) sim.step();
  EXPECT_NEAR(sim.world().vx[0], 4.9, 4.9e-3);
  EXPECT_EQ(sim.world().vy[0], 0);
  // Starting at V_ow it stays there: T_net = 0.
  s.vessel.speed = 4.9;
  World w2;
  addVessel(w2, s.vessel);
  CpuStepper sim2(s, std::move(w2));
  for (int i = 0; i < 100; ++i) sim2.step();
  EXPECT_NEAR(sim2.world().vx[0], 4.9, 1e-9);
}

TEST(Autopilot, ThreeDofVesselReturnsToItsTrackAndHeading) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(
      dir, std::string(kBase) + eventsOnly({"propulsion", "autopilot"}) + "[vessel]\ndof = 3\nposition = [0.0, 0.0]\n");
  World w;
  const int v = addVessel(w, s.vessel);
  w.y[v] = 5;                  // 5 m off the track
  w.angle[v] = 5 * kPi / 180;  // 5 degrees off the heading
  CpuStepper sim(s, std::move(w));
  Real largestOffset = 0;
  for (int i = 0; i < 3000; ++i) {
    sim.step();
    largestOffset = std::max(largestOffset, std::fabs(sim.world().y[0]));
  }
  EXPECT_LT(std::fabs(sim.world().y[0]), 0.05);
  EXPECT_LT(std::fabs(sim.world().angle[0]), 0.1 * kPi / 180);
  EXPECT_LT(largestOffset, 30);  // critically damped: no wild excursion
}

TEST(Motion, OneDofVesselNeitherSwaysNorTurnsWhenHitObliquely) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(
      dir, std::string(kBase) + eventsOnly({"impact", "elastic_contact"}) + "[vessel]\nposition = [0.0, 0.0]\nspeed = 3.0\n");
  World w;
  addVessel(w, s.vessel);
  BodySpec floe = test::squareFloe({0, 0}, 8, 1.0, {0, 0});
  for (Vec2& p : floe.vertices) p = rotate(p, 0.4) + Vec2{stemX(s) + 4, 6};
  w.addBody(floe);
  CpuStepper sim(s, std::move(w));
  int contacts = 0;
  for (int i = 0; i < 40; ++i) {
    sim.step();
    contacts += sim.contactCount();
  }
  ASSERT_GT(contacts, 0);
  const int v = sim.vesselSlot();
  EXPECT_EQ(sim.world().y[v], 0);
  EXPECT_EQ(sim.world().angle[v], 0);
  EXPECT_EQ(sim.world().vy[v], 0);
  EXPECT_LT(sim.world().vx[v], 3.0);  // the floe slowed it
  EXPECT_GT(sim.world().vy[1], 0);    // and was pushed aside (to port: it sits to port of the stem)
}

TEST(Wind, GivenStressAcceleratesAFloeAsFdtOverRhoH) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(
      dir, std::string(kBase) + eventsOnly({}) + "[events.wind]\nforce = 2.0\ndirection_deg = 90.0\n[events.current]\nforce = 1.0\n");
  World w;
  w.addBody(test::squareFloe({0, 0}, 5, 0.5));
  CpuStepper sim(s, std::move(w));
  sim.step();
  EXPECT_NEAR(sim.world().vy[0], 2.0 * 0.1 / (900 * 0.5), 1e-15);
  EXPECT_NEAR(sim.world().vx[0], 1.0 * 0.1 / (900 * 0.5), 1e-15);
}

TEST(Current, BulkStressDrivesAFloeTowardsTheCurrentSpeed) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(dir, "[simulation]\ndt = 0.5\nsteps = 10\nmorton_sort = false\n" + eventsOnly({}) +
                                               "[events.current]\nspeed = 0.3\ndirection_deg = 0.0\n");
  World w;
  w.addBody(test::squareFloe({0, 0}, 5, 0.5));
  CpuStepper sim(s, std::move(w));
  for (int i = 0; i < 20000; ++i) sim.step();
  // d(U - v)/dt = -k (U - v)^2 with k = rho_w C_w / (rho_ice h): U - v = U / (1 + k U t).
  const Real k = 1025 * 5.5e-3 / (900 * 0.5), lag = 0.3 / (1 + k * 0.3 * 10000);
  EXPECT_NEAR(0.3 - sim.world().vx[0], lag, 0.02 * lag);
}

TEST(ShipImpact, ForceIsTheDirectEvaluationOfModelSection5) {
  // A 10 m square floe dead ahead of the stem, principal axes along x: every moment arm is simple.
  VesselSpec vessel;
  vessel.present = true;
  vessel.position = {0, 0};
  World w;
  const int s = addVessel(w, vessel);
  const int f = w.addBody(test::squareFloe({60, 0}, 10, 0.7));
  auto body = [&](int i) {
    PairBody b{};
    b.kind = w.kind[i];
    b.position = w.position(i);
    b.mass = w.mass[i];
    b.gyration2 = w.gyration2[i];
    b.gyrationX2 = w.gyrationX2[i];
    b.gyrationY2 = w.gyrationY2[i];
    b.principalAngle = w.angle[i] + w.principalAngle[i];
    b.thickness = w.thickness[i];
    return b;
  };
  ShipImpact::Params p{};
  p.gyrationX2 = 0.003 * 100 * 100;
  p.gyrationY2 = 0.05 * 100 * 100;
  p.gyrationZ2 = 0.06 * 100 * 100;
  p.pressure = 1e6;
  p.flexuralStrength = 0.5e6;
  p.hullFriction = 0.1;
  const Real beta = 60 * kPi / 180, phi = kPi / 2, vn = 3;
  const Vec2 c = w.position(s) + Vec2{55, 0};  // on the centre line, 5 m behind the floe's centroid
  const ShipImpact::Result r = ShipImpact::evaluate(p, body(s), body(f), c, {1, 0}, vn, beta, phi);

  const Real nx = std::cos(beta), nz = std::sin(beta);
  const Real xs = 55 - w.position(s).x + w.position(s).x;  // contact x in the ship frame about its centroid
  const Real coS = nx * nx + nz * nz / 2 + (nz * xs) * (nz * xs) / (2 * 0.05 * 100 * 100);
  const Real ryf2 = (10.0 * 10.0) / 12;  // r_y^2 of a square of side 10
  const Real coF = nx * nx + nz * nz / 2 + (nz * 5) * (nz * 5) / (2 * ryf2);
  const Real me = 1 / (coS / w.mass[s] + coF / w.mass[f]);
  const Real vnb = vn * std::cos(beta);
  const Real fa13 = (0.012 * 90 + 0.6) * (1.38 - 0.027 * 60 + 0.0004 * 3600);
  const Real fn = 1.3104 * 100 * fa13 * std::pow(me, 2.0 / 3) * std::pow(vnb, 4.0 / 3);
  const Real kv = std::max(1.0, 2.14 * std::pow(vnb / std::sqrt(9.81 * 0.7), 0.33));
  const Real flim = 0.382 * 0.5e6 * 0.7 * 0.7 * (kPi / 2) * kv /
                    ((std::sin(beta) - 0.1 * std::cos(beta)) - 0.039 * (std::cos(beta) + 0.1 * std::sin(beta)));
  EXPECT_NEAR(r.effectiveMass, me, 1e-9 * me);
  EXPECT_NEAR(r.forceNormal, fn, 1e-9 * fn);
  EXPECT_NEAR(r.forceLimit, flim, 1e-9 * flim);
  EXPECT_EQ(r.broke, fn > flim);
  EXPECT_NEAR(r.force, std::min(fn, flim), 1e-9 * fn);
  // A wall-sided frame (beta = 0) cannot fail in bending.
  EXPECT_TRUE(std::isinf(ShipImpact::evaluate(p, body(s), body(f), c, {1, 0}, vn, 0, phi).forceLimit));
}

// docs/model.md 5: every ship-ice collision is an impact (the vessel and a floe overlap and their
// contact points approach), not only a contact's first step. A floe pushed ahead of the bow by the
// thrusting vessel, slowed by water drag, is struck again each time the hull closes on it: several
// impacts, each with its own closing speed, all at the stem.
TEST(ShipImpact, AFloePushedAlongTheBowIsStruckAgainAndAgain) {
  TempDir dir;
  Scenario s =
      test::scenarioFromToml(dir, std::string(kBase) + eventsOnly({"ship_impact", "impact", "elastic_contact", "propulsion", "drag"}) +
                                      "[vessel]\nposition = [0.0, 0.0]\nspeed = 2.0\n");
  World w;
  addVessel(w, s.vessel);
  w.addBody(test::squareFloe({stemX(s) + 5.1, 0}, 10, 2.0));  // thick: it will not break
  CpuStepper sim(s, std::move(w));
  std::vector<double> speeds;
  for (int i = 0; i < 600; ++i) {
    sim.step();
    for (const ImpactRecord& r : ::gem::test::impactsOf(sim)) {
      EXPECT_NEAR(r.frameAngleDeg, 60, 1e-9);  // the default hull's stem
      EXPECT_GT(r.closingSpeed, 0);
      EXPECT_GT(r.force, 0);
      speeds.push_back(r.closingSpeed);
    }
  }
  ASSERT_GE(speeds.size(), 3u) << "a floe pushed along the bow is struck more than once";
  EXPECT_LT(speeds.back(), speeds.front()) << "later strikes are slower than the first";
  EXPECT_NE(speeds[1], speeds[2]) << "each strike has its own closing speed";
}

TEST(ShipImpact, IsLoggedAtTheFirstStrikeWithTheHullAngleOfTheStem) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(dir, std::string(kBase) + eventsOnly({"ship_impact", "impact", "elastic_contact"}) +
                                               "[vessel]\nposition = [0.0, 0.0]\nspeed = 2.0\n");
  World w;
  addVessel(w, s.vessel);
  w.addBody(test::squareFloe({stemX(s) + 5.1, 0}, 10, 2.0));  // thick: it will not break
  CpuStepper sim(s, std::move(w));
  int logged = 0, stepsInContact = 0;
  for (int i = 0; i < 30; ++i) {
    sim.step();
    stepsInContact += sim.contactCount() > 0;
    for (const ImpactRecord& r : ::gem::test::impactsOf(sim)) {
      ++logged;
      EXPECT_NEAR(r.frameAngleDeg, 60, 1e-9);  // the default hull's stem
      EXPECT_NEAR(r.normal.x, 1, 1e-9);
      EXPECT_NEAR(r.xFromStem, 0, 0.2);
      EXPECT_GT(r.force, 0);
    }
  }
  // Without thrust or drag the floe then moves with the hull: no second strike, not even one of a
  // closing speed of rounding size (1 ulp of 2 m/s, once the elastic push no longer parts them).
  EXPECT_EQ(logged, 1);
  EXPECT_GE(stepsInContact, 1);
}

TEST(FlexuralBreaking, ThinFloeStruckHardSplitsAndMassIsAccountedFor) {
  TempDir dir;
  Scenario s = test::scenarioFromToml(dir,
                                      std::string(kBase) + eventsOnly({"ship_impact", "impact", "elastic_contact", "flexural_breaking"}) +
                                          "[vessel]\nposition = [0.0, 0.0]\nspeed = 6.0\n",
                                      {"events.flexural_breaking.min_area=20.0"});
  World w;
  addVessel(w, s.vessel);
  w.addBody(test::squareFloe({stemX(s) + 6.1, 0.5}, 12, 0.3, {0, 0}, 0.01));
  CpuStepper sim(s, std::move(w));
  const double massBefore = sim.world().floeMass();
  bool broke = false;
  for (int i = 0; i < 10 && !broke; ++i) {
    sim.step();
    for (const ImpactRecord& r : ::gem::test::impactsOf(sim)) broke |= r.broke;
  }
  ASSERT_TRUE(broke);
  ASSERT_EQ(sim.floesBroken(), 1);
  const World& r = sim.world();
  EXPECT_NEAR(r.floeMass() + sim.rubbleMass(), massBefore, 1e-9 * massBefore);
  std::vector<int> pieces;
  for (int i = 0; i < r.size(); ++i) {
    if (r.kind[i] != BodyKind::Floe) continue;
    pieces.push_back(i);
    EXPECT_GE(r.id[i], 2);  // the parent (id 1) is gone, pieces have new ids
    EXPECT_GE(r.area[i], 20.0);
    EXPECT_EQ(r.thickness[i], 0.3);
    Vec2 v[kMaxVertices];
    const int n = r.worldVertices(i, v);
    EXPECT_TRUE(isStrictlyConvexCCW(v, n, 1e-9));
  }
  // Pieces move rigidly with the parent: same omega, v_i - v_j = omega x (c_i - c_j).
  if (pieces.size() == 2) {
    const int i = pieces[0], j = pieces[1];
    EXPECT_EQ(r.omega[i], r.omega[j]);
    const Vec2 expected = crossZ(r.omega[i], r.position(i) - r.position(j));
    EXPECT_NEAR(r.vx[i] - r.vx[j], expected.x, 1e-9);
    EXPECT_NEAR(r.vy[i] - r.vy[j], expected.y, 1e-9);
  }
}
