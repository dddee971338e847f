// The CSV rows' numbers (framework/api/row_text.hpp) are the bytes fmt's "{:.Ng}" and printf's
// "%.Ng" write, which timeseries.csv and impacts.csv were written with before: the files do not
// change, only the time they take.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include <fmt/format.h>

#include "events/ship_impact.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/row_text.hpp"

namespace gem {
namespace {

std::string general(double value, int precision) {
  std::string row;
  appendGeneral(row, value, precision);
  return row;
}

TEST(RowText, GeneralIsPrintfsAndFmtsOnEveryKindOfValue) {
  std::vector<double> values = {0.0,
                                -0.0,
                                1.0,
                                -1.0,
                                0.1,
                                0.7,
                                1e-300,
                                5e-324,
                                std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::min(),
                                999999.5,
                                9999999.5,
                                0.00001234565,
                                123456789012.0,
                                1e21,
                                1e-5,
                                1e-4,
                                99999.95,
                                0.5,
                                2.5,
                                1234567.5};
  // Random bit patterns (every exponent) and random values near the rounding edges of 6 and 9 digits.
  std::mt19937_64 random(20261204);
  for (int k = 0; k < 200000; ++k) {
    std::uint64_t bits = random();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    if (std::isfinite(v)) values.push_back(v);
    const double scale = std::pow(10.0, static_cast<int>(random() % 40) - 20);
    values.push_back(scale * (static_cast<double>(random() % 2000000) + 0.5) / 1000.0);
    values.push_back(-scale * static_cast<double>(random() % 1000000000) / 1e6);
  }
  char printed[64];
  for (int precision : {1, 6, 9, 17})
    for (double v : values) {
      std::snprintf(printed, sizeof printed, "%.*g", precision, v);
      ASSERT_EQ(general(v, precision), printed) << "precision " << precision;
      ASSERT_EQ(general(v, precision), fmt::format("{:.{}g}", v, precision)) << "precision " << precision;
    }
  // Not finite: as fmt writes them.
  for (double v :
       {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()})
    EXPECT_EQ(general(v, 9), fmt::format("{:.9g}", v));
}

TEST(RowText, IntegersAsTheyAre) {
  for (std::int64_t v : {std::int64_t{0}, std::int64_t{-1}, std::int64_t{42}, std::numeric_limits<std::int64_t>::max(),
                         std::numeric_limits<std::int64_t>::min()}) {
    std::string row;
    appendInteger(row, v);
    EXPECT_EQ(row, fmt::format("{}", v));
  }
}

// impacts.csv's row, through the output the event registers, is the row of the format it was
// written with before, on impacts of every kind (an edge that cannot fail writes inf).
TEST(RowText, AnImpactRowIsTheOldFormatsRow) {
  const RecordOutputEntry* output = nullptr;
  for (const RecordOutputEntry* entry : Registry::global().recordOutputs())
    if (entry->stream == kImpactStream) output = entry;
  ASSERT_NE(output, nullptr);
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> any(-1e4, 1e4);
  for (int k = 0; k < 2000; ++k) {
    ImpactRecord r{};
    r.time = static_cast<Real>(std::abs(any(random)));
    r.floeId = static_cast<std::int64_t>(random() % 100000);
    r.floeMass = static_cast<Real>(std::abs(any(random)) * 1e3), r.thickness = static_cast<Real>(std::abs(any(random)) / 1e4);
    r.apexDeg = static_cast<Real>(any(random) / 50), r.frameAngleDeg = static_cast<Real>(any(random) / 100);
    r.point = {static_cast<Real>(any(random)), static_cast<Real>(any(random))};
    r.normal = {static_cast<Real>(any(random) / 1e4), static_cast<Real>(any(random) / 1e4)};
    r.xFromStem = static_cast<Real>(any(random)), r.yFromCenterline = static_cast<Real>(any(random) / 100);
    r.closingSpeed = static_cast<Real>(any(random) / 1e3), r.force = static_cast<Real>(std::abs(any(random)) * 1e3);
    r.forceLimit = k % 3 == 0 ? std::numeric_limits<Real>::infinity() : static_cast<Real>(std::abs(any(random)) * 1e4);
    r.broke = k % 5 == 0;
    const std::string old = fmt::format(
        "{:.6g},{},{:.9g},{:.6g},{:.6g},{:.6g},{:.9g},{:.9g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.9g},{},{}\n", r.time, r.floeId,
        r.floeMass, r.thickness, r.apexDeg, r.frameAngleDeg, r.point.x, r.point.y, r.normal.x, r.normal.y, r.xFromStem, r.yFromCenterline,
        r.closingSpeed, r.force, std::isfinite(r.forceLimit) ? fmt::format("{:.9g}", r.forceLimit) : "inf", r.broke ? 1 : 0);
    std::string row = "left over from another row";
    output->writeRow(&r, row);
    ASSERT_EQ(row, old);
  }
}

}  // namespace
}  // namespace gem
