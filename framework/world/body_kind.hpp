// The kinds of body (docs/model.md 1). Host+device.
#pragma once
#include <cstdint>

namespace gem {
enum class BodyKind : std::uint8_t { Floe = 0, Vessel = 1, Wall = 2 };
}
