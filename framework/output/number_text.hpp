// Numbers as text for the run folder's files: the shortest text that reads back to the identical
// value (0.7 stays "0.7"), for float and double builds alike.
#pragma once
#include <charconv>
#include <string>
#include <system_error>

namespace gem {

template <class T>
void appendNumber(std::string& out, T value) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, ec == std::errc() ? end : buf);
}

}  // namespace gem
