// Device broadphases (framework/api/device_broadphase.hpp, broadphase/*.cu): every strategy gives
// the very trajectories of the device grid, bit for bit, since the pairs are sorted by (a, b) and the
// narrowphase drops what the CPU prefilter drops; kept lists rebuild on the device by docs/model.md 9's
// rule; a plugin's broadphase runs on the device with its own device part, and one without a device
// part is refused by cuda and falls back to the CPU under auto. Device runs skip, visibly, where no
// CUDA device exists.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "framework/cuda/cuda_stepper.hpp"
#include "framework/api/device_broadphase.hpp"
#include "framework/app/plugin_loader.hpp"
#include "framework/api/registry.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "../test_support.hpp"
#include "cuda_test_support.hpp"

using namespace gem;
using gem::test::kBusyScene;
using gem::test::TempDir;

namespace {

// Every body's x, y, angle, vx, vy, omega, and the per-step contact and candidate counts.
struct Trajectory {
  std::vector<std::int64_t> ids;
  std::vector<Real> state;
  std::vector<int> contacts, candidates;
  long impacts = 0, broken = 0, rebuilds = 0;
};

Trajectory runOnDevice(const Scenario& s, int steps) {
  CudaStepper sim(s);
  Trajectory t;
  for (int k = 0; k < steps; ++k) {
    sim.step();
    t.contacts.push_back(sim.contactCount());
    t.candidates.push_back(sim.candidateCount());
    t.impacts += static_cast<long>(::gem::test::impactsOf(sim).size());
  }
  const World& w = sim.hostWorld();
  t.ids = w.id;
  for (int i = 0; i < w.size(); ++i) t.state.insert(t.state.end(), {w.x[i], w.y[i], w.angle[i], w.vx[i], w.vy[i], w.omega[i]});
  t.broken = sim.floesBroken();
  t.rebuilds = sim.broadphaseRebuilds();
  return t;
}

Scenario withBroadphase(const TempDir& dir, const std::string& scene, const std::string& broadphase, std::vector<std::string> more = {}) {
  more.push_back("simulation.broadphase=\"" + broadphase + "\"");
  more.push_back("simulation.cuda_driver=\"device\"");  // the device parts of the strategies (the resident driver finds its own pairs)
  return test::scenarioFromToml(dir, scene, more);
}

// Bit for bit (==, not a tolerance): the same contacts in the same order give the same sums.
void expectIdentical(const Trajectory& grid, const Trajectory& other, const std::string& name) {
  ASSERT_EQ(grid.ids, other.ids) << name;
  ASSERT_EQ(grid.state.size(), other.state.size()) << name;
  size_t differing = 0;
  for (size_t k = 0; k < grid.state.size(); ++k) differing += grid.state[k] == other.state[k] ? 0 : 1;
  EXPECT_EQ(differing, 0u) << name << ": state components that differ from the device grid's";
  EXPECT_EQ(grid.contacts, other.contacts) << name;
  EXPECT_EQ(grid.impacts, other.impacts) << name;
  EXPECT_EQ(grid.broken, other.broken) << name;
  for (size_t k = 0; k < other.contacts.size(); ++k)
    ASSERT_GE(other.candidates[k], other.contacts[k]) << name << ": fewer candidates than contacts at step " << k;
}

}  // namespace

// No device needed: every built-in broadphase has a device part, under the built-in origin.
TEST(CudaBroadphase, EveryBuiltInBroadphaseHasADevicePart) {
  for (const BroadphaseEntry* entry : Registry::global().broadphases()) {
    if (entry->origin != "built-in") continue;
    EXPECT_NE(cuda::findCudaBroadphase(entry->name), nullptr) << entry->name << " has no broadphase/" << entry->name << ".cu";
  }
  EXPECT_EQ(cuda::findCudaBroadphase("no_such_broadphase"), nullptr);
}

