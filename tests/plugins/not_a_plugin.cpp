// A shared library that is not a GEM plugin: it exports no gem_plugin_descriptor.
extern "C" __attribute__((visibility("default"))) int gem_test_answer() { return 42; }
