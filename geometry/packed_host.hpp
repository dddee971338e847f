// Host-only forms of two kernels the CPU step runs for every moving body and every candidate pair,
// in SSE2's packed doubles (part of plain x86-64): an x and a y, or the two corners of a box, in
// one register. Each gives the result of the scalar form in polygon.hpp bit for bit (the same
// operations in the same order, lane by lane: a difference is the sum with a negated operand, a
// negation is exact, and min and max are the scalar ternaries, NaN and zeros included), so every
// trajectory is the same; the CUDA kernels and other targets (float builds, other processors)
// take the scalar form. Tests: Geometry.PackedFormsGiveTheScalarFormsBits.
#pragma once
#include <cmath>
#include <cstddef>

#include "geometry/polygon.hpp"

#if defined(__SSE2__) && !defined(GEM_REAL_FLOAT) && !defined(__CUDACC__)
#include <emmintrin.h>
#define GEM_PACKED_SSE2 1
#else
#define GEM_PACKED_SSE2 0
#endif

namespace gem {

// boxesOverlap without its short-circuits (a NaN bound counts as overlapping): packed, two
// comparisons of corners, {x0, y0} of one box against {x1, y1} of the other and back. In the CPU
// narrowphase's candidate loop the four scalar comparisons and their flags were a quarter of the
// loop's instructions.
inline bool boxesMeet(const Box& a, const Box& b) {
#if GEM_PACKED_SSE2
  static_assert(offsetof(Box, y0) == sizeof(Real) && offsetof(Box, y1) == 3 * sizeof(Real), "corners {x0, y0} and {x1, y1}");
  const __m128d apart = _mm_or_pd(_mm_cmpgt_pd(_mm_loadu_pd(&a.x0), _mm_loadu_pd(&b.x1)),  // lanes x, y: all ones where apart
                                  _mm_cmpgt_pd(_mm_loadu_pd(&b.x0), _mm_loadu_pd(&a.x1)));
  return _mm_movemask_pd(apart) == 0;
#else
  return !(a.x0 > b.x1) & !(b.x0 > a.x1) & !(a.y0 > b.y1) & !(b.y0 > a.y1);
#endif
}

// toWorld(local, n, position, angle, world) and then boundingBox(world, n), in one pass: each
// world vertex is position + {c x - s y, s x + c y}, as two lanes {c x + (-s) y, s x + c y}, and
// the box's corners are the running minimum and maximum of both lanes at once.
inline Box toWorldWithBox(const Vec2* local, int n, Vec2 position, Real angle, Vec2* world) {
#if GEM_PACKED_SSE2
  static_assert(sizeof(Vec2) == 2 * sizeof(Real) && offsetof(Vec2, y) == sizeof(Real), "a vertex is {x, y}");
  const Real c = std::cos(angle), s = std::sin(angle);
  const __m128d alongX = _mm_set_pd(s, c), alongY = _mm_set_pd(c, -s);  // _mm_set_pd takes the y lane first
  const __m128d origin = _mm_loadu_pd(&position.x);
  __m128d low{}, high{};
  for (int i = 0; i < n; ++i) {
    const __m128d turned = _mm_add_pd(_mm_mul_pd(alongX, _mm_set1_pd(local[i].x)), _mm_mul_pd(alongY, _mm_set1_pd(local[i].y)));
    const __m128d v = _mm_add_pd(origin, turned);
    _mm_storeu_pd(&world[i].x, v);
    low = i == 0 ? v : _mm_min_pd(v, low);  // v < low ? v : low, lane by lane (boundingBox's test)
    high = i == 0 ? v : _mm_max_pd(v, high);
  }
  Box box;
  _mm_storeu_pd(&box.x0, low), _mm_storeu_pd(&box.x1, high);
  return box;
#else
  toWorld(local, n, position, angle, world);
  return boundingBox(world, n);
#endif
}

}  // namespace gem
