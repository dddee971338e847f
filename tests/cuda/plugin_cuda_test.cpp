// A plugin's event on the CUDA backend (docs/plugins.md "On the GPU"): the shear_current example,
// built by tests/CMakeLists.txt with its .cu (gem_add_plugin's CUDA_SOURCES), registers its device
// driver under its own origin; CudaStepper pairs the plugin's event with that driver only, and
// the run matches the CPU's. The device runs skip, visibly, where no CUDA device exists.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "framework/api/cuda_events.hpp"
#include "framework/cuda/cuda_stepper.hpp"
#include "framework/app/plugin_loader.hpp"
#include "framework/api/registry.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "../test_support.hpp"
#include "cuda_test_support.hpp"

using namespace gem;
using gem::test::TempDir;

namespace {

std::string shearPlugin() { return test::cudaTestPlugin("libshear_current.so"); }

// The example's three floes across the shear current (plugins/shear_current/scenario.toml), two of
// them set moving into each other, so that contacts and the built-in pair events run too.
std::string shearScene(const std::string& plugin, int steps) {
  return "[simulation]\ndt = 0.1\nsteps = " + std::to_string(steps) +
         "\nbroadphase = \"all_pairs\"\n"
         "[[floes]]\nvertices = [[-5.0, -45.0], [5.0, -45.0], [5.0, -35.0], [-5.0, -35.0]]\nthickness = 0.5\n"
         "[[floes]]\nvertices = [[-5.0, -5.0], [5.0, -5.0], [5.0, 5.0], [-5.0, 5.0]]\nthickness = 0.5\nvelocity = [1.0, 0.0]\n"
         "[[floes]]\nvertices = [[5.5, -3.0], [15.5, -3.0], [15.5, 7.0], [5.5, 7.0]]\nthickness = 0.4\nvelocity = [-1.0, 0.0]\n"
         "[[floes]]\nvertices = [[-5.0, 35.0], [5.0, 35.0], [5.0, 45.0], [-5.0, 45.0]]\nthickness = 0.5\n"
         "[events.shear_current]\nu0 = 0.2\nshear = 0.01\n"
         "[[plugins]]\npath = \"" +
         plugin + "\"\n";
}

std::vector<Real> state(Stepper& sim) {
  const World& w = sim.hostWorld();
  std::vector<Real> v;
  for (int i = 0; i < w.size(); ++i) v.insert(v.end(), {w.x[i], w.y[i], w.angle[i], w.vx[i], w.vy[i], w.omega[i]});
  return v;
}

// Largest difference per quantity, relative to that quantity's largest magnitude in `a`.
double relativeDifference(const std::vector<Real>& a, const std::vector<Real>& b) {
  double worst = 0;
  for (size_t q = 0; q < 6; ++q) {
    double scale = 1e-30, diff = 0;
    for (size_t k = q; k < a.size(); k += 6) {
      scale = std::max(scale, std::fabs(a[k]));
      diff = std::max(diff, std::fabs(a[k] - b[k]));
    }
    worst = std::max(worst, diff / scale);
  }
  return worst;
}

}  // namespace

// No device needed: loading registers the plugin's driver under the plugin's origin only, never as
// a built-in of that name.
TEST(CudaPlugin, RegistersItsDeviceDriverUnderItsOwnOrigin) {
  const LoadedPlugin& p = loadPlugin(shearPlugin());
  const EventEntry* entry = Registry::global().findEvent("shear_current");
  ASSERT_NE(entry, nullptr);
  EXPECT_EQ(entry->origin, p.origin);
  EXPECT_NE(cuda::findCudaEvent("shear_current", p.origin), nullptr);
  EXPECT_EQ(cuda::findCudaEvent("shear_current"), nullptr);  // not a built-in's
  EXPECT_NE(cuda::findCudaEvent("drag"), nullptr);           // the built-ins are untouched
}

