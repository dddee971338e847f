// Helpers shared by the tests: scenarios from TOML text, temporary folders, running the gem binary.
#pragma once
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "framework/scenario.hpp"

namespace gem::test {

// A fresh folder under the system's temporary directory, removed when the object goes.
class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    m_path = std::filesystem::temp_directory_path() /
             ("gem-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(m_path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(m_path, ec);
  }
  const std::filesystem::path& path() const { return m_path; }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(m_path / name) << text;
    return m_path / name;
  }

 private:
  std::filesystem::path m_path;
};

inline Scenario scenarioFromToml(const TempDir& dir, const std::string& text, const std::vector<std::string>& overrides = {}) {
  return loadScenario(dir.write("scenario.toml", text), overrides);
}

// Runs the built gem binary; returns its exit status. Output goes to `log`.
inline int runGem(const std::string& arguments, const std::filesystem::path& log) {
  const std::string command = std::string(GEM_BINARY_DIR) + "/gem " + arguments + " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string readFile(const std::filesystem::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace gem::test
