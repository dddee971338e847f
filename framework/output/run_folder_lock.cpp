#include "framework/output/run_folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "framework/api/errors.hpp"
#include "framework/output/output_path.hpp"

namespace gem {

RunFolderLock::RunFolderLock(const std::filesystem::path& dir) : m_file(dir / ".gem-run.lock") {
  // The run folder must be a folder this process can write: a file in its place (or in the place
  // of a folder above it) is bad input, said with the path, not a filesystem exception.
  requireOutputFolder(dir, "the run folder");
  m_fd = ::open(m_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (m_fd < 0) throw InputError(fmt::format("{}: cannot open the run folder's lock: {}", dir.string(), std::strerror(errno)));
  if (::flock(m_fd, LOCK_EX | LOCK_NB) != 0) {
    char holder[32] = {};
    const ssize_t n = ::pread(m_fd, holder, sizeof holder - 1, 0);
    ::close(m_fd);
    m_fd = -1;
    throw InputError(fmt::format("{}: another gem run is writing into this run folder{}; wait for it, or give another --out", dir.string(),
                                 n > 0 ? fmt::format(" (pid {})", std::string(holder, static_cast<size_t>(n))) : ""));
  }
  // A folder where the run writes one of its files would fail the run at its end, after other
  // files were written: refused now, before any work.
  for (const char* name : {"summary.json", "state.csv", "timeseries.csv", "impacts.csv", "gem.log", "scenario.toml", "frames.pvd",
                           "frames.ice", "checkpoint.gem"}) {
    std::error_code ec;
    if (std::filesystem::is_directory(dir / name, ec)) {
      ::close(m_fd);
      m_fd = -1;
      throw InputError(
          fmt::format("{}: a folder where the run writes its file {}; remove it, or give another --out", (dir / name).string(), name));
    }
  }
  const std::string pid = std::to_string(::getpid());
  if (::ftruncate(m_fd, 0) == 0 && ::pwrite(m_fd, pid.data(), pid.size(), 0) < 0) {
    // the pid is only for the message of a run refused later: not writing it is no failure
  }
}

RunFolderLock::~RunFolderLock() {
  if (m_fd < 0) return;
  std::error_code ec;
  std::filesystem::remove(m_file, ec);  // while still held: no other run can be between
  ::close(m_fd);
}

}  // namespace gem
