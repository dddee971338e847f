// Built for another plugin ABI: the loader must refuse it before calling anything but the
// descriptor (gem_plugin_register aborts, so a test would crash if it were called).
#include <cstdlib>

#include "framework/api/plugin_api.hpp"

GEM_PLUGIN_NOTE("999", GEM_REAL_NAME, "", GEM_COMPILER_ID, GEM_COMPILER_VERSION, GEM_VERSION, "abi_mismatch", "0.0.1");

GEM_PLUGIN_EXPORT const GemPluginDescriptor* gem_plugin_descriptor() {
  static const GemPluginDescriptor d{999,         sizeof(gem::Real), "",     GEM_COMPILER_ID, GEM_COMPILER_VERSION,
                                     GEM_VERSION, "abi_mismatch",    "0.0.1"};
  return &d;
}
GEM_PLUGIN_EXPORT void gem_plugin_register(gem::Registry*) { std::abort(); }