// 300 steps of the busy channel: breaks (uploads, so stale lists), a Morton re-sort at step 200,
// and floes shoved at the vessel's speed, past half the skin (direct bodies, then rebuilds).
TEST(CudaBroadphase, EveryStrategyGivesTheGridsTrajectoriesBitForBit) {
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  const int steps = 300;
  const Trajectory grid = runOnDevice(withBroadphase(dir, kBusyScene, "uniform_grid"), steps);
  EXPECT_GT(grid.broken, 0);  // the topology round trip is part of the comparison
  for (const std::string name : {"all_pairs", "variable_radius", "fixed_radius", "triangulation_mesh"}) {
    const Trajectory t = runOnDevice(withBroadphase(dir, kBusyScene, name), steps);
    std::printf("%-18s %d steps: %zu bodies, %ld impacts, %ld broken, %ld list rebuilds, candidates at the last step %d (contacts %d)\n",
                name.c_str(), steps, t.ids.size(), t.impacts, t.broken, t.rebuilds, t.candidates.back(), t.contacts.back());
    expectIdentical(grid, t, name);
    if (name != "all_pairs") {
      EXPECT_GT(t.rebuilds, 1) << name;
    }
  }
}

// A small skin makes the displacement rule fire every few steps (no breaks and no re-sort here, so
// every rebuild past the first is the rule's, decided on the device).
TEST(CudaBroadphase, KeptListsRebuildByTheDisplacementRule) {
  GEM_SKIP_WITHOUT_CUDA();
  // Two rows of twelve floes drifting into each other: 24 moving bodies, more than kMaxDirect.
  std::string scene = "[simulation]\ndt = 0.1\nsteps = 60\n";
  for (int row = 0; row < 2; ++row)
    for (int k = 0; k < 12; ++k) {
      const double x0 = row == 0 ? 0.0 : 9.0, y0 = 6.0 * k;
      scene += "[[floes]]\nvertices = [[" + std::to_string(x0) + ", " + std::to_string(y0) + "], [" + std::to_string(x0 + 4) + ", " +
               std::to_string(y0) + "], [" + std::to_string(x0 + 4) + ", " + std::to_string(y0 + 4) + "], [" + std::to_string(x0) + ", " +
               std::to_string(y0 + 4) + "]]\nthickness = 0.5\nvelocity = [" + (row == 0 ? "1.0" : "-1.0") + ", 0.1]\n";
    }
  TempDir dir;
  const std::vector<std::string> smallSkin{"simulation.skin=0.3"};
  const Trajectory grid = runOnDevice(withBroadphase(dir, scene, "uniform_grid", {}), 60);
  long contacts = 0;
  for (int c : grid.contacts) contacts += c;
  EXPECT_GT(contacts, 0);  // the rows meet
  for (const std::string name : {"variable_radius", "fixed_radius", "triangulation_mesh"}) {
    const Trajectory t = runOnDevice(withBroadphase(dir, scene, name, smallSkin), 60);
    std::printf("%-18s two rows, skin 0.3 m, 60 steps: %ld rebuilds\n", name.c_str(), t.rebuilds);
    expectIdentical(grid, t, name);
    EXPECT_GE(t.rebuilds, 5) << name;  // 0.15 m of travel at about 0.1 m per step
  }
}

// A kept list's step that overflows the candidate room is redone with more room: same run.
TEST(CudaBroadphase, CandidateOverflowWithAKeptListIsRedoneBitForBit) {
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  const Scenario s = withBroadphase(dir, kBusyScene, "variable_radius");
  const Trajectory roomy = runOnDevice(s, 100);
  ::setenv("GEM_CUDA_CAPACITY", "8", 1);
  Trajectory cramped;
  try {
    cramped = runOnDevice(s, 100);
  } catch (...) {
    ::unsetenv("GEM_CUDA_CAPACITY");
    throw;
  }
  ::unsetenv("GEM_CUDA_CAPACITY");
  expectIdentical(roomy, cramped, "variable_radius, capacity 8 at the start");
}

