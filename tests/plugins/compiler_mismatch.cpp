// Claims another compiler family: refused (the C++ ABI GEM and a plugin share must be one).
#include <cstdlib>

#include "framework/api/plugin_api.hpp"

GEM_PLUGIN_NOTE(GEM_PLUGIN_STRINGIFY(GEM_PLUGIN_ABI_VERSION), GEM_REAL_NAME, "", "TurboC", "3.0.0", GEM_VERSION, "compiler_mismatch",
                "0.0.1");

GEM_PLUGIN_EXPORT const GemPluginDescriptor* gem_plugin_descriptor() {
  static const GemPluginDescriptor d{
      GEM_PLUGIN_ABI_VERSION, sizeof(gem::Real), "", "TurboC", "3.0.0", GEM_VERSION, "compiler_mismatch", "0.0.1"};
  return &d;
}
GEM_PLUGIN_EXPORT void gem_plugin_register(gem::Registry*) { std::abort(); }
