// Built for the other real type (float against double or the reverse): refused.
#include <cstdlib>

#include "framework/api/plugin_api.hpp"

#if defined(GEM_REAL_FLOAT)
GEM_PLUGIN_NOTE(GEM_PLUGIN_STRINGIFY(GEM_PLUGIN_ABI_VERSION), "double", "", GEM_COMPILER_ID, GEM_COMPILER_VERSION, GEM_VERSION,
                "real_mismatch", "0.0.1");
#else
GEM_PLUGIN_NOTE(GEM_PLUGIN_STRINGIFY(GEM_PLUGIN_ABI_VERSION), "float", "", GEM_COMPILER_ID, GEM_COMPILER_VERSION, GEM_VERSION,
                "real_mismatch", "0.0.1");
#endif

GEM_PLUGIN_EXPORT const GemPluginDescriptor* gem_plugin_descriptor() {
  static const GemPluginDescriptor d{GEM_PLUGIN_ABI_VERSION,
                                     sizeof(gem::Real) == 8 ? 4u : 8u,
                                     "",
                                     GEM_COMPILER_ID,
                                     GEM_COMPILER_VERSION,
                                     GEM_VERSION,
                                     "real_mismatch",
                                     "0.0.1"};
  return &d;
}
GEM_PLUGIN_EXPORT void gem_plugin_register(gem::Registry*) { std::abort(); }
