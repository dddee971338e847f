// A descriptor that GEM accepts, but no gem_plugin_register: the missing-symbol case.
#include "framework/api/plugin_api.hpp"

GEM_PLUGIN_NOTE(GEM_PLUGIN_STRINGIFY(GEM_PLUGIN_ABI_VERSION), GEM_REAL_NAME, "", GEM_COMPILER_ID, GEM_COMPILER_VERSION, GEM_VERSION,
                "missing_register", "0.0.1");

GEM_PLUGIN_EXPORT const GemPluginDescriptor* gem_plugin_descriptor() {
  static const GemPluginDescriptor d{
      GEM_PLUGIN_ABI_VERSION, sizeof(gem::Real), "", GEM_COMPILER_ID, GEM_COMPILER_VERSION, GEM_VERSION, "missing_register", "0.0.1"};
  return &d;
}
