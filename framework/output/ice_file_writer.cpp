// The thesis .ice writer (format in framework/field/ice_file.hpp, which reads it).
#include "framework/output/ice_file_writer.hpp"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <unordered_set>
#include <vector>

#include "framework/api/errors.hpp"
#include "framework/output/atomic_file.hpp"
#include "framework/output/number_text.hpp"

namespace gem {
namespace {

// Changed by more than 1e-9 relative (absolute below magnitude 1); NaN always counts as changed.
bool differs(Real now, Real written) {
  const double tolerance = 1e-9 * std::max(1.0, std::fabs(static_cast<double>(written)));
  return !(std::fabs(static_cast<double>(now) - static_cast<double>(written)) <= tolerance);
}

}  // namespace

IceFileWriter::IceFileWriter(std::filesystem::path path) : m_path(std::move(path)) {
  m_framesPath = m_path;
  m_framesPath += ".frames.tmp-" + std::to_string(::getpid());
  errno = 0;
  m_frames.open(m_framesPath, std::ios::out | std::ios::trunc | std::ios::binary);
  if (!m_frames) throw std::runtime_error("cannot open " + m_framesPath.string() + " for writing: " + std::strerror(errno));
}

IceFileWriter::IceFileWriter(std::filesystem::path path, BinaryReader& in) : m_path(std::move(path)) {
  namespace fs = std::filesystem;
  m_framesPath = m_path;
  m_framesPath += ".frames.tmp-" + std::to_string(::getpid());
  const auto earlierTemp = in.get<std::string>();
  const auto bytes = in.get<std::uint64_t>();
  in.get(m_frameCount);
  const auto ids = in.get<std::uint64_t>();
  for (std::uint64_t k = 0; k < ids; ++k) {
    const auto id = in.get<std::int64_t>();
    Written& w = m_written[id];
    in.get(w.coordinates), in.get(w.vx), in.get(w.vy), in.get(w.omega), in.get(w.thickness), in.get(w.kind), in.get(w.lastSeenFrame);
  }
  std::error_code ec;
  const fs::path earlier = earlierTempPath(m_path, earlierTemp, ".frames.tmp-");
  if (!fs::is_regular_file(earlier, ec) && fs::is_regular_file(m_path, ec)) {
    // The stopped run finished its file: its frames follow the three header lines (finish()).
    std::ifstream whole(m_path, std::ios::binary);
    std::string line;
    for (int k = 0; k < 3 && std::getline(whole, line);) ++k;
    std::string frames(bytes, '\0');
    whole.read(frames.data(), static_cast<std::streamsize>(bytes));
    if (!whole) throw InputError("cannot resume: " + m_path.string() + " holds fewer frames than the checkpoint");
    m_frames.open(m_framesPath, std::ios::out | std::ios::trunc | std::ios::binary);
    m_frames.write(frames.data(), static_cast<std::streamsize>(frames.size()));
    fs::remove(m_path, ec);  // written again, whole, when the resumed run finishes
  } else {
    adoptForResume(m_path, earlier, m_framesPath, bytes);
    m_frames.open(m_framesPath, std::ios::out | std::ios::app | std::ios::ate | std::ios::binary);
  }
  if (!m_frames) throw std::runtime_error("cannot open " + m_framesPath.string() + " for writing: " + std::strerror(errno));
}

void IceFileWriter::save(BinaryWriter& out) {
  m_frames.flush();
  if (!m_frames) throw std::runtime_error("cannot write " + m_framesPath.string() + ": " + std::strerror(errno));
  out.put(m_framesPath.filename().string());
  out.put(static_cast<std::uint64_t>(m_frames.tellp()));
  out.put(m_frameCount);
  // By id, so that the same state always makes the same checkpoint.
  std::vector<std::int64_t> ids;
  ids.reserve(m_written.size());
  for (const auto& [id, w] : m_written) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  out.put(static_cast<std::uint64_t>(ids.size()));
  for (const std::int64_t id : ids) {
    const Written& w = m_written.at(id);
    out.put(id);
    out.put(w.coordinates), out.put(w.vx), out.put(w.vy), out.put(w.omega), out.put(w.thickness), out.put(w.kind), out.put(w.lastSeenFrame);
  }
}

IceFileWriter::~IceFileWriter() {
  if (m_frames.is_open()) m_frames.close();
  std::error_code ignored;  // never throw from a destructor; the temporary is all there is to tidy
  std::filesystem::remove(m_framesPath, ignored);
}

void IceFileWriter::addFrame(const World& world, double time) {
  if (m_finished) throw std::logic_error("IceFileWriter::addFrame after finish() for " + m_path.string());
  const int frame = m_frameCount;
  std::string out;
  out.reserve(256 + static_cast<size_t>(world.size()) * (frame == 0 ? 400 : 120));
  out += "  <frame index=\"";
  appendNumber(out, frame);
  out += "\" time=\"";
  appendNumber(out, time);
  out += "\">\n";

  Vec2 vertices[kMaxVertices];
  for (int i = 0; i < world.size(); ++i) {
    const int n = world.worldVertices(i, vertices);
    const auto [it, isNew] = m_written.try_emplace(world.id[i]);
    Written& w = it->second;
    if (w.lastSeenFrame == frame)
      throw std::logic_error("IceFileWriter: id " + std::to_string(world.id[i]) + " appears twice in one World");
    w.lastSeenFrame = frame;

    bool coordinatesChanged = isNew || static_cast<size_t>(n) != w.coordinates.size();
    for (int k = 0; k < n && !coordinatesChanged; ++k)
      coordinatesChanged = differs(vertices[k].x, w.coordinates[k].x) || differs(vertices[k].y, w.coordinates[k].y);
    const bool velocityChanged = isNew || differs(world.vx[i], w.vx) || differs(world.vy[i], w.vy) || differs(world.omega[i], w.omega);
    const bool thicknessChanged = isNew || differs(world.thickness[i], w.thickness);
    const bool kindChanged = !isNew && world.kind[i] != w.kind;
    if (!coordinatesChanged && !velocityChanged && !thicknessChanged && !kindChanged) continue;

    out += "    <object index=\"";
    appendNumber(out, world.id[i]);
    out += '"';
    // Floe is the default kind: writing it only for the others keeps plain thesis readers happy.
    if ((isNew && world.kind[i] != BodyKind::Floe) || kindChanged) {
      out += " kind=\"";
      out += bodyKindName(world.kind[i]);
      out += '"';
    }
    out += ">\n";
    if (coordinatesChanged) {
      out += "      <coordinates>";
      for (int k = 0; k < n; ++k) {
        if (k > 0) out += ' ';
        appendNumber(out, vertices[k].x);
        out += ' ';
        appendNumber(out, vertices[k].y);
      }
      out += "</coordinates>\n";
      w.coordinates.assign(vertices, vertices + n);
    }
    if (velocityChanged) {
      out += "      <velocity x=\"";
      appendNumber(out, world.vx[i]);
      out += "\" y=\"";
      appendNumber(out, world.vy[i]);
      out += "\" a=\"";
      appendNumber(out, world.omega[i]);
      out += "\"/>\n";
      w.vx = world.vx[i];
      w.vy = world.vy[i];
      w.omega = world.omega[i];
    }
    if (thicknessChanged) {
      out += "      <thickness>";
      appendNumber(out, world.thickness[i]);
      out += "</thickness>\n";
      w.thickness = world.thickness[i];
    }
    w.kind = world.kind[i];
    out += "    </object>\n";
  }

  // Ids written before but absent now have left the world; sorted so the file is reproducible.
  std::vector<std::int64_t> removed;
  for (const auto& [id, w] : m_written)
    if (w.lastSeenFrame != frame) removed.push_back(id);
  std::sort(removed.begin(), removed.end());
  for (const std::int64_t id : removed) {
    out += "    <object index=\"";
    appendNumber(out, id);
    out += "\"><removed/></object>\n";
    m_written.erase(id);
  }
  out += "  </frame>\n";

  m_frames.write(out.data(), static_cast<std::streamsize>(out.size()));
  if (!m_frames) throw std::runtime_error("cannot write " + m_framesPath.string() + ": " + std::strerror(errno));
  ++m_frameCount;
}

void IceFileWriter::finish() {
  if (m_finished) return;
  m_frames.close();
  if (m_frames.fail()) throw std::runtime_error("cannot write " + m_framesPath.string() + ": " + std::strerror(errno));

  AtomicFile file(m_path);
  std::ofstream& out = file.stream();
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<!-- GEM extensions to the thesis format: object kind, frame time, <removed/>"
         " (see framework/field/ice_file.hpp) -->\n"
      << "<iceFloeSim numFrames=\"" << m_frameCount << "\">\n";
  if (m_frameCount > 0) {  // copying an empty streambuf would set failbit on out
    std::ifstream in(m_framesPath, std::ios::binary);
    if (!in) throw std::runtime_error("cannot reopen " + m_framesPath.string() + ": " + std::strerror(errno));
    out << in.rdbuf();
  }
  out << "</iceFloeSim>\n";
  file.commit();

  std::error_code ignored;
  std::filesystem::remove(m_framesPath, ignored);
  m_finished = true;
}

}  // namespace gem
