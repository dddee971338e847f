// packFrames: shapes once, poses per frame (view_pack.hpp).
#include "framework/analysis/view_pack.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "framework/analysis/frame_series.hpp"

namespace gem {

namespace {

struct Centroid {
  double x = 0, y = 0, area = 0;
};

// The polygon's area centroid; the vertex mean for a degenerate one (nothing to weigh).
Centroid centroidOf(const std::vector<Vec2>& v) {
  double a = 0, cx = 0, cy = 0;
  const size_t n = v.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2 p = v[i], q = v[(i + 1) % n];
    const double cross = double(p.x) * q.y - double(q.x) * p.y;
    a += cross;
    cx += (double(p.x) + q.x) * cross;
    cy += (double(p.y) + q.y) * cross;
  }
  if (std::abs(a) < 1e-12) {
    Centroid c;
    for (const Vec2& p : v) c.x += p.x / double(n), c.y += p.y / double(n);
    return c;
  }
  return {cx / (3 * a), cy / (3 * a), std::abs(a) / 2};
}

// What packing remembers of a live body: its current shape and that shape's vertices.
struct Track {
  std::uint32_t shape;
  std::vector<double> local;
  double thickness;
};

}  // namespace

std::uint64_t ViewPack::payloadBytes() const {
  std::uint64_t bytes = 0;
  for (const ViewShape& s : shapes) bytes += 24 + 4 * s.local.size();
  for (const auto& l : lists) bytes += 4 * l.size();
  for (const ViewFrame& f : frames) bytes += 4 * f.poses.size();
  return bytes;
}

ViewPack packFrames(const std::filesystem::path& iceFile, int every) {
  ViewPack pack;
  pack.every = std::max(every, 1);
  std::unordered_map<std::int64_t, Track> tracks;
  std::vector<float> floeSpeeds;  // a sample, for the colour scale
  double minX = std::numeric_limits<double>::infinity(), minY = minX, maxX = -minX, maxY = -minX;
  double minT = minX, maxT = -minX;
  long visited = 0;
  ViewFrame last;
  bool lastKept = false;

  forEachFrame(iceFile, [&](const FrameState& state) {
    ViewFrame frame;
    frame.source = visited;
    const bool keep = visited++ % pack.every == 0;
    frame.time = state.time;
    frame.poses.reserve(4 * state.bodies.size());
    std::vector<std::uint32_t> list;
    list.reserve(state.bodies.size());
    for (const FrameBody& b : state.bodies) {
      const Centroid c = centroidOf(b.vertices);
      auto it = tracks.find(b.id);
      double angle = 0;
      bool fresh = it == tracks.end() || it->second.local.size() != 2 * b.vertices.size() || it->second.thickness != b.thickness;
      if (!fresh) {
        // The rotation that best maps the shape onto the polygon (2D Procrustes): vertex 0 alone
        // would do for a rigid body, but the fit also tells how far from rigid the motion was.
        const std::vector<double>& l = it->second.local;
        double dot = 0, cross = 0, radius = 0;
        for (size_t k = 0; k < b.vertices.size(); ++k) {
          const double rx = b.vertices[k].x - c.x, ry = b.vertices[k].y - c.y;
          dot += l[2 * k] * rx + l[2 * k + 1] * ry;
          cross += l[2 * k] * ry - l[2 * k + 1] * rx;
          radius = std::max(radius, std::hypot(l[2 * k], l[2 * k + 1]));
        }
        angle = std::atan2(cross, dot);
        const double cs = std::cos(angle), sn = std::sin(angle);
        double misfit = 0;
        for (size_t k = 0; k < b.vertices.size(); ++k) {
          const double px = c.x + cs * l[2 * k] - sn * l[2 * k + 1], py = c.y + sn * l[2 * k] + cs * l[2 * k + 1];
          misfit = std::max(misfit, std::hypot(px - b.vertices[k].x, py - b.vertices[k].y));
        }
        // A centimetre on a 10 m floe is below a pixel at any useful zoom.
        fresh = misfit > 1e-3 * radius + 1e-6;
      }
      if (fresh) {
        ViewShape shape;
        shape.id = b.id;
        shape.kind = b.kind;
        shape.piece = b.piece;
        shape.thickness = float(b.thickness);
        shape.area = float(c.area);
        Track track{std::uint32_t(pack.shapes.size()), {}, b.thickness};
        for (const Vec2& p : b.vertices) {
          track.local.push_back(p.x - c.x);
          track.local.push_back(p.y - c.y);
          shape.local.push_back(float(p.x - c.x));
          shape.local.push_back(float(p.y - c.y));
          shape.radius = std::max(shape.radius, float(std::hypot(p.x - c.x, p.y - c.y)));
        }
        pack.shapes.push_back(std::move(shape));
        tracks[b.id] = std::move(track);
        angle = 0;
      }
      const double speed = std::hypot(b.velocity.x, b.velocity.y);
      list.push_back(tracks[b.id].shape);
      frame.poses.insert(frame.poses.end(), {float(c.x), float(c.y), float(angle), float(speed)});
      if (b.kind == BodyKind::Wall) continue;  // walls are long: they would set the bounds
      for (const Vec2& p : b.vertices) minX = std::min(minX, double(p.x)), maxX = std::max(maxX, double(p.x));
      for (const Vec2& p : b.vertices) minY = std::min(minY, double(p.y)), maxY = std::max(maxY, double(p.y));
      if (b.kind == BodyKind::Floe) {
        // Floes at rest would pull the scale to zero in a large still field: only moving ones count.
        if (speed > 1e-3 && floeSpeeds.size() < 4000000) floeSpeeds.push_back(float(speed));
        minT = std::min(minT, double(b.thickness)), maxT = std::max(maxT, double(b.thickness));
      }
    }
    // Consecutive frames with the same bodies share one list: most frames of a run have no break.
    if (pack.lists.empty() || pack.lists.back() != list) pack.lists.push_back(std::move(list));
    frame.list = std::uint32_t(pack.lists.size() - 1);
    if (keep) {
      pack.frames.push_back(std::move(frame));
      lastKept = true;
    } else {
      last = std::move(frame);
      lastKept = false;
    }
  });
  if (!lastKept) pack.frames.push_back(std::move(last));

  if (minX > maxX) minX = -1, maxX = 1, minY = -1, maxY = 1;  // walls only, or nothing
  pack.minX = minX, pack.maxX = maxX, pack.minY = minY, pack.maxY = maxY;
  if (minT <= maxT) pack.minThickness = minT, pack.maxThickness = maxT;
  if (!floeSpeeds.empty()) {
    const size_t k = floeSpeeds.size() * 99 / 100;
    std::nth_element(floeSpeeds.begin(), floeSpeeds.begin() + long(k), floeSpeeds.end());
    pack.speedScale = std::max(double(floeSpeeds[k]), 1e-2);
  }
  return pack;
}

void thinFrames(ViewPack& pack, int every) {
  if (every <= 1 || pack.frames.empty()) return;
  std::vector<ViewFrame> kept;
  for (size_t k = 0; k < pack.frames.size(); ++k)
    if (k % size_t(every) == 0 || k + 1 == pack.frames.size()) kept.push_back(std::move(pack.frames[k]));
  pack.frames = std::move(kept);
  pack.every *= every;
}

}  // namespace gem
