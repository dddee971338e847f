// A plugin whose static initializer throws while the library loads (before GEM calls anything of
// it): the exception cannot pass through the dynamic loader, so the loader must report it, naming
// the file, and exit 2, not let the process abort (tests/plugin_test.cpp).
#include <stdexcept>

#include "framework/api/plugin_api.hpp"

GEM_PLUGIN("throws_at_load", "0.0.1")

namespace {
struct ThrowsOnLoad {
  ThrowsOnLoad() { throw std::runtime_error("throws_at_load: a static initializer throwing on purpose"); }
};
const ThrowsOnLoad g_throws;
}  // namespace
