#include "events/flexural_breaking.hpp"

#include <algorithm>
#include <unordered_set>

#include "framework/api/parallel.hpp"
#include "framework/api/table_reader.hpp"
#include "framework/world/world.hpp"
#include "geometry/split.hpp"

namespace gem {

// Drops the vertex with the smallest turn until the polygon has at most `limit` vertices: a cut adds
// one vertex, and a floe may have at most kMaxFloeVertices.
static void limitVertices(std::vector<Vec2>& v, int limit) {
  while (static_cast<int>(v.size()) > limit) {
    const int n = static_cast<int>(v.size());
    int flattest = 0;
    Real smallest = INFINITY;
    for (int i = 0; i < n; ++i) {
      const Vec2 a = v[(i + n - 1) % n], b = v[i], c = v[(i + 1) % n];
      const Real turn = std::fabs(cross(b - a, c - b));
      if (turn < smallest) smallest = turn, flattest = i;
    }
    v.erase(v.begin() + flattest);
  }
}

std::vector<std::int64_t> FlexuralBreaking::bodiesRead(const Params& p, const StepRecords& records) {
  std::vector<std::int64_t> ids;
  for (const BreakRequest& request : records.rows(p.breaks)) ids.push_back(request.floeId);
  return ids;
}

void FlexuralBreaking::apply(const Params& p, TopologyData& data) {
  const std::vector<BreakRequest> breaks = data.records->rows(p.breaks);
  if (breaks.empty()) return;
  World& world = *data.world;
  // The slots of the requested floes only (a few per step): one pass over the ids, no map of the
  // whole world (at 10^6 floes that map was most of the CUDA backend's time). The requested ids
  // sorted, and most ids rejected by their range before a search of them.
  std::vector<std::int64_t> wanted;
  for (const BreakRequest& request : breaks) wanted.push_back(request.floeId);
  std::sort(wanted.begin(), wanted.end());
  wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
  std::vector<int> wantedSlot(wanted.size(), -1);
  const std::int64_t lowest = wanted.front(), highest = wanted.back();
  for (int i = 0; i < world.size(); ++i) {
    const std::int64_t id = world.id[i];
    if (id < lowest || id > highest) continue;
    const auto it = std::lower_bound(wanted.begin(), wanted.end(), id);
    if (it != wanted.end() && *it == id) wantedSlot[static_cast<size_t>(it - wanted.begin())] = i;
  }
  auto slotOf = [&](std::int64_t id) {
    return wantedSlot[static_cast<size_t>(std::lower_bound(wanted.begin(), wanted.end(), id) - wanted.begin())];
  };

  // One break per floe and step, the first request in the deterministic contact order.
  std::vector<char> remove(world.size(), 0);
  std::unordered_set<int> done;
  std::vector<BodySpec> pieces;
  for (const BreakRequest& request : breaks) {
    const int i = slotOf(request.floeId);
    if (i < 0 || !done.insert(i).second) continue;
    Vec2 polygon[kMaxVertices];
    const int n = world.worldVertices(i, polygon);
    Vec2 left[kMaxClipVertices], right[kMaxClipVertices];
    int nLeft = 0, nRight = 0;
    const Vec2 linePoint = request.point + request.cuspLength * request.normal;
    splitByLine(polygon, n, linePoint, perpLeft(request.normal), left, &nLeft, right, &nRight);
    if (nLeft < 3 || nRight < 3) continue;  // the cut misses the floe

    remove[i] = 1;
    ++data.floesBroken;
    const Vec2 centroid = world.position(i), velocity = world.velocity(i);
    for (auto [v, count] : {std::pair<const Vec2*, int>{left, nLeft}, {right, nRight}}) {
      BodySpec piece;
      piece.kind = BodyKind::Floe;
      piece.vertices.assign(v, v + count);
      limitVertices(piece.vertices, kMaxFloeVertices);
      const Real area = signedArea(piece.vertices.data(), static_cast<int>(piece.vertices.size()));
      if (area < p.minArea) {
        data.rubbleMass += kRhoIce * area * world.thickness[i];
        continue;
      }
      const Vec2 pieceCentroid = areaCentroid(piece.vertices.data(), static_cast<int>(piece.vertices.size()));
      piece.thickness = world.thickness[i];
      piece.velocity = velocity + crossZ(world.omega[i], pieceCentroid - centroid);
      piece.angularVelocity = world.omega[i];
      piece.origin = "break";
      pieces.push_back(std::move(piece));
    }
  }
  if (data.floesBroken == 0) return;
  // On the CPU stepper's pool when it lent one and the world is large (framework/api/parallel.hpp).
  const bool pooled = parallelTasks(world.size(), 4096) > 1;
  world.removeBodies(remove, pooled ? World::TaskRunner(parallelEach) : World::TaskRunner());
  for (const BodySpec& piece : pieces) world.addBody(piece);
  data.changed = true;
}

static FlexuralBreaking::Params parseFlexuralBreaking(EventConfig& config) {
  FlexuralBreaking::Params p{};
  p.minArea = config.params.getRealIn("min_area", 1, 0, 1e8);
  p.breaks = config.records.open<BreakRequest>(kBreakStream);
  return p;
}

GEM_REGISTER_TOPOLOGY_EVENT(FlexuralBreaking, "flexural_breaking",
                            "splits a floe whose edge failed in bending at the cusp length; small pieces leave as rubble (A.100-A.104)",
                            true, parseFlexuralBreaking);

}  // namespace gem
