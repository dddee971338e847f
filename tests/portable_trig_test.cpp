// geometry/portable_trig.hpp: the sine, cosine and arctangent that the host and the device compute
// to the same bits (the flexural break's, so that the resident CUDA kernel cuts floes as the host
// does). Here: they agree with libm within a few ulp over the angles a run meets, in every
// quadrant and at the edges of the reduction; a piece's mass properties by them are addBody's
// within rounding. (Their host-device identity is tested on the GPU: a resident run that breaks
// floes in its kernel steps to the host topology's hashes, tests/cuda/golden_cuda_test.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "framework/world/world.hpp"
#include "geometry/portable_trig.hpp"

namespace gem {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

void expectSinCosNearLibm(double x) {
  Real s = 0, c = 0;
  portableSinCos(x, &s, &c);
  // Values of at most 1: an absolute bound of a few ulp of 1, plus the reduction's part, which
  // grows with x (1e-15 at 1e6 rad, far past any floe's turn).
  const double bound = 4 * kEps + 2e-21 * std::fabs(x);
  EXPECT_NEAR(s, std::sin(x), bound) << "sin " << x;
  EXPECT_NEAR(c, std::cos(x), bound) << "cos " << x;
}

TEST(PortableTrig, SineAndCosineAgreeWithLibmWithinAFewUlp) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> small(-10, 10), large(-1e6, 1e6), tiny(-1e-8, 1e-8);
  for (int k = 0; k < 20000; ++k) {
    expectSinCosNearLibm(small(random));
    expectSinCosNearLibm(large(random));
    expectSinCosNearLibm(tiny(random));
  }
  // The quadrants' edges, and angles a hair on either side of them.
  for (int k = -16; k <= 16; ++k) {
    const double edge = k * (M_PI / 4);
    expectSinCosNearLibm(edge);
    expectSinCosNearLibm(std::nextafter(edge, 1e9));
    expectSinCosNearLibm(std::nextafter(edge, -1e9));
  }
  Real s = 1, c = 0;
  portableSinCos(0, &s, &c);
  EXPECT_EQ(s, 0);
  EXPECT_EQ(c, 1);
}

TEST(PortableTrig, ArctangentAgreesWithLibmInEveryQuadrant) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> value(-1, 1), exponent(-30, 30);
  for (int k = 0; k < 40000; ++k) {
    const double y = value(random) * std::pow(10.0, exponent(random)), x = value(random) * std::pow(10.0, exponent(random));
    const double expected = std::atan2(y, x);
    EXPECT_NEAR(portableAtan2(y, x), expected, 4 * kEps * std::max(std::fabs(expected), 1e-300)) << y << ", " << x;
  }
  // The axes, the diagonals and the reduction's edge at tan(pi/12).
  const double t = std::tan(M_PI / 12);
  for (const auto& [y, x] : std::initializer_list<std::pair<double, double>>{
           {0, 1}, {1, 0}, {0, -1}, {-1, 0}, {1, 1}, {-1, 1}, {1, -1}, {-1, -1}, {t, 1}, {std::nextafter(t, 1.0), 1}, {1, t}, {-t, -1}})
    EXPECT_NEAR(portableAtan2(y, x), std::atan2(y, x), 4 * kEps * std::max(std::fabs(std::atan2(y, x)), 1e-300)) << y << ", " << x;
  EXPECT_EQ(portableAtan2(0, 0), 0);
}

TEST(PortableTrig, APieceHasTheMassPropertiesOfAnyBodyWithinRounding) {
  const BodySpec spec{BodyKind::Floe, {{3, 1}, {9, 2}, {10, 7}, {5, 9}, {2, 5}}, 0.8, {0.5, -0.2}, 0.1, -1, "test"};
  World a, b;
  a.addBody(spec);
  b.addPiece(spec);
  EXPECT_EQ(a.area, b.area);  // no trigonometry in these
  EXPECT_EQ(a.mass, b.mass);
  EXPECT_EQ(a.gyration2, b.gyration2);
  for (size_t k = 0; k < a.localVertices.size(); ++k)
    EXPECT_TRUE(a.localVertices[k].x == b.localVertices[k].x && a.localVertices[k].y == b.localVertices[k].y);
  EXPECT_NEAR(a.principalAngle[0], b.principalAngle[0], 1e-15);
  EXPECT_NEAR(a.gyrationX2[0], b.gyrationX2[0], 1e-14 * a.gyrationX2[0]);
  EXPECT_NEAR(a.gyrationY2[0], b.gyrationY2[0], 1e-14 * a.gyrationY2[0]);
  EXPECT_EQ(b.id[0], 0);
  EXPECT_EQ(b.nextId, 1);
}

}  // namespace
}  // namespace gem
