// Loads plugins (docs/architecture.md "Plugins", docs/plugins.md): shared libraries that add events and
// broadphases to the one Registry. The library's descriptor is checked before anything of it runs
// but its static initializers; a mismatch, a missing symbol or a name clash is an InputError
// (exit status 2) naming the file and the cause. Libraries are never unloaded.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "framework/api/plugin_api.hpp"

namespace gem {

struct LoadedPlugin {
  std::filesystem::path path;    // canonical
  std::string name, version;     // from the descriptor
  std::string origin;            // "PATH (NAME VERSION)": what gem info shows for its entries
  bool fromEnvironment = false;  // loaded from a folder of GEM_PLUGIN_PATH (first)
};

// Loads the plugin at `path` (relative to the working folder) and registers what it holds. A path
// already loaded is a no-op (it returns the first load). allowOverride: its names may replace
// entries already registered (the scenario's `override = true`). Thread-safe.
const LoadedPlugin& loadPlugin(const std::filesystem::path& path, bool allowOverride = false);

// Loads every *.so of each folder of GEM_PLUGIN_PATH (colon-separated; in name order, without
// override). Once per process; later calls do nothing. Each of those files must be a GEM plugin.
void loadEnvironmentPlugins();

// The plugins loaded so far, in load order.
std::vector<LoadedPlugin> loadedPlugins();

// What differs between a plugin's descriptor and this GEM; empty when it is accepted.
std::vector<std::string> descriptorMismatches(const GemPluginDescriptor& d);

}  // namespace gem
