// A request to cut a floe, the record of the stream "breaks": ship_impact pushes one when a floe's
// edge fails in bending (docs/model.md 5), flexural_breaking cuts the floe in the topology phase
// (docs/model.md 6). Both events open the stream by this name; the framework only carries it.
#pragma once
#include <cstdint>

#include "geometry/vec2.hpp"

namespace gem {

struct BreakRequest {
  std::int64_t floeId;
  Vec2 point;       // contact point c
  Vec2 normal;      // from the vessel into the floe
  Real cuspLength;  // m, distance of the cut from c along the normal
};

constexpr const char* kBreakStream = "breaks";

}  // namespace gem
