// rafting_onset: parameters, the host-side writer of rafting.csv, registration.
#include "rafting_onset.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "framework/api/log_channel.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("rafting_onset", "1.0.0")

namespace gem {

// One run's rafting.csv. Opened at the first onset, so a run without rafting (or gem check)
// writes nothing.
class RaftingLog {
 public:
  explicit RaftingLog(std::filesystem::path file) : m_file(std::move(file)) {}
  ~RaftingLog() {
    if (m_out) std::fclose(m_out);
  }
  void write(const LogRecord& r) {
    if (!m_out) {
      std::filesystem::create_directories(m_file.parent_path());
      m_out = std::fopen(m_file.string().c_str(), "w");
      if (!m_out) return;
      std::fprintf(m_out, "t,floe_a,floe_b,x,y,vc,thickness\n");
    }
    std::fprintf(m_out, "%.6g,%lld,%lld,%.6g,%.6g,%.6g,%.6g\n", double(r.time), static_cast<long long>(r.idA),
                 static_cast<long long>(r.idB), double(r.value[0]), double(r.value[1]), double(r.value[2]), double(r.value[3]));
    std::fflush(m_out);  // onsets are rare: keep the file whole if the run stops
  }

 private:
  std::filesystem::path m_file;
  std::FILE* m_out = nullptr;
};

static RaftingOnset::Params parseRaftingOnset(EventConfig& config) {
  TableReader& t = config.params;
  RaftingOnset::Params p{};
  p.minClosingSpeed = t.getNonNegative("min_closing_speed", Real(0.05));
  p.maxThickness = t.getPositive("max_thickness", Real(0.5));
  // The channel's writer lives as long as the process (and the library, which is never unloaded).
  auto log = std::make_shared<RaftingLog>(config.scenario.output.dir / t.getPath("file", "rafting.csv"));
  p.logChannel = openLogChannel([log](const LogRecord& r) { log->write(r); });
  return p;
}

GEM_REGISTER_PAIR_EVENT(RaftingOnset, "rafting_onset",
                        "records floe-floe contact onsets of thin ice closing fast (rafting onset) to rafting.csv", false,
                        parseRaftingOnset);

}  // namespace gem
