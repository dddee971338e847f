#include "events/flexural_breaking.hpp"

#include <algorithm>
#include <unordered_set>

#include "events/flexural_cut.hpp"
#include "framework/api/parallel.hpp"
#include "framework/api/table_reader.hpp"
#include "framework/world/world.hpp"

namespace gem {

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
    FloePiece cut[2];
    if (!cutFloe(world.local(i), world.vertexCount[i], world.position(i), world.angle[i], world.velocity(i), world.omega[i], request,
                 p.minArea, cut))
      continue;  // the cut misses

    remove[i] = 1;
    ++data.floesBroken;
    for (const FloePiece& piece : cut) {
      if (piece.rubble) {
        data.rubbleMass += kRhoIce * piece.area * world.thickness[i];
        continue;
      }
      BodySpec spec;
      spec.kind = BodyKind::Floe;
      spec.vertices.assign(piece.vertices, piece.vertices + piece.count);
      spec.thickness = world.thickness[i];
      spec.velocity = piece.velocity;
      spec.angularVelocity = world.omega[i];
      spec.origin = "break";
      pieces.push_back(std::move(spec));
    }
  }
  if (data.floesBroken == 0) return;
  // On the CPU stepper's pool when it lent one and the world is large (framework/api/parallel.hpp).
  const bool pooled = parallelTasks(world.size(), 4096) > 1;
  world.removeBodies(remove, pooled ? World::TaskRunner(parallelEach) : World::TaskRunner());
  for (const BodySpec& piece : pieces) world.addPiece(piece);
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
