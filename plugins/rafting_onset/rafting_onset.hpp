// A rafting-onset detector (a plugin example, docs/plugins.md): a two-body event that changes no
// motion and records each new floe-floe contact where thin ice meets fast enough for one floe to
// ride over the other, the onset of rafting (thin ice rafts, thick ice ridges: Parmerter 1975).
//
//   rafting onset  <=>  contact onset  and  both bodies floes
//                       and  V_c >= min_closing_speed                 [m/s]
//                       and  min(h_a, h_b) <= max_thickness           [m]
//
// V_c is the closing speed of the contact points along the normal (docs/model.md 4). Each onset is a
// LogRecord on the event's log channel (framework/api/log_channel.hpp): apply() is the same code on
// the CPU and the GPU, and the host writes each record as a row of rafting.csv in the run folder,
// in contact order, after the step.
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct RaftingOnset {
  struct Params {
    Real minClosingSpeed;  // m/s (0.05)
    Real maxThickness;     // m (0.5)
    int logChannel;        // where onsets go: this run's rafting.csv
  };

  GEM_HD static void apply(const Params& p, const PairBody& a, const PairBody& b, const PairContact& contact, PairSlot&,
                           const StepContext& ctx, const RecordSink& sink) {
    if (!contact.onset || a.kind != BodyKind::Floe || b.kind != BodyKind::Floe) return;
    const Real closing = closingSpeed(a, b, contact);
    const Real thinner = a.thickness < b.thickness ? a.thickness : b.thickness;
    if (!(closing >= p.minClosingSpeed) || thinner > p.maxThickness) return;
    sink.push(LogRecord{p.logChannel, ctx.time, a.id, b.id, {contact.geometry.point.x, contact.geometry.point.y, closing, thinner, 0, 0}});
  }
};

}  // namespace gem
