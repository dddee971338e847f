// Files a reader takes in whole (a .ice file, a CSV output read back): refused up front when they
// could not fit in memory, naming the file and its size, instead of growing until std::bad_alloc
// or swapping for minutes (a 100 GB impacts.csv once did both).
#pragma once
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "framework/api/errors.hpp"

namespace gem {

// A file a reader opens: refused unless it is a regular file, naming the path and what it is
// instead. Checked before the open: opening a named pipe blocks until something writes to it
// (gem analyze once waited forever on an impacts.csv that was a pipe), and a folder fails only at
// the first read, with the C++ library's words ("basic_filebuf::underflow").
inline void requireRegularFile(const std::filesystem::path& file, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (ec && ec != std::errc::no_such_file_or_directory)  // a loop of links, a folder not searchable
    throw InputError(fmt::format("{}: cannot be read as a {}: {}", file.string(), what, ec.message()));
  if (!fs::exists(status)) {
    std::error_code linkError;
    if (fs::is_symlink(fs::symlink_status(file, linkError)))
      throw InputError(fmt::format("{}: a symbolic link to {}, which does not exist: no such {}", file.string(),
                                   fs::read_symlink(file, linkError).string(), what));
    throw InputError(fmt::format("{}: no such {}", file.string(), what));
  }
  if (fs::is_directory(status)) throw InputError(fmt::format("{}: a folder, not a {}", file.string(), what));
  if (!fs::is_regular_file(status))
    throw InputError(fmt::format("{}: not a regular file (a pipe or a device?), not a {}", file.string(), what));
}

// A folder a command reads (a run folder, a sweep's): refused when it is missing or a file, or a
// symbolic link that loops or leads nowhere, naming which.
inline void requireFolder(const std::filesystem::path& dir, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (ec && ec != std::errc::no_such_file_or_directory)
    throw InputError(fmt::format("{}: cannot be read as a {}: {}", dir.string(), what, ec.message()));
  if (fs::is_directory(status)) return;
  if (fs::exists(status)) throw InputError(fmt::format("{}: a file, not a {}", dir.string(), what));
  std::error_code linkError;
  if (fs::is_symlink(fs::symlink_status(dir, linkError)))
    throw InputError(fmt::format("{}: a symbolic link to {}, which does not exist: no such {}", dir.string(),
                                 fs::read_symlink(dir, linkError).string(), what));
  throw InputError(fmt::format("{}: no such {}", dir.string(), what));
}

// Whether a run folder holds `file` (one GEM wrote there): false when no entry has its name; an
// entry that is not a readable regular file (a loop of links, a link to nothing, a folder, a pipe)
// is refused by requireRegularFile, naming what it is, instead of being taken as missing.
inline bool holdsFile(const std::filesystem::path& file, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::exists(std::filesystem::symlink_status(file, ec))) return false;
  requireRegularFile(file, what);
  return true;
}

// This machine's memory, bytes: what an input is measured against before it is read or made.
inline double machineMemory() { return static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE)); }

// expansion: the reader's memory per byte of the file (its text plus what it builds from it).
inline void requireFitsInMemory(const std::filesystem::path& file, double expansion) {
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(file, ec);
  if (ec) return;  // not a regular file: the reader says what it is
  const double memory = machineMemory();
  const double need = static_cast<double>(bytes) * expansion;
  if (memory > 0 && need > 0.8 * memory)
    throw InputError(fmt::format("{}: {:.3g} GB, too large to read: it would take about {:.3g} GB of this machine's {:.3g} GB of memory",
                                 file.string(), static_cast<double>(bytes) / 1e9, need / 1e9, memory / 1e9));
}

}  // namespace gem
