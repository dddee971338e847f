// A plugin's descriptor note (the ".gem_plugin" ELF section that GEM_PLUGIN writes, api/plugin_api.hpp),
// read from the library's file without opening the library: a plugin built for another real type,
// ABI or compiler is refused before the dynamic linker binds any of its symbols.
#pragma once
#include <filesystem>
#include <map>
#include <string>

namespace gem {

struct PluginNote {
  enum class Status { NotElf, NoNote, Found } status = Status::NotElf;
  std::string problem;                        // for NotElf: why the file is not a shared library GEM can read
  std::map<std::string, std::string> fields;  // abi, real, cuda, compiler, compiler_version, gem, name, version
};

// Reads the note of the ELF file at `path`. Every offset and size read from the file is checked
// against the file's size first: a truncated or hostile file gives NotElf, never a crash.
PluginNote readPluginNote(const std::filesystem::path& path);

}  // namespace gem
