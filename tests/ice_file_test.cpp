// The .ice reader and writer (framework/field/ice_file.hpp) and the atomic writes under them.
#include "framework/field/ice_file.hpp"
#include "framework/output/ice_file_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "framework/output/atomic_file.hpp"
#include "framework/api/errors.hpp"

namespace gem {
namespace {

// A fresh folder per test, removed afterwards, so tests can run in parallel.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_path = std::filesystem::temp_directory_path() /
             ("gem_ice_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + "_" + (info ? info->name() : "x"));
    std::filesystem::remove_all(m_path);
    std::filesystem::create_directories(m_path);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(m_path, ignored);
  }
  const std::filesystem::path& path() const { return m_path; }

 private:
  std::filesystem::path m_path;
};

std::string readText(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void writeText(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

BodySpec square(Real x0, Real y0, Real side, Real thickness) {
  BodySpec s;
  s.vertices = {{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}};
  s.thickness = thickness;
  return s;
}

int slotOf(const World& w, std::int64_t id) {
  for (int i = 0; i < w.size(); ++i)
    if (w.id[i] == id) return i;
  return -1;
}

// Expected values are rounded to Real first, so the float build checks the same round trip.
void expectNear(double actual, double expected) {
  const double e = static_cast<Real>(expected);
  EXPECT_NEAR(actual, e, 1e-9 * std::max(1.0, std::fabs(e)));
}

void expectObjectMatches(const IceObject& o, const World& w, int slot) {
  Vec2 v[kMaxVertices];
  const int n = w.worldVertices(slot, v);
  ASSERT_TRUE(o.hasCoordinates);
  ASSERT_EQ(static_cast<int>(o.coordinates.size()), n);
  for (int k = 0; k < n; ++k) {
    expectNear(o.coordinates[k].x, v[k].x);
    expectNear(o.coordinates[k].y, v[k].y);
  }
}

const IceObject* findObject(const IceFrame& f, std::int64_t index) {
  for (const IceObject& o : f.objects)
    if (o.index == index) return &o;
  return nullptr;
}

TEST(AtomicFile, CommitRenamesAndUncommittedLeavesNothing) {
  TempDir dir;
  const auto target = dir.path() / "out.txt";
  {
    AtomicFile f(target);
    f.stream() << "half";
    EXPECT_TRUE(std::filesystem::exists(f.tempPath()));
  }  // no commit: as if the run died here
  EXPECT_FALSE(std::filesystem::exists(target));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));

  writeText(target, "old");
  writeFileAtomically(target, "new content\n");
  EXPECT_EQ(readText(target), "new content\n");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(AtomicFile, FailureNamesThePath) {
  TempDir dir;
  const auto target = dir.path() / "missing_folder" / "out.txt";
  try {
    writeFileAtomically(target, "x");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing_folder"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file"), std::string::npos) << e.what();
  }
}

