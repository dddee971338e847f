// The ParaView writer (framework/output/vtk_writer.hpp): parse what it wrote and check the structure.
#include "framework/output/vtk_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <zlib.h>

#include <atomic>
#include <cstring>
#include <fstream>
#include <iterator>
#include <pugixml.hpp>
#include <sstream>

namespace gem {
namespace {

class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    m_path = std::filesystem::temp_directory_path() / ("gem_vtk_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(m_path);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(m_path, ignored);
  }
  const std::filesystem::path& path() const { return m_path; }

 private:
  std::filesystem::path m_path;
};

std::vector<double> numbers(pugi::xml_node array) {
  std::istringstream in(array.text().get());
  std::vector<double> out;
  for (double v; in >> v;) out.push_back(v);
  return out;
}

pugi::xml_node cellArray(pugi::xml_node piece, const char* name) {
  return piece.child("CellData").find_child_by_attribute("DataArray", "Name", name);
}

TEST(VtkSeriesWriter, WritesPolygonsWithCellDataAndACollection) {
  TempDir dir;  // not created: the writer makes runDir/frames itself
  World w;
  BodySpec square;
  square.vertices = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  square.thickness = 0.7;
  square.velocity = {1.5, -0.5};
  square.angularVelocity = 0.2;
  w.addBody(square);
  BodySpec wall;
  wall.kind = BodyKind::Wall;
  wall.vertices = {{0, -3}, {10, -3}, {10, -2}};
  w.addBody(wall);

  VtkSeriesWriter writer(dir.path());
  writer.addFrame(w, 0.0);
  {
    // After one frame the collection is already a whole document listing that frame.
    pugi::xml_document pvd;
    ASSERT_TRUE(pvd.load_file((dir.path() / "frames.pvd").c_str()));
    EXPECT_EQ(std::distance(pvd.child("VTKFile").child("Collection").children("DataSet").begin(),
                            pvd.child("VTKFile").child("Collection").children("DataSet").end()),
              1);
  }
  BodySpec vessel;
  vessel.kind = BodyKind::Vessel;
  vessel.vertices = {{20, 0}, {30, 0}, {32, 1}, {30, 2}, {20, 2}};
  w.addBody(vessel);
  w.x[0] += 1;
  writer.addFrame(w, 0.25);
  writer.finish();

  pugi::xml_document vtp;
  const auto first = dir.path() / "frames" / "frame_000000.vtp";
  ASSERT_TRUE(vtp.load_file(first.c_str())) << first;
  pugi::xml_node poly = vtp.child("VTKFile");
  EXPECT_STREQ(poly.attribute("type").value(), "PolyData");
  pugi::xml_node piece = poly.child("PolyData").child("Piece");
  EXPECT_EQ(piece.attribute("NumberOfPolys").as_int(), 2);
  EXPECT_EQ(piece.attribute("NumberOfPoints").as_int(), 7);
  const std::vector<double> points = numbers(piece.child("Points").child("DataArray"));
  ASSERT_EQ(points.size(), 21u);
  EXPECT_DOUBLE_EQ(points[3], 2.0);  // second vertex of the square, x
  EXPECT_DOUBLE_EQ(points[2], 0.0);  // z
  EXPECT_EQ(numbers(cellArray(piece, "id")), (std::vector<double>{0, 1}));
  EXPECT_STREQ(cellArray(piece, "id").attribute("type").value(), "Int64");
  EXPECT_EQ(numbers(cellArray(piece, "kind")), (std::vector<double>{0, 2}));
  EXPECT_STREQ(cellArray(piece, "kind").attribute("type").value(), "Int32");
  EXPECT_DOUBLE_EQ(numbers(cellArray(piece, "thickness"))[0], 0.7);
  EXPECT_EQ(cellArray(piece, "velocity").attribute("NumberOfComponents").as_int(), 3);
  EXPECT_EQ(numbers(cellArray(piece, "velocity")), (std::vector<double>{1.5, -0.5, 0, 0, 0, 0}));
  EXPECT_DOUBLE_EQ(numbers(cellArray(piece, "angular_velocity"))[0], 0.2);
  pugi::xml_node polys = piece.child("Polys");
  EXPECT_EQ(numbers(polys.find_child_by_attribute("DataArray", "Name", "offsets")), (std::vector<double>{4, 7}));
  EXPECT_EQ(numbers(polys.find_child_by_attribute("DataArray", "Name", "connectivity")), (std::vector<double>{0, 1, 2, 3, 4, 5, 6}));

  pugi::xml_document second;
  ASSERT_TRUE(second.load_file((dir.path() / "frames" / "frame_000001.vtp").c_str()));
  piece = second.child("VTKFile").child("PolyData").child("Piece");
  EXPECT_EQ(piece.attribute("NumberOfPolys").as_int(), 3);
  EXPECT_EQ(piece.attribute("NumberOfPoints").as_int(), 12);
  EXPECT_EQ(numbers(cellArray(piece, "id")), (std::vector<double>{0, 1, 2}));
  EXPECT_EQ(numbers(cellArray(piece, "kind")), (std::vector<double>{0, 2, 1}));
  EXPECT_DOUBLE_EQ(numbers(piece.child("Points").child("DataArray"))[0], 1.0);  // the moved square

  pugi::xml_document pvd;
  ASSERT_TRUE(pvd.load_file((dir.path() / "frames.pvd").c_str()));
  EXPECT_STREQ(pvd.child("VTKFile").attribute("type").value(), "Collection");
  std::vector<std::pair<double, std::string>> sets;
  for (pugi::xml_node d : pvd.child("VTKFile").child("Collection").children("DataSet"))
    sets.emplace_back(d.attribute("timestep").as_double(), d.attribute("file").value());
  ASSERT_EQ(sets.size(), 2u);
  EXPECT_EQ(sets[0], (std::pair<double, std::string>{0.0, "frames/frame_000000.vtp"}));
  EXPECT_EQ(sets[1], (std::pair<double, std::string>{0.25, "frames/frame_000001.vtp"}));
  for (const auto& s : sets) EXPECT_TRUE(std::filesystem::exists(dir.path() / s.second));

  // Only whole files: no temporaries left beside them.
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
  EXPECT_THROW(writer.addFrame(w, 0.5), std::logic_error);
}

TEST(VtkSeriesWriter, EmptyWorldIsAValidFrame) {
  TempDir dir;
  World w;
  VtkSeriesWriter writer(dir.path());
  writer.addFrame(w, 1.0);
  pugi::xml_document vtp;
  ASSERT_TRUE(vtp.load_file((dir.path() / "frames" / "frame_000000.vtp").c_str()));
  EXPECT_EQ(vtp.child("VTKFile").child("PolyData").child("Piece").attribute("NumberOfPolys").as_int(), 0);
}

// The cell data a ParaView user asks for: GlobalIds to follow a floe, speed as the default
// colouring, the kind by name, area and mass, and which cells are pieces of a break.
TEST(VtkSeriesWriter, CellDataNamesIdsKindsAndBrokenPieces) {
  TempDir dir;
  World w;
  BodySpec square;
  square.vertices = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  square.thickness = 0.5;
  square.velocity = {3, 4};
  w.addBody(square);
  VtkSeriesWriter writer(dir.path());
  writer.addFrame(w, 0.0);
  BodySpec piece = square;
  piece.vertices = {{5, 0}, {6, 0}, {6, 1}};
  w.addBody(piece);  // a new id, as a split's piece has
  writer.addFrame(w, 1.0);

  pugi::xml_document vtp;
  ASSERT_TRUE(vtp.load_file((dir.path() / "frames" / "frame_000001.vtp").c_str()));
  pugi::xml_node piece1 = vtp.child("VTKFile").child("PolyData").child("Piece");
  pugi::xml_node cells = piece1.child("CellData");
  EXPECT_STREQ(cells.attribute("GlobalIds").value(), "id");
  EXPECT_STREQ(cells.attribute("Scalars").value(), "speed");
  EXPECT_DOUBLE_EQ(numbers(cellArray(piece1, "speed"))[0], 5.0);
  EXPECT_DOUBLE_EQ(numbers(cellArray(piece1, "area"))[0], 4.0);
  EXPECT_DOUBLE_EQ(numbers(cellArray(piece1, "mass"))[0], w.mass[0]);
  EXPECT_GT(w.mass[0], 0);
  EXPECT_EQ(numbers(cellArray(piece1, "broken")), (std::vector<double>{0, 1}));
  // "floe" twice, as character codes each ended by 0.
  EXPECT_EQ(numbers(cellArray(piece1, "kind_name")), (std::vector<double>{102, 108, 111, 101, 0, 102, 108, 111, 101, 0}));
}

// output.vtk_encoding = "binary": the same arrays as the ASCII file, as zlib blocks in the
// appended section (decoded here as VTK's reader does).
TEST(VtkSeriesWriter, BinaryFramesHoldTheAsciiValues) {
  TempDir ascii, binary;
  World w;
  for (int k = 0; k < 3000; ++k) {  // over one 64 KiB block for the points
    BodySpec b;
    const double x = 3.0 * (k % 60), y = 3.0 * (k / 60);
    b.vertices = {{x, y}, {x + 2, y}, {x + 2, y + 1.5}, {x + 0.5, y + 2}};
    b.velocity = {0.01 * k, -0.5};
    b.thickness = 0.3 + 0.001 * k;
    w.addBody(b);
  }
  VtkSeriesWriter(ascii.path(), false).addFrame(w, 2.5);
  VtkSeriesWriter(binary.path(), true).addFrame(w, 2.5);
  pugi::xml_document text;
  ASSERT_TRUE(text.load_file((ascii.path() / "frames" / "frame_000000.vtp").c_str()));

  std::ifstream in(binary.path() / "frames" / "frame_000000.vtp", std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(in)), {});
  const std::string marker = "<AppendedData encoding=\"raw\">\n   _";
  const std::size_t at = file.find(marker);
  ASSERT_NE(at, std::string::npos);
  pugi::xml_document head;  // the XML before the raw section, closed
  ASSERT_TRUE(head.load_string((file.substr(0, at) + "</VTKFile>").c_str()));
  EXPECT_STREQ(head.child("VTKFile").attribute("compressor").value(), "vtkZLibDataCompressor");
  const unsigned char* appended = reinterpret_cast<const unsigned char*>(file.data() + at + marker.size());

