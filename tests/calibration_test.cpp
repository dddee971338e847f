// The calibration impacts (thesis 6.2.2.1, issue 5 item 2): for each of the 32 cases the force GEM
// logs at contact onset agrees with the direct evaluation of docs/model.md 5 within 2 %.
#include <gtest/gtest.h>

#include "framework/app/calibration.hpp"

using namespace gem;

TEST(Calibration, EveryCaseLogsTheDirectlyEvaluatedForceWithinTwoPercent) {
  const Scenario base = loadScenario(std::string(GEM_SOURCE_DIR) + "/scenarios/thesis/calibration.toml");
  const auto cases = calibrationCases(base);
  ASSERT_EQ(cases.size(), 32u);
  int broke = 0, flatApex = 0;
  for (const CalibrationCase& c : cases) {
    SCOPED_TRACE(c.name);
    const CalibrationResult r = runCalibrationCase(base, c);
    ASSERT_TRUE(r.logged);
    EXPECT_NEAR(r.record.force, r.directForce, 0.02 * r.directForce);
    EXPECT_NEAR(r.record.frameAngleDeg, r.frameAngleDeg, 1e-9);  // the right hull edge was found
    EXPECT_NEAR(r.record.apexDeg, r.apexDeg, 1e-6);              // and the right floe vertex
    broke += r.record.broke;
    flatApex += r.apexDeg == 180;
  }
  // The set spans both regimes of the logged force (crushing, and the bending limit) and both apex cases.
  EXPECT_GT(broke, 0);
  EXPECT_LT(broke, 32);
  EXPECT_GT(flatApex, 0);
}