// Three frames: A moves and speeds up, B is removed, D (a vessel) is added; C never changes.
TEST(IceFile, RoundTripWritesFrameZeroWholeAndLaterOnlyChanges) {
  TempDir dir;
  const auto file = dir.path() / "frames.ice";
  World w;
  BodySpec a = square(0, 0, 2, 0.5);
  a.velocity = {1, 0};
  const int slotA = w.addBody(a);
  w.addBody(square(10, 0, 3, 0.7));  // B
  BodySpec c;
  c.kind = BodyKind::Wall;
  c.vertices = {{-5, -5}, {20, -5}, {20, -4}};
  c.thickness = 1;
  w.addBody(c);
  const std::int64_t idA = w.id[0], idB = w.id[1], idC = w.id[2];

  IceFileWriter writer(file);
  writer.addFrame(w, 0.0);
  const World frame0 = w;

  w.x[slotA] += 0.5;
  w.angle[slotA] = 0.1;
  w.vx[slotA] = 1.25;
  w.vy[2] += 1e-13;  // below the tolerance: not a change
  writer.addFrame(w, 0.5);
  const World frame1 = w;

  w.removeBodies({0, 1, 0});
  BodySpec d = square(30, 1, 1, 2.0);
  d.kind = BodyKind::Vessel;
  d.angularVelocity = 0.3;
  w.addBody(d);
  const std::int64_t idD = w.id[w.size() - 1];
  writer.addFrame(w, 1.0);
  // Frames stream to a temporary; the .ice appears whole at finish().
  EXPECT_FALSE(std::filesystem::exists(file));
  writer.finish();
  ASSERT_TRUE(std::filesystem::exists(file));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1) << "temporaries left";
  EXPECT_NE(readText(file).find("numFrames=\"3\""), std::string::npos);

  const std::vector<IceFrame> frames = readIceFile(file);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].index, 0);
  EXPECT_TRUE(frames[1].hasTime);
  EXPECT_DOUBLE_EQ(frames[1].time, 0.5);
  EXPECT_DOUBLE_EQ(frames[2].time, 1.0);

  // Frame 0: every body with every element.
  ASSERT_EQ(frames[0].objects.size(), 3u);
  for (const IceObject& o : frames[0].objects) {
    const int slot = slotOf(frame0, o.index);
    ASSERT_GE(slot, 0);
    expectObjectMatches(o, frame0, slot);
    ASSERT_TRUE(o.hasVelocity && o.hasThickness);
    expectNear(o.velocity.x, frame0.vx[slot]);
    expectNear(o.velocity.y, frame0.vy[slot]);
    expectNear(o.angularVelocity, frame0.omega[slot]);
    expectNear(o.thickness, frame0.thickness[slot]);
    EXPECT_EQ(o.kind, frame0.kind[slot]);
  }
  EXPECT_EQ(findObject(frames[0], idC)->kind, BodyKind::Wall);
  EXPECT_TRUE(findObject(frames[0], idC)->hasKind);
  EXPECT_FALSE(findObject(frames[0], idA)->hasKind);  // floe is the default, not written

  // Frame 1: only A, with its coordinates and velocity but not its unchanged thickness.
  ASSERT_EQ(frames[1].objects.size(), 1u);
  const IceObject& movedA = frames[1].objects[0];
  EXPECT_EQ(movedA.index, idA);
  expectObjectMatches(movedA, frame1, slotOf(frame1, idA));
  EXPECT_TRUE(movedA.hasVelocity);
  expectNear(movedA.velocity.x, 1.25);
  EXPECT_FALSE(movedA.hasThickness);
  EXPECT_FALSE(movedA.removed);

  // Frame 2: B removed, D complete with its kind; A and C unchanged so absent.
  ASSERT_EQ(frames[2].objects.size(), 2u);
  const IceObject* removedB = findObject(frames[2], idB);
  ASSERT_NE(removedB, nullptr);
  EXPECT_TRUE(removedB->removed);
  EXPECT_FALSE(removedB->hasCoordinates || removedB->hasVelocity || removedB->hasThickness);
  const IceObject* addedD = findObject(frames[2], idD);
  ASSERT_NE(addedD, nullptr);
  expectObjectMatches(*addedD, w, slotOf(w, idD));
  EXPECT_TRUE(addedD->hasVelocity && addedD->hasThickness);
  EXPECT_EQ(addedD->kind, BodyKind::Vessel);
  expectNear(addedD->angularVelocity, 0.3);
  expectNear(addedD->thickness, 2.0);
  EXPECT_EQ(findObject(frames[2], idA), nullptr);

  // Replaying the frames rebuilds the final state.
  std::map<std::int64_t, IceObject> state;
  for (const IceFrame& f : frames)
    for (const IceObject& o : f.objects) {
      if (o.removed) {
        state.erase(o.index);
        continue;
      }
      IceObject& s = state[o.index];
      s.index = o.index;
      if (o.hasCoordinates) s.coordinates = o.coordinates, s.hasCoordinates = true;
      if (o.hasVelocity) s.velocity = o.velocity, s.angularVelocity = o.angularVelocity;
      if (o.hasThickness) s.thickness = o.thickness;
      if (o.hasKind) s.kind = o.kind;
    }
  ASSERT_EQ(static_cast<int>(state.size()), w.size());
  for (const auto& [id, o] : state) expectObjectMatches(o, w, slotOf(w, id));

  // The initial bodies as a scenario would load them.
  const std::vector<BodySpec> bodies = readIceInitialBodies(file);
  ASSERT_EQ(bodies.size(), 3u);
  EXPECT_EQ(bodies[0].id, idA);
  expectNear(bodies[0].velocity.x, 1.0);
  EXPECT_EQ(bodies[2].kind, BodyKind::Wall);
  EXPECT_NE(bodies[1].origin.find(": object " + std::to_string(idB)), std::string::npos);
}

