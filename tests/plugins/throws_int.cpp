// A plugin whose registration throws something that is not a std::exception (an int): the
// loader must refuse it with a message, exit 2, not let it abort the process.
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"

GEM_PLUGIN("throws_int", "0.0.1")

GEM_REGISTRATION(throwing_, ((void)registry, throw 42));
