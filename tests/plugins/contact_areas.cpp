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
    RecordStream<ContactArea> rows;
  };
  GEM_HD static void apply(const Params& p, const PairBody& a, const PairBody& b, const PairContact& contact, PairSlot&,
                           const StepContext& ctx, const RecordSink& sink) {
    if (a.kind == BodyKind::Floe && b.kind == BodyKind::Floe) sink.push(p.rows, ContactArea{ctx.time, a.id, b.id, contact.geometry.area});
  }
};

static ContactAreaLog::Params parseContactAreaLog(EventConfig& config) { return {config.records.open<ContactArea>("contact_areas")}; }

static void writeContactArea(const void* record, std::string& row) {
  const ContactArea& r = *static_cast<const ContactArea*>(record);
  row = fmt::format("{:.6g},{},{},{:.9g}\n", r.time, r.idA, r.idB, r.area);
}

GEM_REGISTER_RECORD_OUTPUT("contact_areas", "contact_areas.csv", "t,id_a,id_b,area_m2", writeContactArea, "contact_rows", "contact_area_m2",
                           [](const void* record) { return static_cast<double>(static_cast<const ContactArea*>(record)->area); });
GEM_REGISTER_PAIR_EVENT(ContactAreaLog, "contact_area_log", "test plugin: the overlap area of floe-floe contacts, to contact_areas.csv",
                        false, parseContactAreaLog);

}  // namespace gem
