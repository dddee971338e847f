// A plugin event that opens ship_impact's stream "impacts" with records of its own type: refused as
// bad input naming both events and the plugin (it was "gem: failed", exit 1, naming neither), even
// with the event off, since every event's table is read (tests/plugin_test.cpp).
#include "framework/api/event_api.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("reuses_impacts_stream", "0.0.1")

namespace gem {

struct TinyRecord {
  float value;
};

struct ReusesImpactsStream {
  struct Params {
    RecordStream<TinyRecord> rows;
  };
  static void apply(const Params&, const SoloBody&, VelocityChange&, const StepContext&) {}
};

static ReusesImpactsStream::Params parseReusesImpactsStream(EventConfig& config) { return {config.records.open<TinyRecord>("impacts")}; }

GEM_REGISTER_SOLO_EVENT(ReusesImpactsStream, "reuses_impacts_stream", "test plugin: opens the impacts stream with another record type",
                        false, parseReusesImpactsStream);

}  // namespace gem
