// A plugin that declares a record stream of its own and the run-folder file written from it: the
// overlap area of every floe-floe contact, to contact_areas.csv, counted in summary.json as
// "contact_rows" with the statistics of the area as "contact_area_m2". Nothing in GEM names it.
#include <string>

#include <fmt/format.h>

#include "framework/api/event_api.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("contact_areas", "0.1.0")

namespace gem {

struct ContactArea {
  Real time;  // s
  std::int64_t idA, idB;
  Real area;  // m^2
};

struct ContactAreaLog {
  static constexpr int kOrder = event_order::kObservers;
  struct Params {
    Real minArea;  // m^2: smaller overlaps are not logged; required (no default) when the event is on
    RecordStream<ContactArea> rows;
  };
  GEM_HD static void apply(const Params& p, const PairBody& a, const PairBody& b, const PairContact& contact, PairSlot&,
                           const StepContext& ctx, const RecordSink& sink) {
    if (a.kind == BodyKind::Floe && b.kind == BodyKind::Floe && contact.geometry.area >= p.minArea)
      sink.push(p.rows, ContactArea{ctx.time, a.id, b.id, contact.geometry.area});
  }
};

// A parameter without a default is asked for only when the event is on (config.enabled): every
// loaded event is parsed, and a scenario that leaves this one off must not need it.
static ContactAreaLog::Params parseContactAreaLog(EventConfig& config) {
  ContactAreaLog::Params p{};
  p.minArea = config.params.findReal("min_area").value_or(0);
  if (config.enabled && !config.params.has("min_area")) config.params.report("min_area", "is required (no default)");
  p.rows = config.records.open<ContactArea>("contact_areas");
  return p;
}

// Appends to `row`, which GEM hands over empty for every record.
static void writeContactArea(const void* record, std::string& row) {
  const ContactArea& r = *static_cast<const ContactArea*>(record);
  row += fmt::format("{:.6g},{},{},{:.9g}\n", r.time, r.idA, r.idB, r.area);
}

GEM_REGISTER_RECORD_OUTPUT("contact_areas", "contact_areas.csv", "t,id_a,id_b,area_m2", writeContactArea, "contact_rows", "contact_area_m2",
                           [](const void* record) { return static_cast<double>(static_cast<const ContactArea*>(record)->area); });
GEM_REGISTER_PAIR_EVENT(ContactAreaLog, "contact_area_log", "test plugin: the overlap area of floe-floe contacts, to contact_areas.csv",
                        false, parseContactAreaLog);

}  // namespace gem
