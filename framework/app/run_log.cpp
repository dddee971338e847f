#include "framework/app/run_log.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "framework/api/plugin_api.hpp"
#include "framework/output/atomic_file.hpp"

namespace gem {

namespace {

std::string utcNow() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace

RunLog::RunLog(std::string commandLine, bool quiet) : m_quiet(quiet) {
  char host[256] = "?";
  gethostname(host, sizeof host - 1);
  m_header = fmt::format("gem {} (real type {}, plugin ABI {})\ncommand: {}\nworking folder: {}\nhost: {}\nstarted: {}\n\n", GEM_VERSION,
                         GEM_REAL_NAME, GEM_PLUGIN_ABI_VERSION, commandLine, std::filesystem::current_path().string(), host, utcNow());
}

void RunLog::say(const std::string& line) {
  if (!m_quiet) std::printf("%s\n", line.c_str());
  m_lines += line + "\n";
}

void RunLog::note(const std::string& line) { m_lines += line + "\n"; }

void RunLog::continueFrom(const std::filesystem::path& dir) {
  std::ifstream in(dir / "gem.log", std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  m_earlier = text.str();
  // A run killed (kill -9, a crash, a batch system's hard limit) wrote no gem.log of its own.
  if (m_earlier.empty()) m_earlier = "(the run's earlier part left no gem.log: it was killed or crashed)\n";
  m_earlier += "\n--- resumed from checkpoint.gem ---\n\n";
}

void RunLog::write(const std::filesystem::path& dir, int exitStatus) const {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return;
  try {
    writeFileAtomically(dir / "gem.log",
                        m_earlier + m_header + m_lines + fmt::format("\nended: {}, exit status {}\n", utcNow(), exitStatus));
  } catch (const std::exception&) {
    // A run that failed has said why on the terminal: a log that cannot be written (a folder in
    // its place, say) must not replace that message with its own.
    if (exitStatus == 0) throw;
  }
}

std::string commandLineText(int argc, char** argv) {
  std::string out;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    const bool plain =
        !a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./=:,+@%") == std::string::npos;
    std::string quoted = "'";
    for (char c : a) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    out += (i ? " " : "") + (plain ? a : quoted + "'");
  }
  return out;
}

}  // namespace gem
