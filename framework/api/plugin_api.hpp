// The plugin ABI (docs/plugins.md, docs/architecture.md "Plugins"). A plugin is a shared library that
//   0. carries its descriptor as plain text in an ELF section of its own, ".gem_plugin": the loader
//      reads it from the file and refuses a mismatch (ABI, real type, compiler, CUDA
//      architectures) BEFORE the library is opened, so that a plugin built for another real type
//      is refused with that reason instead of failing to bind a GEM function that takes a Real;
//   1. exports `gem_plugin_descriptor`, a plain C function returning a GemPluginDescriptor, the
//      same facts for a loaded library (gem info shows them);
//   2. exports `gem_plugin_register(gem::Registry*)`, called only once the descriptor is accepted:
//      it adds the library's events and broadphases to the registry the built-ins sit in.
// One line in one source file of the plugin writes both: GEM_PLUGIN("my_plugin", "1.0.0").
//
// Plugins use the very same GEM_REGISTER_* macros as the built-ins. Compiled with
// GEM_BUILDING_PLUGIN defined (gem_add_plugin does it), a macro does not register at load time
// (dlopen runs static initializers before the descriptor can be read, and a mismatched library
// must not touch the registry); it only links a node into this library's own list, which
// gem_plugin_register walks.
#pragma once
#include <cstdint>

#include "geometry/config.hpp"

// 4: the descriptor note (".gem_plugin"), declared event order, contact slots with normal and
//    tangential impulses, record streams owned by their events.
// 5: EventConfig::enabled (a parse knows whether its event is on).
// 6: EventInstance::timeInvariant (a solo or motion event's kTimeInvariant).
// Bump on any change to the descriptor, the Registry/EventEntry/BroadphaseEntry layout, the event
// API structs (framework/api/event_api.hpp) or the World that a plugin's code may see.
#define GEM_PLUGIN_ABI_VERSION 6

#define GEM_PLUGIN_STRINGIFY_INNER(x) #x
#define GEM_PLUGIN_STRINGIFY(x) GEM_PLUGIN_STRINGIFY_INNER(x)

// The compiler of the translation unit that expands these: a plugin and GEM each state their own.
#if defined(__clang__)
#define GEM_COMPILER_ID "Clang"
#define GEM_COMPILER_VERSION \
  GEM_PLUGIN_STRINGIFY(__clang_major__) "." GEM_PLUGIN_STRINGIFY(__clang_minor__) "." GEM_PLUGIN_STRINGIFY(__clang_patchlevel__)
#elif defined(__GNUC__)
#define GEM_COMPILER_ID "GNU"
#define GEM_COMPILER_VERSION \
  GEM_PLUGIN_STRINGIFY(__GNUC__) "." GEM_PLUGIN_STRINGIFY(__GNUC_MINOR__) "." GEM_PLUGIN_STRINGIFY(__GNUC_PATCHLEVEL__)
#else
#define GEM_COMPILER_ID "unknown"
#define GEM_COMPILER_VERSION "0"
#endif

// The CUDA architectures the plugin's device code was built for; "" for a CPU-only plugin.
#ifndef GEM_PLUGIN_CUDA_ARCHITECTURES
#define GEM_PLUGIN_CUDA_ARCHITECTURES ""
#endif
#ifndef GEM_VERSION
#define GEM_VERSION "unknown"
#endif

extern "C" {

// Plain C, fixed layout. abiVersion is the first field forever: the loader reads it alone first.
struct GemPluginDescriptor {
  std::uint32_t abiVersion;       // GEM_PLUGIN_ABI_VERSION
  std::uint32_t realSize;         // sizeof(gem::Real): 8 (double) or 4 (float)
  const char* cudaArchitectures;  // e.g. "90"; "" when the plugin has no device code
  const char* compilerId;         // "GNU", "Clang"
  const char* compilerVersion;    // "12.2.0"
  const char* gemVersion;         // the GEM the plugin was built against (informational)
  const char* name;               // the plugin's name, e.g. "skin_drag"
  const char* version;            // the plugin's own version, e.g. "1.0.0"
};

typedef const GemPluginDescriptor* (*GemPluginDescriptorFunction)();

}  // extern "C"