// The sweep_and_prune example plugin, built with its .cu (tests/CMakeLists.txt): its device part is
// registered under its own origin only, and a cuda run with it is the grid's run.
TEST(CudaBroadphase, PluginBroadphaseRunsOnTheDeviceIdentically) {
  const LoadedPlugin& plugin = loadPlugin(test::cudaTestPlugin("libsweep_and_prune.so"));
  EXPECT_EQ(Registry::global().broadphase("sweep_and_prune").origin, plugin.origin);
  EXPECT_NE(cuda::findCudaBroadphase("sweep_and_prune", plugin.origin), nullptr);
  EXPECT_EQ(cuda::findCudaBroadphase("sweep_and_prune"), nullptr);  // not a built-in's
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  const std::string scene = std::string(kBusyScene) + "[[plugins]]\npath = \"" + test::cudaTestPlugin("libsweep_and_prune.so") + "\"\n";
  const Trajectory grid = runOnDevice(withBroadphase(dir, scene, "uniform_grid"), 200);
  const Trajectory sap = runOnDevice(withBroadphase(dir, scene, "sweep_and_prune"), 200);
  std::printf("sweep_and_prune plugin, 200 steps on the device: %zu bodies, %ld impacts\n", sap.ids.size(), sap.impacts);
  expectIdentical(grid, sap, "sweep_and_prune");
}

// A broadphase from a plugin without a device part: cuda refuses it, naming it; auto runs it on the
// CPU. (Made here as an entry of a non-built-in origin, as a plugin's would be.)
namespace {
class PairsFromPlugin final : public Broadphase {
 public:
  explicit PairsFromPlugin(const BroadphaseSettings&) {}
  std::string name() const override { return "cpu_only_plugin_broadphase"; }
  void invalidate() override {}
  void findCandidates(const World& world, std::vector<CandidatePair>& pairs) override {
    pairs.clear();
    for (int a = 0; a < world.size(); ++a)
      for (int b = a + 1; b < world.size(); ++b) pairs.push_back({a, b});
  }
};
}  // namespace

TEST(CudaBroadphase, PluginBroadphaseWithoutADevicePartIsRefusedByCudaAndRunsOnTheCpuUnderAuto) {
  GEM_SKIP_WITHOUT_CUDA();
  const BroadphaseEntry* known = nullptr;
  for (const BroadphaseEntry* e : Registry::global().broadphases())
    if (e->name == "cpu_only_plugin_broadphase") known = e;
  if (!known)
    Registry::global().addBroadphase(
        BroadphaseEntry{"cpu_only_plugin_broadphase",
                        "test",
                        "libpairs.so (pairs 1.0)",
                        [](const BroadphaseSettings& s) -> std::unique_ptr<Broadphase> { return std::make_unique<PairsFromPlugin>(s); },
                        {}});
  TempDir dir;
  const std::string scene =
      "[simulation]\nsteps = 5\nbroadphase = \"cpu_only_plugin_broadphase\"\n"
      "[[floes]]\nvertices = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0]]\nvelocity = [1.0, 0.0]\n"
      "[[floes]]\nvertices = [[4.5, 0.0], [8.5, 0.0], [8.5, 4.0]]\n";
  Scenario cuda = test::scenarioFromToml(dir, scene, {"simulation.backend=\"cuda\""});
  try {
    makeStepper(cuda);
    ADD_FAILURE() << "a broadphase without a device part ran on cuda";
  } catch (const BackendUnsupported& e) {
    EXPECT_NE(std::string(e.what()).find("cpu_only_plugin_broadphase"), std::string::npos) << e.what();
  }
  Scenario automatic = test::scenarioFromToml(dir, scene, {"simulation.backend=\"auto\""});
  auto stepper = makeStepper(automatic);
  EXPECT_EQ(stepper->backend(), "cpu");
  for (int k = 0; k < 5; ++k) stepper->step();
}

