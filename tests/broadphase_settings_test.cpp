// Broadphase settings are each strategy's own (docs/scenario.md [broadphase.NAME]): a strategy takes
// only the keys it declares, from its own table or the older [simulation] keys; any other is refused
// naming the key and the strategies that take it, never silently ignored.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "framework/api/errors.hpp"
#include "framework/scenario/scenario.hpp"
#include "tests/test_support.hpp"

namespace gem {
namespace {

const std::string kBase = "[simulation]\ndt = 0.1\nsteps = 10\n";

std::string errorOf(const std::string& toml) {
  test::TempDir dir;
  try {
    test::scenarioFromToml(dir, toml);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(BroadphaseSettings, TheStrategysOwnTableSetsWhatItDeclares) {
  test::TempDir dir;
  const Scenario s = test::scenarioFromToml(dir, kBase + "broadphase = \"uniform_grid\"\n[broadphase.uniform_grid]\ncell_size = 30.0\n");
  EXPECT_EQ(s.broadphaseSettings.cellSize, 30.0);
  const Scenario v = test::scenarioFromToml(dir, kBase + "broadphase = \"variable_radius\"\n[broadphase.variable_radius]\nskin = 1.5\n");
  EXPECT_EQ(v.broadphaseSettings.skin, 1.5);
  EXPECT_NE(std::find(s.broadphaseSettings.given.begin(), s.broadphaseSettings.given.end(), "cell_size"), s.broadphaseSettings.given.end());
  // The older keys in [simulation] still work for the strategy that declares them.
  const Scenario old = test::scenarioFromToml(dir, kBase + "broadphase = \"fixed_radius\"\nfixed_radius = 12.0\n");
  EXPECT_EQ(old.broadphaseSettings.fixedRadius, 12.0);
}

TEST(BroadphaseSettings, AKeyTheChosenStrategyDoesNotTakeIsRefused) {
  const std::string e = errorOf(kBase + "broadphase = \"variable_radius\"\ncell_size = 20.0\n");
  EXPECT_TRUE(contains(e, "simulation.cell_size")) << e;
  EXPECT_TRUE(contains(e, "\"variable_radius\" has no setting cell_size")) << e;
  EXPECT_TRUE(contains(e, "uniform_grid takes it")) << e;
  // uniform_grid is rebuilt every step, on both backends: it has no skin to set.
  const std::string g = errorOf(kBase + "broadphase = \"uniform_grid\"\n[broadphase.uniform_grid]\nskin = 1.0\n");
  EXPECT_TRUE(contains(g, "\"uniform_grid\" has no setting skin")) << g;
  const std::string f = errorOf(kBase + "broadphase = \"all_pairs\"\n[broadphase.all_pairs]\nskin = 1.0\n");
  EXPECT_TRUE(contains(f, "broadphase.all_pairs.skin")) << f;
  EXPECT_TRUE(contains(f, "it has no settings")) << f;
}

TEST(BroadphaseSettings, UnknownStrategiesKeysAndTwiceGivenKeysAreRefused) {
  const std::string unknown = errorOf(kBase + "[broadphase.quadtree]\nskin = 1.0\n");
  EXPECT_TRUE(contains(unknown, "broadphase.quadtree")) << unknown;
  EXPECT_TRUE(contains(unknown, "uniform_grid")) << unknown;  // the valid names are listed
  const std::string typo = errorOf(kBase + "broadphase = \"uniform_grid\"\n[broadphase.uniform_grid]\ncellsize = 20.0\n");
  EXPECT_TRUE(contains(typo, "broadphase.uniform_grid.cellsize")) << typo;
  // An unknown key names the strategy's settings as the valid ones, also those the table leaves out.
  EXPECT_TRUE(contains(typo, "valid keys here: cell_size")) << typo;
  const std::string kept = errorOf(kBase + "broadphase = \"fixed_radius\"\n[broadphase.fixed_radius]\nskin = 1.0\nfoo = 2\n");
  EXPECT_TRUE(contains(kept, "fixed_radius, skin")) << kept;
  const std::string inSimulation = errorOf(kBase + "broadphase = \"variable_radius\"\nfoo = 2\n");
  EXPECT_TRUE(contains(inSimulation, "simulation.foo")) << inSimulation;
  EXPECT_TRUE(contains(inSimulation, "skin")) << inSimulation;
  const std::string twice =
      errorOf(kBase + "broadphase = \"uniform_grid\"\ncell_size = 20.0\n[broadphase.uniform_grid]\ncell_size = 30.0\n");
  EXPECT_TRUE(contains(twice, "given twice")) << twice;
}

}  // namespace
}  // namespace gem
