// Whole-file writes (docs/architecture.md "Scenario and outputs"): every output file is written under a
// temporary name beside its final path and renamed onto it only once it is complete. rename(2)
// within one directory is atomic, so a run that crashes (or is killed) leaves either the previous
// whole file or the new whole file, never a torn one. No fsync: this guards against a crash of the
// process, not against power loss, which would cost a disk flush on every frame.
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace gem {

class AtomicFile {
 public:
  // Opens "<path>.tmp-<pid>" for writing (the pid keeps two processes writing the same run folder
  // from trampling each other's temporaries). Throws std::runtime_error if it cannot be opened.
  explicit AtomicFile(std::filesystem::path path);
  // A file a resumed run goes on writing (docs/reliability.md "Checkpoints and resume"): its first
  // `bytes`, as a checkpoint recorded them, from the temporary the stopped run was writing
  // (`earlierTemp`) or, when that run closed its files (a signal), from the final path. Either
  // becomes this process's temporary, cut to `bytes`, and writes go on at its end. InputError when
  // neither exists or it is shorter than `bytes`.
  AtomicFile(std::filesystem::path path, const std::filesystem::path& earlierTemp, std::uint64_t bytes);
  // Without commit() the temporary is removed: an unfinished file never appears.
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return m_stream; }
  const std::filesystem::path& path() const { return m_path; }
  const std::filesystem::path& tempPath() const { return m_tempPath; }
  // Flushes what was written to the temporary (not to the disk: a process that dies after this
  // leaves those bytes in the file) and returns its length, for a checkpoint.
  std::uint64_t flushedSize();

  // Flushes and closes the temporary, checks that every write succeeded, and renames it onto the
  // final path. Throws std::runtime_error (naming the path and the system's reason) on failure, in
  // which case the temporary is removed and the final path is left untouched.
  void commit();

 private:
  std::filesystem::path m_path;
  std::filesystem::path m_tempPath;
  std::ofstream m_stream;
  bool m_committed = false;
};

// The temporary a checkpoint names for finalPath (recordedName: "<final name><infix><pid>", in the
// final path's folder), checked: a damaged or crafted checkpoint never makes a resume move or cut
// another file. InputError otherwise.
std::filesystem::path earlierTempPath(const std::filesystem::path& finalPath, const std::string& recordedName,
                                      const std::string& infix = ".tmp-");

// The checkpointed part of a file (AtomicFile's resume constructor) as ownTemp; returns ownTemp.
std::filesystem::path adoptForResume(const std::filesystem::path& path, const std::filesystem::path& earlierTemp,
                                     const std::filesystem::path& ownTemp, std::uint64_t bytes);

// Writes content to path through an AtomicFile.
void writeFileAtomically(const std::filesystem::path& path, const std::string& content);

}  // namespace gem
