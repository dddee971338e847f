// Generated pack-ice fields (thesis 6.2.1.1.1, Table 6.1, and the load study of 6.2.2.2):
// random convex floes of a given size distribution and concentration, or a regular array of
// slightly rotated equal hexagons. Both are deterministic for a given seed on every standard
// library, and every floe starts inside the domain, at least minGap from every other (docs/model.md 1:
// bodies never start in contact). Defined in random_convex_field.cpp and hexagon_field.cpp.
#pragma once
#include <cstdint>
#include <vector>

#include "framework/world/world.hpp"

namespace gem {

// The rectangle a field fills ([domain] x = [x0, x1], y = [y0, y1]).
struct Domain {
  Real x0 = 0, x1 = 0, y0 = 0, y1 = 0;
};

// One ice type of a mixed field: the fraction of the domain area it covers and its thickness.
struct ThicknessGroup {
  Real coverage;
  Real thickness;
};

struct RandomFieldSpec {
  Domain domain;
  Real concentration = 0.4;  // total floe area / domain area, 0 < c < 0.9 (reliable to about 0.8)
  int count = 0;             // exact floe count; 0: as many as the size distribution needs
  // Characteristic size sqrt(area), m: lognormal truncated to [sizeMin, sizeMax], fitted so the
  // truncated distribution has this mean and standard deviation (thesis: 6.9 / 3.9, 2 to 20 m).
  // With count given, the distribution is rescaled by a common factor to meet the concentration.
  Real sizeMean = Real(6.9), sizeSd = Real(3.9), sizeMin = 2, sizeMax = 20;
  int minSides = 4, maxSides = 7;  // vertices per floe, within 3..kMaxFloeVertices
  // Largest length / width (sqrt of the principal second moments' ratio): longer cells are cut
  // back. Natural floes are seldom longer than 2 to 3 times their width.
  Real maxAspect = Real(2.5);
  Real thickness = Real(0.7);          // m, when groups is empty
  std::vector<ThicknessGroup> groups;  // coverages sum to concentration; each floe in one group
  Real minGap = Real(0.05);            // m, smallest distance between floes, and to the domain edge
  std::uint64_t seed = 1;
};

struct HexagonFieldSpec {
  Domain domain;
  Real concentration = Real(0.46);
  Real size = Real(10.1);      // sqrt(area) of every hexagon, m (thesis 6.2.1.1.1)
  Real rotationJitterDeg = 3;  // each hexagon rotated uniformly in +-jitter (breaks interlocking)
  Real thickness = Real(0.7);
  Real minGap = Real(0.05);  // m, as in RandomFieldSpec
  // > 0: exactly this many hexagons, an nx by ny array with nx ny = count (the thesis's 456 and 595,
  // Table 6.1), still within 0.01 of the concentration; 0: the count nearest the concentration.
  int count = 0;
  std::uint64_t seed = 1;
};

// Floes (kind Floe, counter-clockwise world vertices, origin "field"), ordered along x.
// Throws InputError naming the scenario key (field.concentration, field.size_min, field.groups,
// ...) for a bad or unreachable spec.
std::vector<BodySpec> generateRandomConvexField(const RandomFieldSpec& spec);
std::vector<BodySpec> generateHexagonField(const HexagonFieldSpec& spec);

}  // namespace gem
