// A plugin that needs a symbol nothing provides: the dynamic linker refuses it at load time
// (RTLD_NOW). The loader must say what the linker said, not a stale errno ("Bad file descriptor").
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"

GEM_PLUGIN("unresolved_symbol", "0.0.1")

extern "C" void gem_test_symbol_that_no_library_defines();

GEM_REGISTRATION(unresolved_, ((void)registry, gem_test_symbol_that_no_library_defines()));
