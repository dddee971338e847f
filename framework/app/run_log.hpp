// gem.log: what a run's terminal showed, kept in its folder with the facts a reader of the folder
// needs later (gem's version and build, the command line, the host, the start and end times, the
// exit status), so that a folder found months later says how it was made.
#pragma once
#include <filesystem>
#include <string>

namespace gem {

class RunLog {
 public:
  RunLog(std::string commandLine, bool quiet);

  // A line of the run's report: printed on stdout (unless quiet) and kept for the log.
  void say(const std::string& line);
  // A line for the log only (what the terminal shows on stderr, such as an error).
  void note(const std::string& line);
  // A resumed run (gem run --resume): the log of the run's earlier parts in dir is kept, and this
  // part's follows it.
  void continueFrom(const std::filesystem::path& dir);
  // Writes dir/gem.log (atomically) with the lines so far and how gem ends (exit status). Does
  // nothing when dir does not exist (a run refused before it opened its folder); for a run that
  // failed (exitStatus != 0) a log that cannot be written is let go, the failure's message kept.
  void write(const std::filesystem::path& dir, int exitStatus) const;

 private:
  std::string m_earlier, m_header, m_lines;
  bool m_quiet;
};

// The command line as typed, each argument quoted for the shell where it needs to be.
std::string commandLineText(int argc, char** argv);

}  // namespace gem
