#include "framework/output/atomic_file.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "framework/api/errors.hpp"

namespace gem {

namespace {

std::runtime_error writeError(const std::string& what, const std::filesystem::path& path, int err) {
  // errno may be 0 when an iostream failed without a system call failing (e.g. a formatting error).
  const std::string reason = err != 0 ? std::strerror(err) : "stream error";
  return std::runtime_error("cannot " + what + " " + path.string() + ": " + reason);
}

// The place a file is written to holds nothing or a regular file (or a link to one): the rename
// at commit replaces whatever is there, and a device, a pipe or a folder given as an output path
// (gem view --out /dev/full, once, as root) must be refused, not replaced by a file.
void requireFilePlace(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status) || fs::is_regular_file(status)) return;
  const char* what = fs::is_directory(status) ? "a folder" : fs::is_fifo(status) ? "a pipe" : "a device or other special file";
  throw InputError(fmt::format("{}: {}, not a file GEM may write (it writes a new file in its place)", path.string(), what));
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path path) : m_path(std::move(path)) {
  requireFilePlace(m_path);
  m_tempPath = m_path;
  m_tempPath += ".tmp-" + std::to_string(::getpid());
  errno = 0;
  m_stream.open(m_tempPath, std::ios::out | std::ios::trunc | std::ios::binary);
  if (!m_stream) throw writeError("open for writing", m_tempPath, errno);
}

std::filesystem::path earlierTempPath(const std::filesystem::path& finalPath, const std::string& recordedName, const std::string& infix) {
  const std::string prefix = finalPath.filename().string() + infix;
  const bool digits =
      recordedName.size() > prefix.size() && recordedName.find_first_not_of("0123456789", prefix.size()) == std::string::npos;
  if (recordedName.compare(0, prefix.size(), prefix) != 0 || !digits)
    throw InputError(fmt::format("checkpoint: damaged (it names \"{}\" as the temporary of {})", recordedName.substr(0, 200),
                                 finalPath.filename().string()));
  return finalPath.parent_path() / recordedName;
}

// The part of a file a checkpoint vouches for, from where the stopped run left it, as this
// process's temporary.
std::filesystem::path adoptForResume(const std::filesystem::path& path, const std::filesystem::path& earlierTemp,
                                     const std::filesystem::path& ownTemp, std::uint64_t bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path source = fs::is_regular_file(earlierTemp, ec) ? earlierTemp : fs::is_regular_file(path, ec) ? path : fs::path();
  // A resume killed before its first checkpoint had already taken the file over under its own
  // temporary name (NAME.tmp-ITSPID), which the checkpoint does not know: that file starts with the
  // same bytes (it only ran on past them), so it serves as well. Without this the folder could
  // never be resumed again.
  if (source.empty()) {
    // The recorded temporary's name without its process id: NAME.tmp-, or a writer's own infix.
    std::string prefix = earlierTemp.filename().string();
    prefix.erase(prefix.find_last_not_of("0123456789") + 1);
    std::vector<fs::path> candidates;
    for (const auto& entry : fs::directory_iterator(path.parent_path().empty() ? fs::path(".") : path.parent_path(), ec)) {
      const std::string name = entry.path().filename().string();
      if (name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
          name.find_first_not_of("0123456789", prefix.size()) == std::string::npos && entry.is_regular_file(ec) &&
          fs::file_size(entry.path(), ec) >= bytes && !ec)
        candidates.push_back(entry.path());
    }
    std::sort(candidates.begin(), candidates.end());
    if (!candidates.empty()) source = candidates.front();
  }
  if (source.empty())
    throw InputError("cannot resume: " + path.string() + " is missing (neither it nor " + earlierTemp.filename().string() +
                     ", which the stopped run was writing, is there)");
  const std::uintmax_t size = fs::file_size(source, ec);
  if (ec || size < bytes)
    throw InputError(
        fmt::format("cannot resume: {} holds {} bytes, fewer than the {} of the checkpoint", source.string(), ec ? 0 : size, bytes));
  if (source != ownTemp) fs::rename(source, ownTemp);
  fs::resize_file(ownTemp, bytes);
  return ownTemp;
}

AtomicFile::AtomicFile(std::filesystem::path path, const std::filesystem::path& earlierTemp, std::uint64_t bytes)
    : m_path(std::move(path)) {
  requireFilePlace(m_path);
  m_tempPath = m_path;
  m_tempPath += ".tmp-" + std::to_string(::getpid());
  adoptForResume(m_path, earlierTemp, m_tempPath, bytes);
  errno = 0;
  m_stream.open(m_tempPath, std::ios::out | std::ios::app | std::ios::ate | std::ios::binary);
  if (!m_stream) throw writeError("open for writing", m_tempPath, errno);
}

std::uint64_t AtomicFile::flushedSize() {
  m_stream.flush();
  if (!m_stream) throw writeError("write", m_tempPath, errno);
  return static_cast<std::uint64_t>(m_stream.tellp());
}

AtomicFile::~AtomicFile() {
  if (m_committed) return;
  if (m_stream.is_open()) m_stream.close();
  std::error_code ignored;  // a destructor must not throw; a leftover temporary is harmless
  std::filesystem::remove(m_tempPath, ignored);
}

void AtomicFile::commit() {
  if (m_committed) throw std::logic_error("AtomicFile::commit called twice for " + m_path.string());
  errno = 0;
  m_stream.flush();
  // close() flushes what remains and reports a failed final write (a full disk shows up here).
  const bool wroteAll = static_cast<bool>(m_stream);
  m_stream.close();
  if (!wroteAll || m_stream.fail()) {
    const int err = errno;
    std::error_code ignored;
    std::filesystem::remove(m_tempPath, ignored);
    throw writeError("write", m_tempPath, err);
  }
  if (std::rename(m_tempPath.c_str(), m_path.c_str()) != 0) {
    const int err = errno;
    std::error_code ignored;
    std::filesystem::remove(m_tempPath, ignored);
    throw writeError("rename " + m_tempPath.string() + " onto", m_path, err);
  }
  m_committed = true;
}

void writeFileAtomically(const std::filesystem::path& path, const std::string& content) {
  AtomicFile file(path);
  file.stream().write(content.data(), static_cast<std::streamsize>(content.size()));
  file.commit();
}

}  // namespace gem
