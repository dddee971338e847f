#include "framework/scenario/toml_limits.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"

namespace gem {

void checkTomlLimits(std::string_view text, const std::string& fileName) {
  int line = 1, column = 0, depth = 0, dots = 0;
  enum class In { Code, Comment, Basic, Literal, MultiBasic, MultiLiteral } in = In::Code;
  for (size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    ++column;
    if (c == '\n') ++line, column = 0;
    auto startsWith = [&](std::string_view s) { return text.substr(k, s.size()) == s; };
    switch (in) {
      case In::Comment:
        if (c == '\n') in = In::Code;
        continue;
      case In::Basic:
        if (c == '\\')
          ++k, ++column;
        else if (c == '"' || c == '\n')
          in = In::Code;
        continue;
      case In::Literal:
        if (c == '\'' || c == '\n') in = In::Code;
        continue;
      case In::MultiBasic:
        if (c == '\\')
          ++k, ++column;
        else if (startsWith("\"\"\""))
          in = In::Code, k += 2, column += 2;
        continue;
      case In::MultiLiteral:
        if (startsWith("'''")) in = In::Code, k += 2, column += 2;
        continue;
      case In::Code:
        break;
    }
    if (c == '#')
      in = In::Comment;
    else if (startsWith("\"\"\""))
      in = In::MultiBasic, k += 2, column += 2;
    else if (startsWith("'''"))
      in = In::MultiLiteral, k += 2, column += 2;
    else if (c == '"')
      in = In::Basic;
    else if (c == '\'')
      in = In::Literal;
    if (c == '[' || c == '{') {
      if (++depth > kMaxTomlNesting)
        throw InputError(fileName, line, column, fmt::format("arrays or tables nested more than {} deep", kMaxTomlNesting));
    }
    if (c == ']' || c == '}') depth = depth > 0 ? depth - 1 : 0;
    if (c == '=' || c == ',' || c == '\n' || c == '[' || c == ']' || c == '{' || c == '}') dots = 0;
    if (c == '.' && ++dots >= kMaxTomlKeyParts)
      throw InputError(fileName, line, column, fmt::format("a dotted key of more than {} parts", kMaxTomlKeyParts));
  }
}

std::string readTomlFile(const std::string& fileName, const char* what) {
  namespace fs = std::filesystem;
  requireRegularFile(fileName, fmt::format("{} file", what));
  std::error_code ec;
  const auto bytes = fs::file_size(fileName, ec);
  if (ec) throw InputError(fmt::format("{}: cannot be read: {}", fileName, ec.message()));
  if (bytes > static_cast<std::uintmax_t>(kMaxTomlBytes))
    throw InputError(fmt::format("{}: {} MiB, larger than a {} file may be ({} MiB)", fileName, bytes >> 20, what, kMaxTomlBytes >> 20));
  std::ifstream in(fileName, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot be read: {}", fileName, std::strerror(errno)));
  // Read to the end, at most one byte past the limit: a file whose size the system does not know
  // (those of /proc say 0) is measured by what it holds.
  std::string text;
  char chunk[1 << 16];
  while (in && text.size() <= static_cast<size_t>(kMaxTomlBytes)) {
    in.read(chunk, sizeof chunk);
    text.append(chunk, static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(fmt::format("{}: cannot be read", fileName));
  if (text.empty()) throw InputError(fmt::format("{}: empty: a {} file holds at least one table", fileName, what));
  if (text.size() > static_cast<size_t>(kMaxTomlBytes))
    throw InputError(fmt::format("{}: larger than a {} file may be ({} MiB)", fileName, what, kMaxTomlBytes >> 20));
  checkTomlLimits(text, fileName);
  return text;
}

}  // namespace gem
