// Nothing changes in behaviour: every golden scene (tests/golden_scenes.hpp) steps on the CPU to the
// very hashes recorded in tests/golden/cpu.txt before the code was reorganised into rooms
// (tests/golden_hash.hpp says what is hashed).
#include <gtest/gtest.h>

#include "tests/golden_scenes.hpp"

namespace gem {
namespace {

class GoldenCpu : public ::testing::TestWithParam<test::GoldenScene> {};

TEST_P(GoldenCpu, StepsToTheRecordedHash) { test::expectGoldenHash(GetParam(), "cpu", "tests/golden/cpu.txt"); }

INSTANTIATE_TEST_SUITE_P(Scenes, GoldenCpu, ::testing::ValuesIn(test::goldenScenes()), [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace gem
