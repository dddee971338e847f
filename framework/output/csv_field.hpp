// One field of a CSV row (RFC 4180): as it is, or quoted with its quotes doubled when it holds a
// comma, a quote or a line break (a sweep's default case names hold commas: "r35,bollard_thrust=92000").
#pragma once
#include <string>

namespace gem {

inline std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace gem
