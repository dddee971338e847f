#include "framework/output/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <system_error>

namespace gem {

namespace {

std::runtime_error writeError(const std::string& what, const std::filesystem::path& path, int err) {
  // errno may be 0 when an iostream failed without a system call failing (e.g. a formatting error).
  const std::string reason = err != 0 ? std::strerror(err) : "stream error";
  return std::runtime_error("cannot " + what + " " + path.string() + ": " + reason);
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path path) : m_path(std::move(path)) {
  m_tempPath = m_path;
  m_tempPath += ".tmp-" + std::to_string(::getpid());
  errno = 0;
  m_stream.open(m_tempPath, std::ios::out | std::ios::trunc | std::ios::binary);
  if (!m_stream) throw writeError("open for writing", m_tempPath, errno);
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
