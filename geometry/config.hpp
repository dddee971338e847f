// Project-wide compile-time settings shared by host and device code.
// This is the one place GEM_HD and gem::Real are defined (docs/architecture.md "Writing an event").
#pragma once

#if defined(__CUDACC__)
#define GEM_HD __host__ __device__
#else
#define GEM_HD
#endif

namespace gem {

// The one floating-point type of the engine. Double unless the build asks for float
// (cmake -DGEM_REAL=float); tests state their tolerances for each.
#if defined(GEM_REAL_FLOAT)
using Real = float;
#define GEM_REAL_NAME "float"
#else
using Real = double;
#define GEM_REAL_NAME "double"
#endif

// Floes have 3 to 19 vertices (docs/model.md 1: "fewer than twenty sides"); the vessel and walls
// may use up to kMaxVertices. Every polygon is stored with this fixed stride.
constexpr int kMaxFloeVertices = 19;
constexpr int kMaxVertices = 24;
// The intersection of two convex polygons has at most n + m vertices.
constexpr int kMaxClipVertices = 2 * kMaxVertices;

constexpr Real kPi = Real(3.14159265358979323846);

}  // namespace gem