namespace gem {

class Registry;

// One GEM_REGISTER_* of a plugin: a function that adds one entry, linked into the library's list.
struct PluginRegistration {
  void (*add)(Registry&);
  PluginRegistration* next;
};

using PluginRegisterFunction = void (*)(Registry*);

}  // namespace gem

// The head of this library's list. Hidden: every plugin has its own, even when several are loaded.
extern "C" __attribute__((visibility("hidden"))) ::gem::PluginRegistration* gem_plugin_registrations;

namespace gem {
// A static object of each plugin macro: pushes its node at load time (plain pointer work only).
struct PluginRegistrationNode {
  explicit PluginRegistrationNode(void (*add)(Registry&)) : node{add, gem_plugin_registrations} { gem_plugin_registrations = &node; }
  PluginRegistration node;
};

// The list is last-constructed first: walk it backwards, so entries register in source order.
inline void runPluginRegistrations(const PluginRegistration* r, Registry& registry) {
  if (!r) return;
  runPluginRegistrations(r->next, registry);
  r->add(registry);
}
}  // namespace gem

#define GEM_PLUGIN_EXPORT extern "C" __attribute__((visibility("default")))

// The descriptor as text in the ELF section ".gem_plugin": read by the loader from the file, before
// the library is opened (no relocation, no code of the plugin runs). Each argument is a string
// literal; GEM_PLUGIN writes this plugin's own facts, the loader's tests write wrong ones.
#define GEM_PLUGIN_NOTE(ABI, REAL, CUDA_ARCHITECTURES, COMPILER_ID, COMPILER_VERSION, GEM_VER, NAME, VERSION)                 \
  extern "C" __attribute__((section(".gem_plugin"), used, visibility("hidden"))) const char gem_plugin_note[] =               \
      "gem-plugin\n"                                                                                                          \
      "abi=" ABI "\nreal=" REAL "\ncuda=" CUDA_ARCHITECTURES "\ncompiler=" COMPILER_ID "\ncompiler_version=" COMPILER_VERSION \
      "\ngem=" GEM_VER "\nname=" NAME "\nversion=" VERSION "\n"

// Exactly once per plugin, at namespace scope of one source file: the descriptor and the
// registration entry point. NAME and VERSION are string literals.
#define GEM_PLUGIN(NAME, VERSION)                                                                                              \
  GEM_PLUGIN_NOTE(GEM_PLUGIN_STRINGIFY(GEM_PLUGIN_ABI_VERSION), GEM_REAL_NAME, GEM_PLUGIN_CUDA_ARCHITECTURES, GEM_COMPILER_ID, \
                  GEM_COMPILER_VERSION, GEM_VERSION, NAME, VERSION);                                                           \
  extern "C" {                                                                                                                 \
  __attribute__((visibility("hidden"))) ::gem::PluginRegistration* gem_plugin_registrations = nullptr;                         \
  }                                                                                                                            \
  GEM_PLUGIN_EXPORT const GemPluginDescriptor* gem_plugin_descriptor() {                                                       \
    static const GemPluginDescriptor descriptor{GEM_PLUGIN_ABI_VERSION,                                                        \
                                                static_cast<std::uint32_t>(sizeof(::gem::Real)),                               \
                                                GEM_PLUGIN_CUDA_ARCHITECTURES,                                                 \
                                                GEM_COMPILER_ID,                                                               \
                                                GEM_COMPILER_VERSION,                                                          \
                                                GEM_VERSION,                                                                   \
                                                NAME,                                                                          \
                                                VERSION};                                                                      \
    return &descriptor;                                                                                                        \
  }                                                                                                                            \
  GEM_PLUGIN_EXPORT void gem_plugin_register(::gem::Registry* registry) {                                                      \
    ::gem::runPluginRegistrations(gem_plugin_registrations, *registry);                                                        \
  }