  // Every DataArray of the ASCII file, by its place in the document, against the binary one's.
  std::vector<pugi::xml_node> textArrays, binaryArrays;
  for (pugi::xpath_node n : text.select_nodes("//Piece//DataArray")) textArrays.push_back(n.node());
  for (pugi::xpath_node n : head.select_nodes("//Piece//DataArray")) binaryArrays.push_back(n.node());
  ASSERT_EQ(textArrays.size(), binaryArrays.size());
  int decoded = 0;
  for (std::size_t a = 0; a < textArrays.size(); ++a) {
    const pugi::xml_node t = textArrays[a], b = binaryArrays[a];
    EXPECT_STREQ(t.attribute("Name").value(), b.attribute("Name").value());
    if (std::string(b.attribute("format").value()) != "appended") continue;  // kind_name stays text
    // The header's UInt64s sit at any byte offset in the file: read them by copying.
    const unsigned char* at = appended + b.attribute("offset").as_ullong();
    auto word = [&](std::uint64_t i) {
      std::uint64_t v;
      std::memcpy(&v, at + i * sizeof v, sizeof v);
      return v;
    };
    const std::uint64_t blocks = word(0), blockSize = word(1), lastSize = word(2);
    std::vector<unsigned char> raw;
    const unsigned char* data = at + (3 + blocks) * sizeof(std::uint64_t);
    for (std::uint64_t k = 0; k < blocks; ++k) {
      uLongf size = (k + 1 == blocks && lastSize) ? lastSize : blockSize;
      std::vector<unsigned char> block(size);
      ASSERT_EQ(uncompress(block.data(), &size, data, static_cast<uLong>(word(3 + k))), Z_OK);
      raw.insert(raw.end(), block.begin(), block.begin() + static_cast<std::ptrdiff_t>(size));
      data += word(3 + k);
    }
    const std::string type = b.attribute("type").value();
    std::vector<double> values;
    auto read = [&](auto zero) {
      using T = decltype(zero);
      for (std::size_t k = 0; k + sizeof(T) <= raw.size(); k += sizeof(T)) {
        T v;
        std::memcpy(&v, raw.data() + k, sizeof(T));
        values.push_back(static_cast<double>(v));
      }
    };
    if (type == "Float64") read(0.0);
    if (type == "Float32") read(0.0f);
    if (type == "Int64") read(std::int64_t{0});
    if (type == "Int32") read(std::int32_t{0});
    if (type == "UInt8") read(std::uint8_t{0});
    const std::vector<double> expected = numbers(t);
    ASSERT_EQ(values.size(), expected.size()) << t.attribute("Name").value();
    for (std::size_t k = 0; k < values.size(); ++k) ASSERT_DOUBLE_EQ(values[k], expected[k]) << t.attribute("Name").value() << " " << k;
    ++decoded;
  }
  EXPECT_GE(decoded, 11);  // points, 9 cell arrays (kind_name aside), connectivity, offsets
  EXPECT_LT(file.size(), std::filesystem::file_size(ascii.path() / "frames" / "frame_000000.vtp") / 2);
}

}  // namespace
}  // namespace gem
