// The ParaView writer (framework/output/vtk_writer.hpp): parse what it wrote and check the structure.
#include "framework/output/vtk_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
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

}  // namespace
}  // namespace gem
