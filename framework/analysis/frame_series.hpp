// The frames of a run's frames.ice as whole scenes: the file stores frame 0 complete and later
// frames only what changed (framework/field/ice_file.hpp); readFrameSeries accumulates those
// changes so that each FrameState lists every body present at that time. Shared by gem view and
// gem movie.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "framework/world/body_kind.hpp"
#include "geometry/vec2.hpp"

namespace gem {

struct FrameBody {
  std::int64_t id;
  BodyKind kind;
  std::vector<Vec2> vertices;  // world coordinates, m
  Vec2 velocity;               // m/s
  Real angularVelocity;        // rad/s
  Real thickness;              // m
  bool piece;                  // appeared after frame 0 (a broken piece)
};

struct FrameState {
  double time;                    // s
  std::vector<FrameBody> bodies;  // every body present in that frame, world coordinates
};

// Reads RUN_DIR/frames.ice, frames in index order, bodies in order of first appearance. Throws
// InputError naming the file when it is missing (saying to run with output.formats including
// "ice"), when readIceFile refuses it, or when a body first appears without coordinates or
// thickness.
std::vector<FrameState> readFrameSeries(const std::filesystem::path& iceFile);

// The same frames, one at a time, to `visit` (the FrameState is reused between calls): a 10^5-floe
// run's whole series would not fit in memory at once.
void forEachFrame(const std::filesystem::path& iceFile, const std::function<void(const FrameState&)>& visit);

}  // namespace gem
