#include "framework/output/vtk_writer.hpp"

#include <zlib.h>

#include <algorithm>
#include <fstream>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <type_traits>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

#include "framework/api/errors.hpp"
#include "framework/output/atomic_file.hpp"
#include "framework/output/number_text.hpp"

namespace gem {

namespace {

// VTK's name for the engine's floating-point type: a float build writes Float32 arrays.
constexpr const char* kRealType = sizeof(Real) == 8 ? "Float64" : "Float32";
// The uncompressed size of one zlib block of an appended array (VTK's own writer uses 32 KiB).
constexpr std::size_t kBlockBytes = 1 << 16;

template <class T>
constexpr const char* vtkTypeOf() {
  if constexpr (std::is_same_v<T, double>) return "Float64";
  if constexpr (std::is_same_v<T, float>) return "Float32";
  if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  if constexpr (std::is_same_v<T, std::int32_t>) return "Int32";
  if constexpr (std::is_same_v<T, std::uint8_t>) return "UInt8";
}

// One file's DataArrays, written either inline as text (ASCII: the files diff and grep) or, for
// large fields, as zlib blocks in the file's appended section (output.vtk_encoding = "binary"):
// each array there is VTK's compression header (UInt64 block count, block size, size of a
// partial last block or 0, each block's compressed size) followed by the compressed blocks.
class ArrayWriter {
 public:
  explicit ArrayWriter(bool binary) : m_binary(binary) {}

  // count values of type T, given by valueOf(i), as an array of `components` components.
  template <class T, class F>
  void add(std::string& out, const char* name, int components, std::size_t count, F&& valueOf) {
    out += "        <DataArray type=\"";
    out += vtkTypeOf<T>();
    out += '"';
    if (name) out += fmt::format(" Name=\"{}\"", name);
    if (components > 1) out += fmt::format(" NumberOfComponents=\"{}\"", components);
    if (m_binary) {
      out += fmt::format(" format=\"appended\" offset=\"{}\"/>\n", m_appended.size());
      std::vector<T> values(count);
      for (std::size_t i = 0; i < count; ++i) values[i] = static_cast<T>(valueOf(i));
      appendCompressed(reinterpret_cast<const unsigned char*>(values.data()), values.size() * sizeof(T));
      return;
    }
    out += " format=\"ascii\">\n";
    // A bounded number per line, so that large fields stay readable in an editor.
    const std::size_t perLine = components > 1 ? 8 * static_cast<std::size_t>(components) : 16;
    for (std::size_t i = 0; i < count; ++i) {
      out += (i == 0) ? "          " : (i % perLine == 0 ? "\n          " : " ");
      appendNumber(out, static_cast<T>(valueOf(i)));
    }
    out += "\n        </DataArray>\n";
  }

  // A string per cell, always as text: VTK writes a string as its character codes, each ended by 0.
  void addStrings(std::string& out, const char* name, std::size_t count, const std::function<const char*(std::size_t)>& valueOf) {
    out += fmt::format("        <DataArray type=\"String\" Name=\"{}\" NumberOfTuples=\"{}\" format=\"ascii\">\n", name, count);
    for (std::size_t i = 0; i < count; ++i) {
      out += (i == 0) ? "          " : "\n          ";
      for (const char* c = valueOf(i); *c; ++c) out += fmt::format("{} ", static_cast<int>(static_cast<unsigned char>(*c)));
      out += '0';
    }
    out += "\n        </DataArray>\n";
  }

  // The appended section, after every array was added ("_" then the raw bytes), or "".
  std::string appendedSection() const {
    if (!m_binary) return "";
    std::string out = "  <AppendedData encoding=\"raw\">\n   _";
    out.append(m_appended.begin(), m_appended.end());
    out += "\n  </AppendedData>\n";
    return out;
  }

 private:
  void appendCompressed(const unsigned char* data, std::size_t bytes) {
    const std::size_t blocks = (bytes + kBlockBytes - 1) / kBlockBytes;
    std::vector<std::uint64_t> header{blocks, kBlockBytes, bytes % kBlockBytes};
    std::vector<unsigned char> compressed;
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t size = std::min(kBlockBytes, bytes - b * kBlockBytes);
      uLongf length = compressBound(static_cast<uLong>(size));
      const std::size_t at = compressed.size();
      compressed.resize(at + length);
      if (compress2(compressed.data() + at, &length, data + b * kBlockBytes, static_cast<uLong>(size), Z_BEST_SPEED) != Z_OK)
        throw std::runtime_error("zlib could not compress a frame's array");
      compressed.resize(at + length);
      header.push_back(length);
    }
    const auto* h = reinterpret_cast<const unsigned char*>(header.data());
    m_appended.insert(m_appended.end(), h, h + header.size() * sizeof(std::uint64_t));
    m_appended.insert(m_appended.end(), compressed.begin(), compressed.end());
  }

