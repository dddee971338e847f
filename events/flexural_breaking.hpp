// Flexural breaking (docs/model.md 6, thesis A.100 to A.104). When ship_impact finds that a floe edge
// fails in bending (F_n > F_lim), the floe is cut (choice) by the straight line perpendicular to
// the contact normal n at the cusp length into the floe:
//
//   L_cusp = 1.2 min(20 h / K_v, L_c),   L_c = |c - floe centroid|                        [m]
//
// Both pieces are convex, keep the thickness, get their own mass properties and move rigidly with
// the parent: v_i = v + omega x (centroid_i - centroid), omega_i = omega. A piece smaller than
// min_area leaves the simulation as rubble; its mass is counted in the summary (rubble_mass_kg).
// A floe is broken at most once per step; a cut that misses the floe leaves it whole.
// The cut itself is events/flexural_cut.hpp (host and device): this event runs it on the host
// (CPU stepper, the device-wide CUDA driver); the resident CUDA driver runs it in its kernel.
#pragma once
#include <cstdint>
#include <vector>

#include "events/break_request.hpp"
#include "framework/api/registry.hpp"

namespace gem {

struct FlexuralBreaking {
  struct Params {
    Real minArea;                       // m^2: smaller pieces become rubble (1)
    RecordStream<BreakRequest> breaks;  // what ship_impact asks to cut
  };
  static void apply(const Params& p, TopologyData& data);
  // The topology contract (api/registry.hpp TopologyData): the streams whose rows call for this
  // phase, and the bodies a step's rows name, the only ones apply() reads.
  static std::vector<int> streamsRead(const Params& p) { return {p.breaks.index}; }
  static std::vector<std::int64_t> bodiesRead(const Params& p, const StepRecords& records);
};

}  // namespace gem
