// A rafting-onset detector (a plugin example, docs/plugins.md): a two-body event that changes no
// motion and records each new floe-floe contact where thin ice meets fast enough for one floe to
// ride over the other, the onset of rafting (thin ice rafts, thick ice ridges: Parmerter 1975).
//
//   rafting onset  <=>  contact onset  and  both bodies floes
//                       and  V_c >= min_closing_speed                 [m/s]
//                       and  min(h_a, h_b) <= max_thickness           [m]
//
// V_c is the closing speed of the contact points along the normal (MODEL.md 4). Each onset is a
// row of rafting.csv in the run folder, written by the plugin itself on the host (CPU backend).
#pragma once
#include <cmath>

#include "framework/event_api.hpp"

namespace gem {

class RaftingLog;  // host side, rafting_onset.cpp
void recordRafting(RaftingLog* log, Real time, const PairBody& a, const PairBody& b, Vec2 point, Real closing);

struct RaftingOnset {
  struct Params {
    Real minClosingSpeed;  // m/s (0.05)
    Real maxThickness;     // m (0.5)
    RaftingLog* log;       // host: where onsets go (a plain pointer keeps Params trivially copyable)
  };

  GEM_HD static void apply(const Params& p, const PairBody& a, const PairBody& b, const PairContact& contact,
                           PairSlot&, const StepContext& ctx, const RecordSink&) {
    if (!contact.onset || a.kind != BodyKind::Floe || b.kind != BodyKind::Floe) return;
    const Real closing = closingSpeed(a, b, contact);
    const Real thinner = a.thickness < b.thickness ? a.thickness : b.thickness;
    if (!(closing >= p.minClosingSpeed) || thinner > p.maxThickness) return;
#if !defined(__CUDA_ARCH__)
    recordRafting(p.log, ctx.time, a, b, contact.geometry.point, closing);
#endif
  }
};

}  // namespace gem
