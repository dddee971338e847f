// EXPERIMENT (issue 15), not for main: the GEM-free WHILE-graph probe run inside gem_cuda_tests.
#include <gtest/gtest.h>
#include <cstdlib>
int whileGraphProbe(int argc, char** argv);
TEST(MemcheckProbe, WhileGraphInTheTestProcess) {
  const char* mode = std::getenv("GEM_MEMCHECK_PROBE");
  if (!mode) GTEST_SKIP() << "GEM_MEMCHECK_PROBE not set";
  char a0[] = "probe", a1[] = "8";
  char* argv[] = {a0, a1, const_cast<char*>(mode), nullptr};
  EXPECT_EQ(whileGraphProbe(3, argv), 0);
}
