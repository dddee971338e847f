// rafting_onset: parameters, the host-side log (rafting.csv in the run folder), registration.
#include "rafting_onset.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "framework/plugin_api.hpp"
#include "framework/registry.hpp"
#include "framework/scenario.hpp"
#include "framework/table_reader.hpp"

GEM_PLUGIN("rafting_onset", "1.0.0")

namespace gem {

// One run's log. Opened at the first onset, so a run without rafting (or gem check) writes nothing.
class RaftingLog {
 public:
  explicit RaftingLog(std::filesystem::path file) : m_file(std::move(file)) {}
  ~RaftingLog() {
    if (m_out) std::fclose(m_out);
  }
  void record(Real time, const PairBody& a, const PairBody& b, Vec2 point, Real closing) {
    if (!m_out) {
      std::filesystem::create_directories(m_file.parent_path());
      m_out = std::fopen(m_file.string().c_str(), "w");
      if (!m_out) return;
      std::fprintf(m_out, "t,floe_a,floe_b,x,y,vc,thickness\n");
    }
    std::fprintf(m_out, "%.6g,%lld,%lld,%.6g,%.6g,%.6g,%.6g\n", double(time), static_cast<long long>(a.id),
                 static_cast<long long>(b.id), double(point.x), double(point.y), double(closing),
                 double(a.thickness < b.thickness ? a.thickness : b.thickness));
    std::fflush(m_out);  // onsets are rare: keep the file whole if the run stops
  }

 private:
  std::filesystem::path m_file;
  std::FILE* m_out = nullptr;
};

void recordRafting(RaftingLog* log, Real time, const PairBody& a, const PairBody& b, Vec2 point, Real closing) {
  if (log) log->record(time, a, b, point, closing);
}

// Every run's log lives as long as the process (and the library, which is never unloaded).
static RaftingLog* newLog(const std::filesystem::path& file) {
  static std::mutex mutex;  // sweeps parse their cases on several threads
  static std::vector<std::unique_ptr<RaftingLog>> logs;
  std::lock_guard lock(mutex);
  logs.push_back(std::make_unique<RaftingLog>(file));
  return logs.back().get();
}

static RaftingOnset::Params parseRaftingOnset(EventConfig& config) {
  TableReader& t = config.params;
  RaftingOnset::Params p{};
  p.minClosingSpeed = t.getNonNegative("min_closing_speed", Real(0.05));
  p.maxThickness = t.getPositive("max_thickness", Real(0.5));
  p.log = newLog(config.scenario.output.dir / t.getString("file", "rafting.csv"));
  return p;
}

GEM_REGISTER_PAIR_EVENT(RaftingOnset, "rafting_onset", "records floe-floe contact onsets of thin ice closing fast (rafting onset) to rafting.csv",
                        false, parseRaftingOnset);

}  // namespace gem