  bool m_binary;
  std::vector<unsigned char> m_appended;
};

std::string polyData(const World& world, double time, bool binary, const std::unordered_set<std::int64_t>& firstIds,
                     const std::vector<std::pair<std::int64_t, Real>>* contactForces) {
  const std::size_t n = static_cast<std::size_t>(world.size());
  std::vector<Vec2> points;  // every body's world vertices, one after the other
  std::vector<std::int64_t> offsets;
  Vec2 vertices[kMaxVertices];
  for (std::size_t i = 0; i < n; ++i) {
    const int count = world.worldVertices(static_cast<int>(i), vertices);
    points.insert(points.end(), vertices, vertices + count);
    offsets.push_back(static_cast<std::int64_t>(points.size()));
  }
  ArrayWriter arrays(binary);
  std::string out;
  out.reserve(512 + (binary ? 0 : points.size() * 48 + n * 160));
  out += "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"";
  out += binary ? " compressor=\"vtkZLibDataCompressor\">\n" : ">\n";
  out += "  <PolyData>\n";
  // TimeValue lets ParaView show the time of a .vtp opened on its own, without the .pvd.
  out += "    <FieldData>\n";
  out += "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">";
  appendNumber(out, time);
  out += "</DataArray>\n";
  out += "    </FieldData>\n";
  out +=
      fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"{}\">\n",
                  points.size(), n);

  out += "      <Points>\n";
  arrays.add<Real>(out, nullptr, 3, points.size() * 3, [&](std::size_t k) {
    const Vec2 p = points[k / 3];
    return k % 3 == 0 ? p.x : k % 3 == 1 ? p.y : Real(0);
  });
  out += "      </Points>\n";

  // speed is the active scalar, so ParaView colours by it on opening; id is the GlobalIds
  // attribute, so a floe can be followed (and selected) across frames whatever its cell order.
  out += "      <CellData Scalars=\"speed\" Vectors=\"velocity\" GlobalIds=\"id\">\n";
  auto at = [](std::size_t i) { return static_cast<int>(i); };
  arrays.add<std::int64_t>(out, "id", 1, n, [&](std::size_t i) { return world.id[i]; });
  arrays.add<std::int32_t>(out, "kind", 1, n, [&](std::size_t i) { return static_cast<std::int32_t>(world.kind[i]); });
  arrays.addStrings(out, "kind_name", n, [&](std::size_t i) { return bodyKindName(world.kind[at(i)]); });
  arrays.add<Real>(out, "speed", 1, n, [&](std::size_t i) { return std::hypot(world.vx[i], world.vy[i]); });
  arrays.add<Real>(out, "velocity", 3, n * 3, [&](std::size_t k) {
    const std::size_t i = k / 3;
    return k % 3 == 0 ? world.vx[i] : k % 3 == 1 ? world.vy[i] : Real(0);
  });
  arrays.add<Real>(out, "angular_velocity", 1, n, [&](std::size_t i) { return world.omega[i]; });
  arrays.add<Real>(out, "thickness", 1, n, [&](std::size_t i) { return world.thickness[i]; });
  arrays.add<Real>(out, "area", 1, n, [&](std::size_t i) { return world.area[i]; });
  arrays.add<Real>(out, "mass", 1, n, [&](std::size_t i) { return world.mass[i]; });
  // 1 for a piece that a break made (an id the series' first frame did not have).
  arrays.add<std::uint8_t>(out, "broken", 1, n, [&](std::size_t i) { return firstIds.count(world.id[i]) ? 0 : 1; });
  if (contactForces)
    arrays.add<Real>(out, "contact_force", 1, n, [&](std::size_t i) {
      const auto found =
          std::lower_bound(contactForces->begin(), contactForces->end(), std::pair<std::int64_t, Real>{world.id[i], Real(-1)});
      return found != contactForces->end() && found->first == world.id[i] ? found->second : Real(0);
    });
  out += "      </CellData>\n";

  // Polys: connectivity lists each polygon's point indices; offsets[i] is the end of polygon i.
  out += "      <Polys>\n";
  arrays.add<std::int64_t>(out, "connectivity", 1, points.size(), [](std::size_t k) { return static_cast<std::int64_t>(k); });
  arrays.add<std::int64_t>(out, "offsets", 1, n, [&](std::size_t i) { return offsets[i]; });
  out += "      </Polys>\n";
  out += "    </Piece>\n";
  out += "  </PolyData>\n";
  out += arrays.appendedSection();
  out += "</VTKFile>\n";
  return out;
}

}  // namespace

