// A 2D vector for host and device code: plain aggregate, no constructors beyond the default,
// so arrays of it stay trivially copyable.
#pragma once
#include <cmath>

#include "geometry/config.hpp"

namespace gem {

struct Vec2 {
  Real x, y;
};

GEM_HD inline Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
GEM_HD inline Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
GEM_HD inline Vec2 operator-(Vec2 a) { return {-a.x, -a.y}; }
GEM_HD inline Vec2 operator*(Real s, Vec2 a) { return {s * a.x, s * a.y}; }
GEM_HD inline Vec2 operator*(Vec2 a, Real s) { return {s * a.x, s * a.y}; }
GEM_HD inline Vec2& operator+=(Vec2& a, Vec2 b) {
  a.x += b.x;
  a.y += b.y;
  return a;
}
GEM_HD inline Vec2& operator-=(Vec2& a, Vec2 b) {
  a.x -= b.x;
  a.y -= b.y;
  return a;
}
GEM_HD inline Real dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
// z component of the 3D cross product: positive when b is counter-clockwise of a.
GEM_HD inline Real cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
// omega x r for an angular velocity omega about z.
GEM_HD inline Vec2 crossZ(Real omega, Vec2 r) { return {-omega * r.y, omega * r.x}; }
GEM_HD inline Vec2 perpLeft(Vec2 a) { return {-a.y, a.x}; }
GEM_HD inline Real norm2(Vec2 a) { return dot(a, a); }
GEM_HD inline Real norm(Vec2 a) { return std::sqrt(dot(a, a)); }
GEM_HD inline Vec2 normalized(Vec2 a) {
  Real n = norm(a);
  return n > Real(0) ? Vec2{a.x / n, a.y / n} : Vec2{Real(0), Real(0)};
}
// Rotation by an angle given as its cosine and sine.
GEM_HD inline Vec2 rotate(Vec2 a, Real c, Real s) { return {c * a.x - s * a.y, s * a.x + c * a.y}; }
GEM_HD inline Vec2 rotate(Vec2 a, Real angle) { return rotate(a, std::cos(angle), std::sin(angle)); }

}  // namespace gem