// [broadphase.uniform_grid] cell_size reaches the device's grid (it was dropped there): a cell far
// smaller than the largest floe makes most floes "large" (tested against all), a far larger one
// puts many in a cell; both step bit for bit as the default grid.
TEST(CudaBroadphase, UniformGridHonoursCellSizeOnTheDevice) {
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  const int steps = 150;
  const Trajectory grid = runOnDevice(test::scenarioFromToml(dir, kBusyScene, {"simulation.broadphase=\"uniform_grid\""}), steps);
  for (const char* cell : {"1.5", "40.0"}) {
    const Scenario s =
        test::scenarioFromToml(dir, kBusyScene, {"simulation.broadphase=\"uniform_grid\"", std::string("simulation.cell_size=") + cell});
    EXPECT_EQ(s.broadphaseSettings.cellSize, std::stod(cell));
    expectIdentical(grid, runOnDevice(s, steps), std::string("cell_size ") + cell);
  }
}

// A setting the strategy's device part does not honour is refused by cuda, naming the strategy and
// the setting, and run on the CPU under auto. (A strategy whose CPU part reads skin and whose device
// part declares nothing, as a plugin's could.)
namespace {
class SkinOnlyOnTheCpu final : public Broadphase {
 public:
  static constexpr const char* kSettings[] = {"skin"};
  explicit SkinOnlyOnTheCpu(const BroadphaseSettings&) {}
  std::string name() const override { return "skin_only_on_the_cpu"; }
  void invalidate() override {}
  void findCandidates(const World& world, std::vector<CandidatePair>& pairs) override {
    pairs.clear();
    for (int a = 0; a < world.size(); ++a)
      for (int b = a + 1; b < world.size(); ++b) pairs.push_back({a, b});
  }
};
class NoSettingsOnTheDevice final : public cuda::CudaBroadphase {
 public:
  explicit NoSettingsOnTheDevice(const BroadphaseSettings&) {}
  void enqueue(const cuda::BroadphaseBodies&, const cuda::CandidateSink&, cudaStream_t) override {}
};
}  // namespace

TEST(CudaBroadphase, ASettingTheDevicePartDoesNotHonourIsRefused) {
  GEM_SKIP_WITHOUT_CUDA();
  bool known = false;
  for (const BroadphaseEntry* e : Registry::global().broadphases()) known = known || e->name == "skin_only_on_the_cpu";
  if (!known) {
    Registry::global().addBroadphase(
        BroadphaseEntry{"skin_only_on_the_cpu", "test", "built-in",
                        [](const BroadphaseSettings& s) -> std::unique_ptr<Broadphase> { return std::make_unique<SkinOnlyOnTheCpu>(s); },
                        declaredBroadphaseSettings<SkinOnlyOnTheCpu>()});
    cuda::addCudaBroadphase("skin_only_on_the_cpu", [](const BroadphaseSettings& s) -> std::unique_ptr<cuda::CudaBroadphase> {
      return std::make_unique<NoSettingsOnTheDevice>(s);
    });
  }
  TempDir dir;
  const std::string scene =
      "[simulation]\nsteps = 5\nbroadphase = \"skin_only_on_the_cpu\"\n[broadphase.skin_only_on_the_cpu]\nskin = 1.0\n"
      "[[floes]]\nvertices = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0]]\n";
  try {
    makeStepper(test::scenarioFromToml(dir, scene, {"simulation.backend=\"cuda\"", "simulation.cuda_driver=\"device\""}));
    ADD_FAILURE() << "a setting the device part does not honour was accepted on cuda";
  } catch (const BackendUnsupported& e) {
    EXPECT_NE(std::string(e.what()).find("does not honour the setting skin"), std::string::npos) << e.what();
  }
  EXPECT_EQ(
      makeStepper(test::scenarioFromToml(dir, scene, {"simulation.backend=\"auto\"", "simulation.cuda_driver=\"device\""}))->backend(),
      "cpu");
  // Without the setting it runs on the device.
  const std::string plain =
      "[simulation]\nsteps = 5\nbroadphase = \"skin_only_on_the_cpu\"\n[[floes]]\nvertices = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0]]\n";
  EXPECT_EQ(makeStepper(test::scenarioFromToml(dir, plain, {"simulation.backend=\"cuda\""}))->backend(), "cuda");
}
