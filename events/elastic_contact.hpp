// Elastic contact (docs/model.md 4): a steady elastic stress resisting static pressure, every step that
// two bodies overlap:
//
//   I_el = 0.05 C sigma_max w h dt,   C = min(A_0 K_ice / (w D), 1)                       [N s]
//   h = min(h_1, h_2),  D = min(sqrt(A_1), sqrt(A_2))
//
// w: length of the line of contact (m); A_0: overlap area (m^2); sigma_max = 1 MPa; K_ice = 100.
// The impulse acts at c along n, pushing the bodies apart. The thesis defines the elastic stress for
// ice-ice pairs (3.2.1, L399: "to resist static pressure" between floes; A.1.5, L1622: "the two floes");
// `vessel` says whether vessel-floe pairs take part too (walls always do).
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct ElasticContact {
  static constexpr int kOrder = event_order::kForces;  // docs/plugins.md "Order"
  struct Params {
    Real sigmaMax;   // Pa
    Real stiffness;  // K_ice, dimensionless
    Real factor;     // the 0.05 of the formula
    bool vessel;     // vessel-floe pairs take part
  };

  GEM_HD static void apply(const Params& p, const PairBody& a, const PairBody& b, const PairContact& contact, PairSlot& slot,
                           const StepContext& ctx, const RecordSink&) {
    const Real w = contact.geometry.width;
    if (!(w > 0)) return;
    if (!p.vessel && (a.kind == BodyKind::Vessel || b.kind == BodyKind::Vessel)) return;
    const Real h = a.thickness < b.thickness ? a.thickness : b.thickness;
    const Real d = std::sqrt(a.area < b.area ? a.area : b.area);
    Real coverage = contact.geometry.area * p.stiffness / (w * d);
    coverage = coverage < 1 ? coverage : 1;
    slot.addNormal(p.factor * coverage * p.sigmaMax * w * h * ctx.dt, contact.geometry.normal);
  }
};

}  // namespace gem
