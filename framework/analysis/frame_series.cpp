// readFrameSeries: frames.ice's per-frame changes accumulated into whole scenes.
#include "framework/analysis/frame_series.hpp"

#include <algorithm>
#include <string>
#include <unordered_map>

#include "framework/api/errors.hpp"
#include "framework/field/ice_file.hpp"

namespace gem {

void forEachFrame(const std::filesystem::path& iceFile, const std::function<void(const FrameState&)>& visit) {
  std::error_code ec;
  if (!std::filesystem::exists(iceFile, ec))
    throw InputError(iceFile.string(), 0, 0,
                     "no such file; run the scenario with output.formats including \"ice\" (the default) to write it");
  std::vector<IceFrame> frames = readIceFile(iceFile);
  // The reader keeps file order; the changes only make sense applied in index order.
  std::stable_sort(frames.begin(), frames.end(), [](const IceFrame& a, const IceFrame& b) { return a.index < b.index; });

  // The live bodies in order of first appearance; `slot` maps an id to its place there.
  FrameState state{0, {}};
  std::vector<FrameBody>& live = state.bodies;
  std::unordered_map<std::int64_t, size_t> slot;
  for (const IceFrame& frame : frames) {
    bool removedAny = false;
    for (const IceObject& o : frame.objects) {
      const auto found = slot.find(o.index);
      if (o.removed) {
        // Removing a body that is not there is harmless: nothing to draw either way.
        if (found != slot.end()) {
          live[found->second].id = -1;  // compacted below, once per frame
          slot.erase(found);
          removedAny = true;
        }
        continue;
      }
      if (found == slot.end()) {
        // A new body (a piece of a split floe, or any body of frame 0) must be written whole.
        if (!o.hasCoordinates || !o.hasThickness)
          throw InputError(iceFile.string(), 0, 0,
                           "frame " + std::to_string(frame.index) + ": object " + std::to_string(o.index) +
                               " appears without <coordinates> and <thickness>");
        FrameBody body{o.index,         o.hasKind ? o.kind : BodyKind::Floe, o.coordinates, o.velocity, o.angularVelocity, o.thickness,
                       frame.index != 0};
        slot.emplace(o.index, live.size());
        live.push_back(std::move(body));
        continue;
      }
      // A known body: only the elements the frame wrote changed.
      FrameBody& body = live[found->second];
      if (o.hasCoordinates) body.vertices = o.coordinates;
      if (o.hasVelocity) {
        body.velocity = o.velocity;
        body.angularVelocity = o.angularVelocity;
      }
      if (o.hasThickness) body.thickness = o.thickness;
      if (o.hasKind) body.kind = o.kind;
    }
    if (removedAny) {
      std::erase_if(live, [](const FrameBody& b) { return b.id < 0; });
      for (size_t k = 0; k < live.size(); ++k) slot[live[k].id] = k;
    }
    state.time = frame.time;
    visit(state);
  }
}

std::vector<FrameState> readFrameSeries(const std::filesystem::path& iceFile) {
  std::vector<FrameState> series;
  forEachFrame(iceFile, [&](const FrameState& state) { series.push_back(state); });
  return series;
}

}  // namespace gem
