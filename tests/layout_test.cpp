// The house's rules (docs/architecture.md "Rooms"): a lower room never includes a higher one, and
// no file of GEM's own includes the deprecated paths kept for old plugins. Read from the source
// tree, so a new include that breaks a rule fails here, naming the file, the line and the rule.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace gem {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = GEM_SOURCE_DIR;

// The room of a path relative to the source root: "geometry", "api", "events", ... or "" (other).
std::string roomOf(const std::string& path) {
  static const std::vector<std::string> framework{"api", "world", "field", "scenario", "step", "cuda", "output", "app", "analysis"};
  for (const std::string& room : framework)
    if (path.rfind("framework/" + room + "/", 0) == 0) return room;
  for (const char* top : {"geometry", "events", "broadphase", "bench", "plugins", "tests"})
    if (path.rfind(std::string(top) + "/", 0) == 0) return top;
  return "";
}

// The rooms each room may include (besides itself). The order, lowest first: geometry, world,
// api, field, scenario, step, then cuda and output side by side, analysis, app. Events and
// broadphases are what plugins are: they see the api and what lies under it, and an event's host
// part may read the scenario (the vessel's hull, say).
const std::map<std::string, std::set<std::string>>& allowed() {
  static const std::map<std::string, std::set<std::string>> rules{
      {"geometry", {}},
      {"world", {"geometry"}},
      {"api", {"geometry", "world"}},
      {"field", {"geometry", "world", "api"}},
      {"scenario", {"geometry", "world", "api", "field"}},
      {"step", {"geometry", "world", "api", "field", "scenario"}},
      {"cuda", {"geometry", "world", "api", "field", "scenario", "step"}},
      {"output", {"geometry", "world", "api", "field", "scenario", "step"}},
      {"analysis", {"geometry", "world", "api", "field", "scenario", "step", "output"}},
      {"events", {"geometry", "world", "api", "field", "scenario"}},
      {"broadphase", {"geometry", "world", "api"}},
  };
  return rules;
}

struct Include {
  std::string file;  // relative to the source root
  int line;
  std::string target;
};

std::vector<Include> projectIncludes() {
  std::vector<Include> includes;
  for (const char* top : {"framework", "geometry", "events", "broadphase", "bench", "plugins", "tests"}) {
    for (const auto& entry : fs::recursive_directory_iterator(kSource / top)) {
      const std::string ext = entry.path().extension().string();
      if (!entry.is_regular_file() || (ext != ".hpp" && ext != ".cpp" && ext != ".cu" && ext != ".cuh")) continue;
      const std::string file = fs::relative(entry.path(), kSource).generic_string();
      if (file.rfind("framework/api/deprecated/", 0) == 0) continue;
      std::ifstream in(entry.path());
      std::string text;
      for (int line = 1; std::getline(in, text); ++line) {
        // #include "target" (spaces allowed around '#'); system includes <...> are not GEM's.
        const size_t hash = text.find_first_not_of(" \t");
        if (hash == std::string::npos || text[hash] != '#') continue;
        const size_t word = text.find_first_not_of(" \t", hash + 1);
        if (word == std::string::npos || text.compare(word, 7, "include") != 0) continue;
        const size_t open = text.find('"', word + 7), close = open == std::string::npos ? open : text.find('"', open + 1);
        if (close != std::string::npos) includes.push_back({file, line, text.substr(open + 1, close - open - 1)});
      }
    }
  }
  return includes;
}

TEST(Layout, LowerRoomsNeverIncludeHigherOnes) {
  int checked = 0;
  for (const Include& inc : projectIncludes()) {
    const auto rule = allowed().find(roomOf(inc.file));
    if (rule == allowed().end()) continue;  // app, bench, plugins and tests may include any room
    const std::string target = roomOf(inc.target);
    if (target.empty() || target == rule->first) continue;  // a system or sibling header, or its own room
    // The resident kernel's table of built-in events: the one place the framework names them
    // (the registry otherwise keeps it ignorant of events); the events still see nothing above them.
    if (inc.file == "framework/cuda/resident_events.cu" && target == "events") continue;
    ++checked;
    EXPECT_TRUE(rule->second.count(target)) << inc.file << ":" << inc.line << ": room " << rule->first << " includes " << inc.target
                                            << " of room " << target << ", which lies above it (docs/architecture.md \"Rooms\")";
  }
  EXPECT_GT(checked, 100) << "the scan found too few includes: is GEM_SOURCE_DIR the source tree?";
}

// Every GEM include names a file where it says, not a forwarding header of the old layout (those
// are for plugins written against GEM 0.1 only; tests/plugins/old_layout.cpp uses them on purpose).
TEST(Layout, NothingOfGemIncludesTheDeprecatedPaths) {
  for (const Include& inc : projectIncludes()) {
    if (inc.file == "tests/plugins/old_layout.cpp") continue;
    const std::string room = roomOf(inc.target);
    if (room.empty() && inc.target.find('/') != std::string::npos && inc.target.rfind("framework/", 0) != 0) continue;
    if (inc.target.find('/') == std::string::npos) continue;  // beside the including file
    EXPECT_TRUE(fs::exists(kSource / inc.target)) << inc.file << ":" << inc.line << ": includes " << inc.target
                                                  << ", which is not in the tree (a deprecated path? see framework/api/deprecated)";
  }
}

}  // namespace
}  // namespace gem
