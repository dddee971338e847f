// Bounds checked on TOML text before it reaches the parser (toml++ recurses into nested arrays,
// inline tables and dotted keys: a key of 50,000 parts or arrays 50,000 deep overflow its stack).
// Scenario files, sweep files and --set values go through it.
#pragma once
#include <string>
#include <string_view>

namespace gem {

constexpr int kMaxTomlNesting = 64;        // arrays and inline tables within one another
constexpr int kMaxTomlKeyParts = 64;       // a.b.c... in one key
constexpr long kMaxTomlBytes = 64L << 20;  // a scenario or sweep file, 64 MiB

// Throws InputError("FILE:LINE:COLUMN: ...") at the first place the text passes a bound.
void checkTomlLimits(std::string_view text, const std::string& fileName);

// The text of a scenario or sweep file, refused with a clear message when it is not one: missing, a
// folder, not a regular file (a device, a pipe), empty, or larger than kMaxTomlBytes.
std::string readTomlFile(const std::string& fileName, const char* what);

}  // namespace gem