TEST(CudaPlugin, ShearCurrentOnCudaMatchesTheCpu) {
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  const Scenario s = test::scenarioFromToml(dir, shearScene(shearPlugin(), 20));
  CpuStepper cpu(s);
  CudaStepper gpu(s);
  int contacts = 0;
  for (int k = 0; k < 20; ++k) {
    cpu.step();
    gpu.step();
    ASSERT_EQ(cpu.contactCount(), gpu.contactCount()) << "step " << k;
    contacts += cpu.contactCount();
  }
  const std::vector<Real> a = state(cpu), b = state(gpu);
  ASSERT_EQ(a.size(), b.size());
  const double diff = relativeDifference(a, b);
  std::printf("shear_current plugin, 20 steps: %zu bodies, %d contacts, max relative difference CUDA vs CPU %.3g\n", a.size() / 6, contacts,
              diff);
  EXPECT_LT(diff, 1e-12);
  EXPECT_GT(contacts, 0);
  // The plugin's event really ran on the device: the floe at y = -40 drifts back (U < 0), the one
  // at y = 40 forward, each towards the water at its own y.
  const World& w = gpu.hostWorld();
  for (int i = 0; i < w.size(); ++i) {
    if (w.y[i] < -30) {
      EXPECT_LT(w.vx[i], 0);
    }
    if (w.y[i] > 30) {
      EXPECT_GT(w.vx[i], 0);
    }
  }
}

// `gem run --backend cuda` end to end with the plugin named in the scenario: it runs on the device
// (no fallback to the CPU) and says so in summary.json.
TEST(CudaPlugin, GemRunWithThePluginOnBackendCuda) {
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  const std::filesystem::path scene = dir.write("shear.toml", shearScene(shearPlugin(), 50)), log = dir.path() / "log.txt";
  ASSERT_EQ(0, test::runGem("run " + scene.string() + " --backend cuda --quiet --out " + (dir.path() / "run").string(), log))
      << test::readFile(log);
  const std::string summary = test::readFile(dir.path() / "run" / "summary.json");
  EXPECT_NE(summary.find("\"backend\": \"cuda\""), std::string::npos) << summary;
}

// rafting_onset on the device: its LogRecords come back with the step's records and are written
// on the host in contact order, so rafting.csv lists the same onsets (time, floe pair) in the same
// order as the CPU run's, over a busy scene where floes collide all the time.
TEST(CudaPlugin, RaftingOnsetLogsTheSameRowsOnCudaAsOnTheCpu) {
  GEM_SKIP_WITHOUT_CUDA();
  const std::string plugin = test::cudaTestPlugin("librafting_onset.so");
  TempDir dir;
  const std::filesystem::path scene =
      dir.write("rafting.toml",
                "[simulation]\ndt = 0.1\nsteps = 60\nseed = 3\n[domain]\nx = [0.0, 120.0]\ny = [-40.0, 40.0]\nwalls = true\n"
                "[field]\nkind = \"random_convex\"\nconcentration = 0.45\nsize_mean = 5.0\nsize_sd = 2.0\nsize_min = 2.0\nsize_max = 12.0\n"
                "thickness = 0.4\n[vessel]\nposition = [-56.0, 0.0]\nbollard_thrust = 740e3\nopen_water_speed = 6.5\n"
                "[events.rafting_onset]\nmin_closing_speed = 0.0\nmax_thickness = 1.0\n"
                "[output]\nframe_every = 0\n[[plugins]]\npath = \"" +
                    plugin + "\"\n");
  auto rows = [&](const std::string& backend) {
    const std::filesystem::path out = dir.path() / backend, log = dir.path() / (backend + ".log");
    EXPECT_EQ(0, test::runGem("run " + scene.string() + " --backend " + backend + " --quiet --out " + out.string(), log))
        << test::readFile(log);
    // t, floe_a, floe_b of each row: the values after them agree to rounding, not bit for bit.
    std::vector<std::string> keys;
    std::istringstream in(test::readFile(out / "rafting.csv"));
    for (std::string line; std::getline(in, line);) {
      const std::vector<std::string> cells = test::csvCells(line);
      keys.push_back(cells.at(0) + "," + cells.at(1) + "," + cells.at(2));
    }
    return keys;
  };
  const std::vector<std::string> cpu = rows("cpu"), gpu = rows("cuda");
  EXPECT_GT(cpu.size(), 5u);  // the header and several onsets
  EXPECT_EQ(cpu, gpu);
}
