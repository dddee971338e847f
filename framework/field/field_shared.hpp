// What the random and the hexagon field generators share: double-precision points, the seeded
// random numbers (the draw sequence fixes every field), input checks and the floe output.
// Internal to framework/field/; the public API is field_generator.hpp.
//
// The generator computes in double whatever gem::Real is, and with no fused multiply-add, so
// that the same seed gives the same field whatever the target flags (-march with FMA otherwise
// changes the rounding; GCC 12 fuses a*b - c*d pairs through the vectorizer even with fp-contract
// off, hence the second switch). CMakeLists.txt therefore compiles every .cpp of framework/field/
// with -ffp-contract=off -fno-tree-vectorize.
#pragma once
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <utility>
#include <vector>

#include "framework/api/errors.hpp"
#include "framework/field/field_generator.hpp"

namespace gem::field_detail {

// In double, not gem::Real: the field must not depend on the engine's precision.
constexpr double kPiD = 3.14159265358979323846;
constexpr double kTwoPi = 2 * kPiD;

struct P2 {
  double x, y;
};
inline P2 operator+(P2 a, P2 b) { return {a.x + b.x, a.y + b.y}; }
inline P2 operator-(P2 a, P2 b) { return {a.x - b.x, a.y - b.y}; }
inline P2 operator*(double s, P2 a) { return {s * a.x, s * a.y}; }
inline double dot(P2 a, P2 b) { return a.x * b.x + a.y * b.y; }
inline double cross(P2 a, P2 b) { return a.x * b.y - a.y * b.x; }
inline double length(P2 a) { return std::sqrt(dot(a, a)); }
inline P2 rotated(P2 a, double c, double s) { return {c * a.x - s * a.y, s * a.x + c * a.y}; }

// ---------------------------------------------------------------------------------------------
// Random numbers. std::mt19937_64's output is fixed by the standard; the standard distributions
// are not, so the few we need are built here from its raw bits.
class Random {
 public:
  explicit Random(std::uint64_t seed) : m_engine(seed) {}
  double uniform() { return static_cast<double>(m_engine() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  std::uint64_t below(std::uint64_t n) {  // [0, n), unbiased by rejection
    const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % n;
    std::uint64_t r;
    do r = m_engine();
    while (r >= limit);
    return r % n;
  }
  template <class T>
  void shuffle(std::vector<T>& v) {  // Fisher-Yates
    for (size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[below(i)]);
  }

 private:
  std::mt19937_64 m_engine;
};

// ---------------------------------------------------------------------------------------------
// Input checks: messages name the scenario key; the scenario loader adds the file.
template <class... Args>
[[noreturn]] void fail(const Args&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  throw InputError(out.str());
}

void checkDomain(const Domain& d);
void checkCommon(Real concentration, Real thickness, Real minGap, bool thicknessUsed);

// A floe (kind Floe, origin "field") of the n counter-clockwise vertices v, rounded to Real.
BodySpec makeFloe(const P2* v, int n, Real thickness);
// Along x, then y, of the centroids (computed before rounding, so a float build orders alike):
// ids then grow along the vessel's track.
void sortAlongX(std::vector<BodySpec>& floes, const std::vector<P2>& centre);

}  // namespace gem::field_detail
