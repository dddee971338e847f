#include "framework/scenario/toml_limits.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "framework/api/errors.hpp"

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
  std::error_code ec;
  const fs::file_status status = fs::status(fileName, ec);
  if (ec || !fs::exists(status)) throw InputError(fmt::format("{}: no such {} file", fileName, what));
  if (fs::is_directory(status)) throw InputError(fmt::format("{}: a folder, not a {} file", fileName, what));
  if (!fs::is_regular_file(status))
    throw InputError(fmt::format("{}: not a regular file (a device or a pipe?), not a {} file", fileName, what));
  const auto bytes = fs::file_size(fileName, ec);
  if (ec) throw InputError(fmt::format("{}: cannot be read: {}", fileName, ec.message()));
  if (bytes == 0) throw InputError(fmt::format("{}: empty: a {} file holds at least one table", fileName, what));
  if (bytes > static_cast<std::uintmax_t>(kMaxTomlBytes))
    throw InputError(fmt::format("{}: {} MiB, larger than a {} file may be ({} MiB)", fileName, bytes >> 20, what, kMaxTomlBytes >> 20));
  std::ifstream in(fileName, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) throw InputError(fmt::format("{}: cannot be read", fileName));
  checkTomlLimits(text, fileName);
  return text;
}

}  // namespace gem