TEST(IceFile, ReadsThesisStyleFile) {
  TempDir dir;
  const auto file = dir.path() / "thesis.ice";
  // Capitalised root as the thesis text writes it, a repeated closing vertex, commas, a kind.
  writeText(file,
            "<IceFloeSim numFrames=\"2\">\n"
            "  <frame index=\"0\">\n"
            "    <object index=\"4\">\n"
            "      <coordinates> 0 0 2 0 2 2 0 2 0 0 </coordinates>\n"
            "      <velocity x=\"+0.5\" y=\"-1e-1\" a=\"0.25\" />\n"
            "      <thickness> 0.7 </thickness>\n"
            "    </object>\n"
            "    <object index=\"9\" kind=\"wall\">\n"
            "      <coordinates>0,-2, 5,-2, 5,-1</coordinates>\n"
            "      <thickness>1</thickness>\n"
            "    </object>\n"
            "  </frame>\n"
            "  <frame index=\"1\"><object index=\"4\"><thickness>0.6</thickness></object></frame>\n"
            "</IceFloeSim>\n");
  const std::vector<BodySpec> bodies = readIceInitialBodies(file);
  ASSERT_EQ(bodies.size(), 2u);
  EXPECT_EQ(bodies[0].id, 4);
  EXPECT_EQ(bodies[0].vertices.size(), 4u);  // the repeated closing vertex is dropped
  EXPECT_DOUBLE_EQ(bodies[0].velocity.x, 0.5);
  EXPECT_EQ(bodies[0].velocity.y, Real(-0.1));
  EXPECT_DOUBLE_EQ(bodies[0].angularVelocity, 0.25);
  EXPECT_EQ(bodies[0].thickness, Real(0.7));
  EXPECT_EQ(bodies[1].kind, BodyKind::Wall);
  EXPECT_EQ(bodies[1].vertices.size(), 3u);
  EXPECT_DOUBLE_EQ(bodies[1].velocity.x, 0.0);  // no velocity element: at rest
  const auto frames = readIceFile(file);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_FALSE(frames[1].objects[0].hasCoordinates);
  EXPECT_EQ(frames[1].objects[0].thickness, Real(0.6));
}

// Each bad input: its text, the line the message must name, and a fragment it must contain.
struct BadCase {
  const char* name;
  std::string text;
  int line;
  std::string fragment;
};

std::string object0(const std::string& body) {
  return "<iceFloeSim>\n<frame index=\"0\">\n<object index=\"5\">\n" + body + "</object>\n</frame>\n</iceFloeSim>\n";
}

const char* kGood = "<coordinates>0 0 1 0 1 1</coordinates>\n<thickness>1</thickness>\n";

