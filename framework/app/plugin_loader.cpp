// The plugin loader. First the descriptor note is read from the file (plugin_note.hpp) and checked:
// a mismatch is refused before the library is opened. Then Boost.DLL with std::filesystem, RTLD_NOW
// (an unresolved symbol fails at load, with the linker's message, not at the first call mid-run),
// throwing overloads (their message, dlerror's included, reaches the user).
#define BOOST_DLL_USE_STD_FS
#include "framework/app/plugin_loader.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <sstream>
#include <system_error>

#include <boost/dll/shared_library.hpp>
#include <fmt/format.h>

#include "framework/api/errors.hpp"
#include "framework/api/registry.hpp"
#include "framework/app/plugin_note.hpp"
#include "framework/step/stepper.hpp"

namespace fs = std::filesystem;

namespace gem {
namespace {

struct LoaderState {
  std::mutex mutex;
  std::vector<LoadedPlugin> plugins;
  // Never destroyed, so never unloaded: the registry's factories and every object they made run
  // code of these libraries, up to and past the end of main (docs/architecture.md "Plugins").
  std::vector<boost::dll::shared_library> libraries;
  bool environmentLoaded = false;
};

LoaderState& state() {
  static LoaderState* s = new LoaderState;  // deliberately leaked (see above)
  return *s;
}

std::string text(const char* s) { return s ? s : "(null)"; }

// An exception thrown by a plugin's static initializer cannot pass through the dynamic loader:
// it ends in std::terminate, inside dlopen. While a library loads, the terminate handler reports
// it as any refused plugin is reported (the file and the cause, exit 2) instead of an abort.
const char* g_loading = nullptr;  // the file being opened (loads are serialised by LoaderState's mutex)

[[noreturn]] void reportThrowingInitializer() {
  std::string what = "an exception that is not a std::exception";
  try {
    if (const std::exception_ptr e = std::current_exception()) std::rethrow_exception(e);
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {}
  std::fprintf(stderr, "gem: error: plugin %s: cannot be loaded: a static initializer threw while the library loaded: %s\n",
               g_loading ? g_loading : "?", what.c_str());
  std::fflush(stderr);
  std::_Exit(2);
}

struct TerminateReportsPlugin {
  std::terminate_handler previous;
  explicit TerminateReportsPlugin(const std::string& file) {
    g_loading = file.c_str();
    previous = std::set_terminate(reportThrowingInitializer);
  }
  ~TerminateReportsPlugin() {
    std::set_terminate(previous);
    g_loading = nullptr;
  }
};

std::string majorOf(const std::string& version) { return version.substr(0, version.find('.')); }

// The CUDA architectures of this GEM's device code; "" when it has no CUDA backend.
std::string hostCudaArchitectures() {
#ifdef GEM_CUDA_ARCHITECTURES
  if (findBackend("cuda")) return GEM_CUDA_ARCHITECTURES;
#endif
  return "";
}

// The note's fields as a descriptor (the strings live in `note`). A field that is missing or not a
// number reads as 0, which no GEM accepts.
GemPluginDescriptor descriptorOf(const PluginNote& note) {
  auto field = [&](const char* key) -> const char* {
    auto it = note.fields.find(key);
    return it == note.fields.end() ? "" : it->second.c_str();
  };
  auto number = [](const char* text) {
    char* end = nullptr;
    const unsigned long v = std::strtoul(text, &end, 10);
    return *text && end && !*end && v < 100000 ? static_cast<std::uint32_t>(v) : 0u;
  };
  const std::string real = field("real");
  const std::uint32_t realSize = real == "double" ? 8u : real == "float" ? 4u : 0u;
  return GemPluginDescriptor{number(field("abi")),      realSize,     field("cuda"), field("compiler"),
                             field("compiler_version"), field("gem"), field("name"), field("version")};
}

const LoadedPlugin& loadLocked(LoaderState& st, const fs::path& given, bool allowOverride, bool fromEnvironment = false) {
  const std::string file = given.string();
  std::error_code ec;
  if (!fs::exists(given, ec)) throw InputError(fmt::format("plugin {}: no such file", file));
  if (!fs::is_regular_file(given, ec)) throw InputError(fmt::format("plugin {}: not a regular file", file));
  const fs::path path = fs::canonical(given);
  for (const LoadedPlugin& p : st.plugins)
    if (p.path == path) return p;  // the same library twice: already registered

  // The note, before anything of the library is mapped: a plugin for another real type would
  // otherwise die in the dynamic linker on the first GEM function it calls that takes a Real.
  const PluginNote note = readPluginNote(path);
  if (note.status == PluginNote::Status::NotElf) throw InputError(fmt::format("plugin {}: cannot be loaded: {}", file, note.problem));
  if (note.status == PluginNote::Status::NoNote)
    throw InputError(
        fmt::format("plugin {}: not a GEM plugin (it has no .gem_plugin descriptor note; one source file of a plugin says "
                    "GEM_PLUGIN(\"name\", \"version\"), and a plugin built for GEM 0.1 must be rebuilt)",
                    file));
  const std::vector<std::string> noteMismatches = descriptorMismatches(descriptorOf(note));
  if (!noteMismatches.empty())
    throw InputError(fmt::format("plugin {}: refused, it was built for another GEM: {}", file, fmt::join(noteMismatches, "; ")));

  boost::dll::shared_library library;
  try {
    const TerminateReportsPlugin guard(file);
    library.load(path, boost::dll::load_mode::rtld_now);
  } catch (const boost::dll::fs::system_error& e) {
    // Boost.DLL reports dlopen's failure as dlerror()'s text followed by ": " and the message of
    // an error code it chose (EBADF, "Bad file descriptor"), which is not the cause: drop it.
    std::string what = e.what();
    const std::string suffix = ": " + e.code().message();
    if (what.size() > suffix.size() && what.compare(what.size() - suffix.size(), suffix.size(), suffix) == 0)
      what.erase(what.size() - suffix.size());
    throw InputError(fmt::format("plugin {}: cannot be loaded: {}", file, what));
  } catch (const std::exception& e) {
    throw InputError(fmt::format("plugin {}: cannot be loaded: {}", file, e.what()));
  }
  // From here on the library stays loaded whatever happens: its static initializers have run.
  st.libraries.push_back(library);

  if (!library.has("gem_plugin_descriptor"))
    throw InputError(
        fmt::format("plugin {}: not a GEM plugin (it exports no gem_plugin_descriptor; "
                    "one source file of a plugin says GEM_PLUGIN(\"name\", \"version\"))",
                    file));
  const GemPluginDescriptor* d = library.get<const GemPluginDescriptor*()>("gem_plugin_descriptor")();
  if (!d) throw InputError(fmt::format("plugin {}: gem_plugin_descriptor returned nothing", file));
  const std::vector<std::string> mismatches = descriptorMismatches(*d);
  if (!mismatches.empty())
    throw InputError(fmt::format("plugin {}: refused, it was built for another GEM: {}", file, fmt::join(mismatches, "; ")));
  if (!library.has("gem_plugin_register"))
    throw InputError(
        fmt::format("plugin {}: missing symbol gem_plugin_register (the descriptor is there, the "
                    "registration entry point is not)",
                    file));
  auto registerAll = library.get<void(Registry*)>("gem_plugin_register");

  LoadedPlugin plugin{path, text(d->name), text(d->version), "", fromEnvironment};
  plugin.origin = fmt::format("{} ({} {})", path.string(), plugin.name, plugin.version);
  Registry& registry = Registry::global();
  registry.beginPlugin(plugin.origin, allowOverride);
  try {
    registerAll(&registry);
    registry.commitPlugin();
  } catch (const InputError&) {
    registry.abortPlugin();
    throw;
  } catch (const std::exception& e) {
    registry.abortPlugin();
    throw InputError(fmt::format("plugin {}: its registration failed: {}", file, e.what()));
  } catch (...) {  // a plugin may throw anything: never let it end the process
    registry.abortPlugin();
    throw InputError(fmt::format("plugin {}: its registration failed with an exception that is not a std::exception", file));
  }
  st.plugins.push_back(plugin);
  return st.plugins.back();
}

}  // namespace

std::vector<std::string> descriptorMismatches(const GemPluginDescriptor& d) {
  std::vector<std::string> out;
  // The first field alone first: under another ABI the rest may be laid out differently.
  if (d.abiVersion != GEM_PLUGIN_ABI_VERSION) {
    out.push_back(fmt::format("plugin ABI version {} (this GEM: {})", d.abiVersion, GEM_PLUGIN_ABI_VERSION));
    return out;
  }
  if (d.realSize != sizeof(Real)) {
    auto realName = [](unsigned size) { return size == 8 ? "double" : size == 4 ? "float" : "unknown"; };
    out.push_back(fmt::format("real type {} ({} bytes; this GEM: {}, {} bytes)", realName(d.realSize), d.realSize, realName(sizeof(Real)),
                              sizeof(Real)));
  }
  // Same compiler family and major version: the C++ ABI of std::string, std::function and the
  // vtables the plugin shares with GEM.
  const std::string id = text(d.compilerId), version = text(d.compilerVersion);
  if (id != GEM_COMPILER_ID || majorOf(version) != majorOf(GEM_COMPILER_VERSION))
    out.push_back(fmt::format("compiler {} {} (this GEM: {} {}; the family and major version must match)", id, version, GEM_COMPILER_ID,
                              GEM_COMPILER_VERSION));
  // Device code must be built for the architectures GEM runs its kernels on.
  const std::string archs = text(d.cudaArchitectures), hostArchs = hostCudaArchitectures();
  if (!archs.empty() && !hostArchs.empty() && archs != hostArchs)
    out.push_back(fmt::format("CUDA architectures {} (this GEM: {})", archs, hostArchs));
  return out;
}

const LoadedPlugin& loadPlugin(const fs::path& path, bool allowOverride) {
  LoaderState& st = state();
  std::lock_guard lock(st.mutex);
  return loadLocked(st, path, allowOverride);
}

void loadEnvironmentPlugins() {
  LoaderState& st = state();
  std::lock_guard lock(st.mutex);
  if (st.environmentLoaded) return;
  st.environmentLoaded = true;
  const char* value = std::getenv("GEM_PLUGIN_PATH");
  if (!value) return;
  std::stringstream folders(value);
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    if (folder.empty()) continue;
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) throw InputError(fmt::format("GEM_PLUGIN_PATH: {}: no such folder", folder));
    std::vector<fs::path> files;
    for (const fs::directory_entry& e : fs::directory_iterator(folder))
      if (e.is_regular_file() && e.path().extension() == ".so") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      try {
        loadLocked(st, f, false, true);
      } catch (const InputError& e) {
        // The registry's hint for a clash names a [[plugins]] entry's override, which a plugin of
        // GEM_PLUGIN_PATH does not have (it never replaces another).
        std::string message = e.what();
        const std::string hint = "(to replace it, give the plugin's [[plugins]] entry override = true)";
        if (const size_t at = message.find(hint); at != std::string::npos)
          message.replace(at, hint.size(),
                          "(GEM_PLUGIN_PATH never replaces an entry: keep one of the two in its folders, or load the replacing plugin "
                          "from a scenario's [[plugins]] entry with override = true)");
        throw InputError(fmt::format("GEM_PLUGIN_PATH: {}", message));
      }
    }
  }
}

std::vector<LoadedPlugin> loadedPlugins() {
  LoaderState& st = state();
  std::lock_guard lock(st.mutex);
  return st.plugins;
}

// The registry's plugin loader (api/registry.hpp): installed when GEM's library loads.
static const bool g_installed = [] {
  setPluginLibraryLoader({[](const fs::path& path, bool allowOverride) { loadPlugin(path, allowOverride); }, &loadEnvironmentPlugins});
  return true;
}();

}  // namespace gem
