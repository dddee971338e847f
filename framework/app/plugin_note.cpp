#include "framework/app/plugin_note.hpp"

#include <elf.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

namespace gem {

namespace {

// The whole file, up to a bound: a plugin is a few MB; anything near this is not one.
constexpr std::uintmax_t kMaxPluginBytes = std::uintmax_t(1) << 31;

bool readRange(const std::vector<char>& file, std::uint64_t offset, std::uint64_t size, void* out) {
  if (offset > file.size() || size > file.size() - offset) return false;
  std::memcpy(out, file.data() + offset, size);
  return true;
}

}  // namespace

PluginNote readPluginNote(const std::filesystem::path& path) {
  PluginNote note;
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec || bytes > kMaxPluginBytes) {
    note.problem = ec ? ec.message() : "larger than any plugin (2 GiB)";
    return note;
  }
  std::vector<char> file(bytes);
  std::ifstream in(path, std::ios::binary);
  if (!in.read(file.data(), static_cast<std::streamsize>(bytes))) {
    note.problem = "cannot be read";
    return note;
  }
  Elf64_Ehdr header;
  if (!readRange(file, 0, sizeof header, &header) || std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0) {
    note.problem = "not an ELF shared library";
    return note;
  }
  if (header.e_ident[EI_CLASS] != ELFCLASS64 || header.e_ident[EI_DATA] != ELFDATA2LSB || header.e_shentsize != sizeof(Elf64_Shdr)) {
    note.problem = "not a 64-bit little-endian ELF library (as this GEM is)";
    return note;
  }
  auto section = [&](unsigned index, Elf64_Shdr& out) {
    return index < header.e_shnum && readRange(file, header.e_shoff + std::uint64_t(index) * sizeof(Elf64_Shdr), sizeof out, &out);
  };
  Elf64_Shdr names;
  if (!section(header.e_shstrndx, names) || names.sh_offset > file.size() || names.sh_size > file.size() - names.sh_offset) {
    note.problem = "its ELF section table is damaged";
    return note;
  }
  note.status = PluginNote::Status::NoNote;
  for (unsigned k = 0; k < header.e_shnum; ++k) {
    Elf64_Shdr s;
    if (!section(k, s) || s.sh_name >= names.sh_size) continue;
    const char* name = file.data() + names.sh_offset + s.sh_name;
    const size_t room = names.sh_size - s.sh_name;
    if (strnlen(name, room) == room || std::strcmp(name, ".gem_plugin") != 0) continue;
    if (s.sh_offset > file.size() || s.sh_size > file.size() - s.sh_offset) break;
    const std::string text(file.data() + s.sh_offset, strnlen(file.data() + s.sh_offset, s.sh_size));
    std::istringstream lines(text);
    std::string line;
    if (!std::getline(lines, line) || line != "gem-plugin") break;
    while (std::getline(lines, line)) {
      const size_t eq = line.find('=');
      if (eq != std::string::npos) note.fields[line.substr(0, eq)] = line.substr(eq + 1);
    }
    note.status = PluginNote::Status::Found;
    break;
  }
  return note;
}

}  // namespace gem