TEST(IceFile, ErrorsNameFileLineAndProblem) {
  const std::vector<BadCase> cases = {
      {"wrong root", "<?xml version=\"1.0\"?>\n<floes><frame index=\"0\"/></floes>\n", 2, "<iceFloeSim>"},
      {"no frame 0", "<iceFloeSim>\n<frame index=\"1\"/>\n</iceFloeSim>\n", 1, "index 0"},
      {"no coordinates", object0("<thickness>1</thickness>\n"), 3, "object 5 in frame 0 has no <coordinates>"},
      {"no thickness", object0("<coordinates>0 0 1 0 1 1</coordinates>\n"), 3, "object 5 in frame 0 has no <thickness>"},
      {"odd count", object0("<coordinates>0 0 1 0 1</coordinates>\n<thickness>1</thickness>\n"), 4, "odd number"},
      {"two vertices", object0("<coordinates>0 0 1 0</coordinates>\n<thickness>1</thickness>\n"), 4, "3 to"},
      {"not a number", object0("<coordinates>0 0 1 0\n 1 abc</coordinates>\n<thickness>1</thickness>\n"), 5,
       "object 5: coordinate value 6 'abc' is not a number"},
      {"infinite", object0("<coordinates>0 0 1 0 1 inf</coordinates>\n<thickness>1</thickness>\n"), 4,
       "object 5: coordinate value 6 'inf' is not a finite number"},
      {"nan velocity", object0(std::string(kGood) + "<velocity x=\"nan\" y=\"0\" a=\"0\"/>\n"), 6,
       "object 5: velocity x 'nan' is not a finite number"},
      {"overflow", object0("<coordinates>0 0 1 0 1 1</coordinates>\n<thickness>1e999</thickness>\n"), 5,
       "object 5: thickness '1e999' is out of range"},
      {"bad thickness", object0("<coordinates>0 0 1 0 1 1</coordinates>\n<thickness>thick</thickness>\n"), 5,
       "object 5: thickness 'thick' is not a number"},
      {"zero thickness", object0("<coordinates>0 0 1 0 1 1</coordinates>\n<thickness>0</thickness>\n"), 5, "must be positive"},
      {"bad kind",
       "<iceFloeSim>\n<frame index=\"0\">\n<object index=\"5\" kind=\"ship\">\n" + std::string(kGood) +
           "</object>\n</frame>\n</iceFloeSim>\n",
       3, "kind='ship'"},
      {"duplicate object",
       "<iceFloeSim>\n<frame index=\"0\">\n<object index=\"5\">\n" + std::string(kGood) + "</object>\n<object index=\"5\">\n" + kGood +
           "</object>\n</frame>\n</iceFloeSim>\n",
       7, "duplicate object index 5"},
      {"bad object index",
       "<iceFloeSim>\n<frame index=\"0\">\n<object index=\"-2\">\n" + std::string(kGood) + "</object>\n</frame>\n</iceFloeSim>\n", 3,
       "non-negative integer"},
      {"numFrames mismatch",
       "<iceFloeSim numFrames=\"2\">\n<frame index=\"0\">\n<object index=\"5\">\n" + std::string(kGood) +
           "</object>\n</frame>\n</iceFloeSim>\n",
       1, "numFrames=2 but the file holds 1 frames"},
      {"duplicate frame", "<iceFloeSim>\n<frame index=\"0\"/>\n<frame index=\"0\"/>\n</iceFloeSim>\n", 3, "duplicate frame index 0"},
      {"removed in frame 0", object0(std::string(kGood) + "<removed/>\n"), 6, "frame 0"},
      // One document: nothing but comments and processing instructions outside the root element.
      {"second root", object0(kGood) + "<iceFloeSim>\n<frame index=\"0\"/>\n</iceFloeSim>\n", 9, "a second root element <iceFloeSim>"},
      {"second document", object0(kGood) + "<?xml version=\"1.0\"?>\n" + object0(kGood), 9, "an XML declaration"},
      {"text after the root", object0(kGood) + "<!-- c -->\n  trailing words\n", 10, "text 'trailing words' after the root"},
      {"text before the root", "stray\n" + object0(kGood), 1, "text 'stray' before the root"},
      {"no root", "<!-- only a comment -->\n", 1, "found no element"},
  };
  TempDir dir;
  for (const BadCase& c : cases) {
    const auto file = dir.path() / "bad.ice";
    writeText(file, c.text);
    try {
      readIceFile(file);
      ADD_FAILURE() << c.name << ": no error";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(file.string() + ":" + std::to_string(c.line) + ":"), std::string::npos) << c.name << ": " << message;
      EXPECT_NE(message.find(c.fragment), std::string::npos) << c.name << ": " << message;
    }
  }
}

TEST(IceFile, MalformedXmlReportsLineAndColumn) {
  TempDir dir;
  const auto file = dir.path() / "broken.ice";
  // Line 4 closes <coordinates> with </coordinate>; pugixml points at the closing tag's name,
  // column 33 (after the 6 spaces, the 13-character <coordinates>, "0 0 1 0 1 1" and "</").
  writeText(file,
            "<iceFloeSim>\n"
            "  <frame index=\"0\">\n"
            "    <object index=\"0\">\n"
            "      <coordinates>0 0 1 0 1 1</coordinate>\n"
            "    </object>\n"
            "  </frame>\n"
            "</iceFloeSim>\n");
  try {
    readIceFile(file);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file.string() + ":4:33: malformed XML"), std::string::npos) << message;
  }
  // Unterminated attribute value on line 2, reported where the parser gave up.
  writeText(file, "<iceFloeSim>\n  <frame index=\"0>\n");
  try {
    readIceFile(file);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string() + ":"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("malformed XML"), std::string::npos) << e.what();
  }
}

TEST(IceFile, ValueErrorsPointAtTheValue) {
  TempDir dir;
  const auto file = dir.path() / "value.ice";
  // The bad value sits on line 6, column 4 (after three spaces), inside a multi-line list.
  writeText(file, object0("<coordinates>\n   0 0\n   x1 0 1 1\n</coordinates>\n<thickness>1</thickness>\n"));
  try {
    readIceFile(file);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string() + ":6:4: object 5: coordinate value 3 'x1'"), std::string::npos) << e.what();
  }
}

TEST(IceFile, MissingFileIsAnInputError) {
  TempDir dir;
  const auto file = dir.path() / "nowhere.ice";
  try {
    readIceInitialBodies(file);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nowhere.ice"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no such .ice file"), std::string::npos) << e.what();
  }
}

TEST(IceFile, UnfinishedWriterLeavesNoFile) {
  TempDir dir;
  {
    World w;
    w.addBody(square(0, 0, 1, 1));
    IceFileWriter writer(dir.path() / "frames.ice");
    writer.addFrame(w, 0);
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace gem
