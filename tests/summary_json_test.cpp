// summary.json (docs/scenario.md 4.1) is written through nlohmann-json: strings that hold quotes,
// backslashes or control characters still give valid JSON that reads back to the same text, the
// keys keep their documented order, and numbers keep 9 significant digits (non-finite: null).
#include <gtest/gtest.h>

#include <cmath>
#include <iterator>
#include <set>

#include <nlohmann/json.hpp>

#include "framework/analysis/sweep_summary.hpp"
#include "framework/api/registry.hpp"
#include "framework/app/runner.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::TempDir;

TEST(SummaryJson, StringsAreEscapedAndReadBack) {
  RunSummary s;
  s.completed = true;
  s.stopReason = "duration";
  s.steps = 12;
  s.simTime = 1.2;
  s.wallTime = 0.123456789012;
  s.backend = "cpu";
  s.device = "GPU \"H200\" \\\\ slot\t1\n";
  s.shipSpeed = Stats{0.5, 1.0 / 3.0, 2.0, 3};
  s.iceMassInitial = NAN;
  const std::string text = summaryJson(s);
  TempDir dir;
  const auto summary = readSummaryJson(dir.write("summary.json", text));  // throws on invalid JSON
  EXPECT_EQ(summary.at("device"), s.device);
  EXPECT_EQ(summary.at("ship_speed.mean"), "0.333333333");  // 9 significant digits
  EXPECT_EQ(summary.at("ice_mass_initial_kg"), "");         // NaN: null
  EXPECT_EQ(summary.at("wall_time_s"), "0.123456789");
  EXPECT_NE(text.find("  \"steps\": 12,\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  \"ship_speed\": {\"min\": 0.5, \"mean\": 0.333333333, \"max\": 2},\n"), std::string::npos) << text;
  // The documented order: gem_version first, resistance_in_ice_n last.
  EXPECT_EQ(text.rfind("{\n  \"gem_version\": ", 0), 0u) << text;
  EXPECT_LT(text.find("\"device\""), text.find("\"floes_initial\""));
  EXPECT_NE(text.find("\"resistance_in_ice_n\": null\n}\n"), std::string::npos) << text;
}

// The keys GEM writes itself are the ones a plugin's record output may not take (registry.hpp
// kGemSummaryKeys): a key added to summaryJson and not reserved there would let a plugin overwrite it.
TEST(SummaryJson, GemsOwnKeysAreExactlyTheReservedOnes) {
  RunSummary s;
  const nlohmann::json j = nlohmann::json::parse(summaryJson(s));
  std::set<std::string> written, reserved(std::begin(kGemSummaryKeys), std::end(kGemSummaryKeys));
  for (const auto& [key, value] : j.items()) written.insert(key);
  EXPECT_EQ(written, reserved);
}
