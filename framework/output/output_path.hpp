// Output places named on the command line (--out, --csv), checked before any work is done: a file
// where a folder must be, or a folder that cannot be made or written, is bad input (exit 2), said
// with the option and the path, instead of a failure once the work is done (a benchmark, the
// calibration runs) with the name of a temporary file.
#pragma once
#include <filesystem>
#include <string>

namespace gem {

// `dir` exists afterwards, as a folder this process may write. `option` names where the path came
// from ("gem sweep --out"). InputError otherwise.
void requireOutputFolder(const std::filesystem::path& dir, const std::string& option);

// As requireOutputFolder, but nothing is made: a path through a file is refused, and a folder that
// exists already is checked whole; one that does not is left to be made by the run (gem run checks
// --out while it loads, and a run refused for its input leaves no folder behind).
void requireOutputFolderIfThere(const std::filesystem::path& dir, const std::string& option);

// `file` can be written: its folder is made as requireOutputFolder does, and it is not a folder.
void requireOutputFile(const std::filesystem::path& file, const std::string& option);

}  // namespace gem
