#include "framework/output/output_path.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "framework/api/errors.hpp"

namespace fs = std::filesystem;

namespace gem {
namespace {

// No file and no dangling link on the way to `folder`, for `what`: the folder could not be made.
void refuseBlockedPath(const fs::path& folder, const std::string& what) {
  std::error_code ec;
  for (fs::path p = folder; !p.empty() && p != p.root_path(); p = p.parent_path())
    if (fs::exists(p, ec) && !fs::is_directory(p, ec)) throw InputError(fmt::format("{}: {} is a file, not a folder", what, p.string()));
  // A link whose target is missing: the folder cannot be made through it ("File exists").
  for (fs::path p = folder; !p.empty() && p != p.root_path(); p = p.parent_path())
    if (fs::is_symlink(fs::symlink_status(p, ec)) && !fs::exists(p, ec))
      throw InputError(
          fmt::format("{}: {} is a symbolic link to {}, which does not exist", what, p.string(), fs::read_symlink(p, ec).string()));
}

// `folder` made and writable, for `what` ("gem sweep --out runs/x"), which it holds or is.
void makeWritableFolder(const fs::path& folder, const std::string& what) {
  refuseBlockedPath(folder, what);
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw InputError(fmt::format("{}: cannot make the folder {}: {}", what, folder.string(), ec.message()));
  if (::access(folder.c_str(), W_OK | X_OK) != 0) throw InputError(fmt::format("{}: cannot write in the folder {}", what, folder.string()));
  // access() answers yes to root for any folder on a writable filesystem, also for one that can
  // hold no new file (/proc, /sys): a file made and removed again is the only sure test. Without it
  // `--out /proc` failed later, on the run folder's lock, in words that named no option.
  const fs::path probe = folder / fmt::format(".gem-probe-{}", ::getpid());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    const int error = errno;      // before anything else can change it
    if (error == EEXIST) return;  // a probe of this pid left by a killed run: the folder holds files
    throw InputError(fmt::format("{}: cannot make a file in the folder {}: {}", what, folder.string(), std::strerror(error)));
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

}  // namespace

void requireOutputFolder(const fs::path& dir, const std::string& option) { makeWritableFolder(dir, option + " " + dir.string()); }

void requireOutputFolderIfThere(const fs::path& dir, const std::string& option) {
  refuseBlockedPath(dir, option + " " + dir.string());
  std::error_code ec;
  if (fs::exists(dir, ec)) makeWritableFolder(dir, option + " " + dir.string());
}

void requireOutputFile(const fs::path& file, const std::string& option) {
  const std::string what = option + " " + file.string();
  std::error_code ec;
  if (fs::is_directory(file, ec)) throw InputError(fmt::format("{}: a folder, not a file", what));
  makeWritableFolder(file.parent_path().empty() ? fs::path(".") : file.parent_path(), what);
}

}  // namespace gem
