// One run writes into a run folder at a time: a second gem run (or sweep case) aimed at a folder
// that a live run holds is refused, instead of both writing and their files mixing. An advisory
// lock (flock) on RUN_DIR/.gem-run.lock, released by the kernel when the holder exits, even killed.
#pragma once
#include <filesystem>

namespace gem {

class RunFolderLock {
 public:
  // Creates the folder when needed and takes its lock; throws InputError naming the folder (and the
  // holder's pid) when another process holds it.
  explicit RunFolderLock(const std::filesystem::path& dir);
  ~RunFolderLock();
  RunFolderLock(const RunFolderLock&) = delete;
  RunFolderLock& operator=(const RunFolderLock&) = delete;

 private:
  std::filesystem::path m_file;
  int m_fd = -1;
};

}  // namespace gem
