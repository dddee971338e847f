#include "framework/analysis/sweep_summary.hpp"

#include <cctype>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "framework/api/errors.hpp"
#include "framework/output/atomic_file.hpp"
#include "framework/output/csv_field.hpp"

namespace fs = std::filesystem;

namespace gem {

namespace {

// A small recursive-descent reader for the JSON that summaryJson() writes.
class JsonReader {
 public:
  JsonReader(std::string text, std::string file) : m_text(std::move(text)), m_file(std::move(file)) {}

  std::map<std::string, std::string> read() {
    std::map<std::string, std::string> out;
    value("", out);
    skipSpace();
    if (m_pos != m_text.size()) fail("text after the end of the object");
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    // Bad input like any other (exit 2): a damaged file in a sweep's folder, not an internal error.
    throw InputError(
        fmt::format("{}: malformed JSON at offset {}: {} (delete it, and the sweep runs that case again)", m_file, m_pos, what));
  }
  void skipSpace() {
    while (m_pos < m_text.size() && std::isspace(static_cast<unsigned char>(m_text[m_pos]))) ++m_pos;
  }
  bool take(char c) {
    skipSpace();
    if (m_pos < m_text.size() && m_text[m_pos] == c) return ++m_pos, true;
    return false;
  }
  void expect(char c) {
    if (!take(c)) fail(fmt::format("expected '{}'", c));
  }
  bool word(const char* w) {
    const std::string s(w);
    if (m_text.compare(m_pos, s.size(), s) != 0) return false;
    m_pos += s.size();
    return true;
  }
  std::string string() {
    expect('"');
    std::string s;
    while (m_pos < m_text.size() && m_text[m_pos] != '"') {
      char c = m_text[m_pos++];
      if (c == '\\' && m_pos < m_text.size()) {
        c = m_text[m_pos++];
        if (c == 'n')
          c = '\n';
        else if (c == 't')
          c = '\t';
        else if (c == 'u') {  // GEM writes none; keep the escape as text rather than decode it
          s += "\\u";
          continue;
        }
      }
      s += c;
    }
    if (m_pos >= m_text.size()) fail("unterminated string");
    ++m_pos;
    return s;
  }
  // Nesting is bounded: a summary.json nested 50,000 deep (a damaged or hostile file) must not
  // overflow the stack of this recursive reader; GEM's own are 2 deep.
  static constexpr int kMaxDepth = 64;

  void value(const std::string& key, std::map<std::string, std::string>& out, int depth = 0) {
    skipSpace();
    if (m_pos >= m_text.size()) fail("unexpected end");
    if (depth > kMaxDepth) fail(fmt::format("nested more than {} deep", kMaxDepth));
    const char c = m_text[m_pos];
    if (c == '{') {
      ++m_pos;
      if (take('}')) return;
      do {
        skipSpace();
        const std::string name = string();
        expect(':');
        value(key.empty() ? name : key + "." + name, out, depth + 1);
      } while (take(','));
      expect('}');
    } else if (c == '[') {
      ++m_pos;
      std::map<std::string, std::string> ignored;
      if (take(']')) return;
      do value(key, ignored, depth + 1);
      while (take(','));
      expect(']');
    } else if (c == '"') {
      out[key] = string();
    } else if (word("null")) {
      out[key] = "";
    } else if (word("true")) {
      out[key] = "true";
    } else if (word("false")) {
      out[key] = "false";
    } else {
      const size_t start = m_pos;
      while (m_pos < m_text.size() && std::string_view("+-.0123456789eE").find(m_text[m_pos]) != std::string_view::npos) ++m_pos;
      if (m_pos == start) fail("expected a value");
      out[key] = m_text.substr(start, m_pos - start);
    }
  }

  std::string m_text, m_file;
  size_t m_pos = 0;
};

// summary.csv column -> summary.json key.
const std::vector<std::pair<std::string, std::string>>& columnKeys() {
  static const std::vector<std::pair<std::string, std::string>> keys = {
      {"impacts", "impacts"},
      {"ship_speed_min", "ship_speed.min"},
      {"ship_speed_mean", "ship_speed.mean"},
      {"ship_speed_max", "ship_speed.max"},
      {"impact_force_min", "impact_force_n.min"},
      {"impact_force_mean", "impact_force_n.mean"},
      {"impact_force_max", "impact_force_n.max"},
      {"resistance_mean", "resistance_mean_n"},
      {"wall_time_s", "wall_time_s"},
      // Beyond the list: the means over the steady part of the transit (hull in the field).
      {"ship_speed_in_ice_mean", "ship_speed_in_ice.mean"},
      {"resistance_in_ice_mean", "resistance_in_ice_n"},
  };
  return keys;
}

}  // namespace

std::map<std::string, std::string> readSummaryJson(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError("cannot read " + file.string());
  std::string text(std::istreambuf_iterator<char>(in), {});
  return JsonReader(std::move(text), file.string()).read();
}

const std::vector<std::string>& sweepSummaryColumns() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& [column, key] : columnKeys()) n.push_back(column);
    return n;
  }();
  return names;
}

int writeSweepSummary(const SweepDefinition& sweep, const fs::path& csv, const std::vector<fs::path>& caseDirs) {
  AtomicFile out(csv);
  std::vector<std::string> header{"name"};
  header.insert(header.end(), sweep.columns.begin(), sweep.columns.end());
  header.insert(header.end(), sweepSummaryColumns().begin(), sweepSummaryColumns().end());
  for (size_t k = 0; k < header.size(); ++k) out.stream() << (k ? "," : "") << csvField(header[k]);
  out.stream() << "\n";
  int rows = 0;
  for (size_t i = 0; i < sweep.cases.size(); ++i) {
    const fs::path json = caseDirs[i] / "summary.json";
    if (!fs::exists(json)) continue;
    const std::map<std::string, std::string> summary = readSummaryJson(json);
    const SweepCase& c = sweep.cases[i];
    out.stream() << csvField(c.name);
    for (const std::string& key : sweep.columns) out.stream() << "," << csvField(sweepCell(c, key));
    for (const auto& [column, key] : columnKeys()) {
      auto it = summary.find(key);
      out.stream() << "," << csvField(it == summary.end() ? "" : it->second);
    }
    out.stream() << "\n";
    ++rows;
  }
  out.commit();
  return rows;
}

}  // namespace gem