VtkSeriesWriter::VtkSeriesWriter(std::filesystem::path runDir, bool binary) : m_runDir(std::move(runDir)), m_binary(binary) {
  std::error_code ec;
  std::filesystem::create_directories(m_runDir / "frames", ec);
  if (ec) throw std::runtime_error("cannot create " + (m_runDir / "frames").string() + ": " + ec.message());
}

void VtkSeriesWriter::addFrame(const World& world, double time, const std::vector<std::pair<std::int64_t, Real>>* contactForces) {
  if (m_finished) throw std::logic_error("VtkSeriesWriter::addFrame after finish() in " + m_runDir.string());
  const std::string relative = frameFile(frameCount());
  if (m_entries.empty()) m_firstIds.insert(world.id.begin(), world.id.end());
  writeFileAtomically(m_runDir / relative, polyData(world, time, m_binary, m_firstIds, contactForces));
  m_entries.push_back({time, relative});

  writeCollection();
}

// The whole collection each time: O(frames) per frame, small next to the frame itself, and the
// .pvd on disk is always a complete document listing only frames that exist.
void VtkSeriesWriter::writeCollection() {
  std::string pvd;
  pvd.reserve(160 + m_entries.size() * 80);
  pvd += "<?xml version=\"1.0\"?>\n";
  pvd += "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n";
  pvd += "  <Collection>\n";
  for (const Entry& e : m_entries) {
    pvd += "    <DataSet timestep=\"";
    appendNumber(pvd, e.time);
    pvd += "\" group=\"\" part=\"0\" file=\"";
    pvd += e.file;
    pvd += "\"/>\n";
  }
  pvd += "  </Collection>\n";
  pvd += "</VTKFile>\n";
  writeFileAtomically(m_runDir / "frames.pvd", pvd);
}

std::string VtkSeriesWriter::frameFile(int index) {
  char name[40];
  std::snprintf(name, sizeof name, "frames/frame_%06d.vtp", index);
  return name;
}

// Whether a frame file ends as every frame GEM writes does: "</VTKFile>" then a line break.
static bool endsAsAWholeFrame(const std::filesystem::path& file) {
  static const std::string end = "</VTKFile>\n";
  std::ifstream in(file, std::ios::binary);
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (!in || size < static_cast<std::streamoff>(end.size())) return false;
  in.seekg(size - static_cast<std::streamoff>(end.size()));
  std::string tail(end.size(), '\0');
  in.read(tail.data(), static_cast<std::streamsize>(tail.size()));
  return in && tail == end;
}

void VtkSeriesWriter::save(BinaryWriter& out) const {
  std::vector<double> times;
  for (const Entry& e : m_entries) times.push_back(e.time);
  out.put(times);
  std::vector<std::int64_t> firstIds(m_firstIds.begin(), m_firstIds.end());
  std::sort(firstIds.begin(), firstIds.end());
  out.put(firstIds);
}

VtkSeriesWriter::VtkSeriesWriter(std::filesystem::path runDir, bool binary, BinaryReader& in) : VtkSeriesWriter(std::move(runDir), binary) {
  std::vector<double> times;
  std::vector<std::int64_t> firstIds;
  in.get(times), in.get(firstIds);
  for (const double t : times) m_entries.push_back({t, frameFile(frameCount())});
  m_firstIds.insert(firstIds.begin(), firstIds.end());
  // The frames the checkpoint's series lists must all be there: a resume once went on without a
  // deleted frames/ and wrote a frames.pvd listing thousands of frames that no longer existed.
  for (const Entry& e : m_entries) {
    std::error_code missing;
    if (!std::filesystem::is_regular_file(m_runDir / e.file, missing))
      throw InputError(
          fmt::format("cannot resume: {} is missing (the checkpoint's frames.pvd lists {} frames; the run's frames are "
                      "gone: run it again from the start)",
                      (m_runDir / e.file).string(), m_entries.size()));
    // A frame is written whole under a temporary name: one that does not end as every frame does
    // was cut after the stop (the resume went on over it, and frames.pvd listed it).
    if (!endsAsAWholeFrame(m_runDir / e.file))
      throw InputError(
          fmt::format("cannot resume: {} is cut short (it does not end with </VTKFile>, as every frame GEM writes "
                      "does): run it again from the start",
                      (m_runDir / e.file).string()));
  }
  // Frames the stopped run wrote after its checkpoint go: the resumed run writes them again, and
  // one that stops earlier must not leave frames its series does not list.
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(m_runDir / "frames", ec)) {
    const std::string name = entry.path().filename().string();
    int index = -1;
    const bool later =
        std::sscanf(name.c_str(), "frame_%d.vtp", &index) == 1 && index >= frameCount() && entry.path().extension() == ".vtp";
    if (later || name.find(".tmp-") != std::string::npos) std::filesystem::remove(entry.path(), ec);
  }
  writeCollection();
}

void VtkSeriesWriter::finish() { m_finished = true; }

}  // namespace gem
