#include "framework/output/vtk_writer.hpp"

#include <charconv>
#include <cstdio>
#include <stdexcept>
#include <system_error>

#include "framework/output/atomic_file.hpp"
#include "framework/output/number_text.hpp"

namespace gem {

namespace {

// VTK's name for the engine's floating-point type: a float build writes Float32 arrays.
constexpr const char* kRealType = sizeof(Real) == 8 ? "Float64" : "Float32";

void openArray(std::string& out, const char* type, const char* name, int components) {
  out += "        <DataArray type=\"";
  out += type;
  out += '"';
  if (name) {
    out += " Name=\"";
    out += name;
    out += '"';
  }
  if (components > 1) {
    out += " NumberOfComponents=\"";
    appendNumber(out, components);
    out += '"';
  }
  out += " format=\"ascii\">\n";
}

void closeArray(std::string& out) { out += "\n        </DataArray>\n"; }

// Values of one array, a bounded number per line so that large fields stay readable in an editor.
template <class T, class F>
void appendValues(std::string& out, int count, F&& valueOf) {
  for (int i = 0; i < count; ++i) {
    out += (i == 0) ? "          " : (i % 16 == 0 ? "\n          " : " ");
    appendNumber(out, static_cast<T>(valueOf(i)));
  }
}

std::string polyData(const World& world, double time) {
  const int n = world.size();
  int points = 0;
  for (int i = 0; i < n; ++i) points += world.vertexCount[i];

  std::string out;
  out.reserve(512 + static_cast<size_t>(points) * 48 + static_cast<size_t>(n) * 96);
  out += "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n";
  out += "  <PolyData>\n";
  // TimeValue lets ParaView show the time of a .vtp opened on its own, without the .pvd.
  out += "    <FieldData>\n";
  out += "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">";
  appendNumber(out, time);
  out += "</DataArray>\n";
  out += "    </FieldData>\n";
  out += "    <Piece NumberOfPoints=\"";
  appendNumber(out, points);
  out += "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"";
  appendNumber(out, n);
  out += "\">\n";

  out += "      <Points>\n";
  openArray(out, kRealType, nullptr, 3);
  Vec2 vertices[kMaxVertices];
  bool first = true;
  for (int i = 0; i < n; ++i) {
    const int count = world.worldVertices(i, vertices);
    out += first ? "          " : "\n          ";  // one polygon per line
    first = false;
    for (int k = 0; k < count; ++k) {
      if (k > 0) out += ' ';
      appendNumber(out, vertices[k].x);
      out += ' ';
      appendNumber(out, vertices[k].y);
      out += " 0";
    }
  }
  closeArray(out);
  out += "      </Points>\n";

  out += "      <CellData Scalars=\"thickness\" Vectors=\"velocity\">\n";
  openArray(out, "Int64", "id", 1);
  appendValues<long long>(out, n, [&](int i) { return world.id[i]; });
  closeArray(out);
  openArray(out, "Int32", "kind", 1);
  appendValues<int>(out, n, [&](int i) { return static_cast<int>(world.kind[i]); });
  closeArray(out);
  openArray(out, kRealType, "thickness", 1);
  appendValues<Real>(out, n, [&](int i) { return world.thickness[i]; });
  closeArray(out);
  openArray(out, kRealType, "velocity", 3);
  for (int i = 0; i < n; ++i) {
    out += (i == 0) ? "          " : (i % 8 == 0 ? "\n          " : " ");
    appendNumber(out, world.vx[i]);
    out += ' ';
    appendNumber(out, world.vy[i]);
    out += " 0";
  }
  closeArray(out);
  openArray(out, kRealType, "angular_velocity", 1);
  appendValues<Real>(out, n, [&](int i) { return world.omega[i]; });
  closeArray(out);
  out += "      </CellData>\n";

  // Polys: connectivity lists each polygon's point indices; offsets[i] is the end of polygon i.
  out += "      <Polys>\n";
  openArray(out, "Int64", "connectivity", 1);
  long long next = 0;
  for (int i = 0; i < n; ++i) {
    out += (i == 0) ? "          " : "\n          ";
    for (int k = 0; k < world.vertexCount[i]; ++k) {
      if (k > 0) out += ' ';
      appendNumber(out, next++);
    }
  }
  closeArray(out);
  openArray(out, "Int64", "offsets", 1);
  long long end = 0;
  appendValues<long long>(out, n, [&](int i) { return end += world.vertexCount[i]; });
  closeArray(out);
  out += "      </Polys>\n";
  out += "    </Piece>\n";
  out += "  </PolyData>\n";
  out += "</VTKFile>\n";
  return out;
}

}  // namespace

VtkSeriesWriter::VtkSeriesWriter(std::filesystem::path runDir) : m_runDir(std::move(runDir)) {
  std::error_code ec;
  std::filesystem::create_directories(m_runDir / "frames", ec);
  if (ec) throw std::runtime_error("cannot create " + (m_runDir / "frames").string() + ": " + ec.message());
}

void VtkSeriesWriter::addFrame(const World& world, double time) {
  if (m_finished) throw std::logic_error("VtkSeriesWriter::addFrame after finish() in " + m_runDir.string());
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.vtp", frameCount());
  const std::string relative = std::string("frames/") + name;
  writeFileAtomically(m_runDir / "frames" / name, polyData(world, time));
  m_entries.push_back({time, relative});

  // The whole collection each time: O(frames) per frame, small next to the frame itself, and the
  // .pvd on disk is always a complete document listing only frames that exist.
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

void VtkSeriesWriter::finish() { m_finished = true; }

}  // namespace gem
