// The frames of a run packed for gem view's page: each body's shape stored once (vertices about
// its centroid at first appearance) and per frame only its pose and speed, so a 10^5-floe frame
// costs 16 bytes a body. A body gets a new shape when its vertex count or thickness changes, or
// when its polygon no longer matches a rigid motion of its shape (deformation, re-meshing).
#pragma once
#include <cstdint>
#include <filesystem>
#include <vector>

#include "framework/world/body_kind.hpp"

namespace gem {

struct ViewShape {
  std::int64_t id = -1;
  BodyKind kind = BodyKind::Floe;
  bool piece = false;        // appeared after frame 0
  float thickness = 0;       // m
  float area = 0;            // m^2
  float radius = 0;          // m, largest vertex distance from the centroid (culling, hover)
  std::vector<float> local;  // x0 y0 x1 y1 ... about the centroid, at angle 0
};

struct ViewFrame {
  double time = 0;
  long source = 0;           // its place among frames.ice's frames (they differ once thinned)
  std::uint32_t list = 0;    // index into ViewPack::lists: the shapes present, in order
  std::vector<float> poses;  // x, y, angle, speed for each entry of the list
};

struct ViewPack {
  std::vector<ViewShape> shapes;
  std::vector<std::vector<std::uint32_t>> lists;  // shared by consecutive frames with the same bodies
  std::vector<ViewFrame> frames;
  int every = 1;                                  // frames kept: every N-th of the file's, and the last
  double minX = 0, minY = 0, maxX = 0, maxY = 0;  // bounds of every body over the frames kept
  double speedScale = 1;                          // m/s: the 99th percentile of moving floes' speeds
  double minThickness = 0, maxThickness = 0;      // m, over the floes
  std::uint64_t payloadBytes() const;             // the binary data the page will embed
};

// Reads iceFile through forEachFrame and packs every `every`-th frame and the last.
ViewPack packFrames(const std::filesystem::path& iceFile, int every);

// Keeps every `every`-th frame of the pack and its last (a thinning decided after packing).
void thinFrames(ViewPack& pack, int every);

}  // namespace gem
