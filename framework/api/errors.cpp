#include "framework/api/errors.hpp"

#include <fmt/format.h>

namespace gem {

namespace {
// Control characters of the input a message quotes, written out as \xNN: a value's escape
// sequences would otherwise reach the terminal (retitle it, clear it) and a NUL would cut the
// message short where it is printed. Line breaks and tabs stay (several errors, one a line).
std::string escapeControls(const std::string& message) {
  std::string out;
  out.reserve(message.size());
  for (const char c : message) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\n' && c != '\t') || u == 0x7f)
      out += fmt::format("\\x{:02x}", u);
    else
      out += c;
  }
  return out;
}
}  // namespace

std::string InputError::shorten(const std::string& raw) {
  const std::string message = escapeControls(raw);
  if (message.size() <= kMaxMessage) return message;
  const size_t head = kMaxMessage * 2 / 3, tail = kMaxMessage / 4;
  return message.substr(0, head) + fmt::format(" [... {} characters left out ...] ", message.size() - head - tail) +
         message.substr(message.size() - tail);
}

InputError InputError::multiline(const std::string& lines) {
  std::string out;
  size_t start = 0;
  while (start <= lines.size()) {
    const size_t end = std::min(lines.find('\n', start), lines.size());
    if (start > 0) out += '\n';
    out += shorten(lines.substr(start, end - start));
    start = end + 1;
  }
  return InputError(out, Whole{});
}

std::string InputError::format(const std::string& file, int line, int column, const std::string& message) {
  if (file.empty()) return message;
  if (line > 0 && column > 0) return fmt::format("{}:{}:{}: {}", file, line, column, message);
  if (line > 0) return fmt::format("{}:{}: {}", file, line, message);
  return fmt::format("{}: {}", file, message);
}

}  // namespace gem
