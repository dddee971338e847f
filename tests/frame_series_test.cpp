// readFrameSeries: a hand-written three-frame .ice with a moved body, a removal and a new piece.
#include <gtest/gtest.h>

#include "framework/analysis/frame_series.hpp"
#include "framework/api/errors.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::TempDir;

namespace {

constexpr const char* kThreeFrames = R"(<iceFloeSim numFrames="3">
  <frame index="0" time="0">
    <object index="1" kind="vessel"><coordinates>0 0 4 0 4 2 0 2</coordinates><velocity x="1" y="0" a="0"/><thickness>5</thickness></object>
    <object index="2"><coordinates>10 0 12 0 11 2</coordinates><thickness>0.5</thickness></object>
    <object index="3"><coordinates>20 0 22 0 21 2</coordinates><thickness>0.7</thickness></object>
  </frame>
  <frame index="1" time="0.5">
    <object index="1"><coordinates>1 0 5 0 5 2 1 2</coordinates></object>
    <object index="3"><removed/></object>
    <object index="4"><coordinates>20 0 21 0 21 1</coordinates><velocity x="0" y="2" a="0.1"/><thickness>0.7</thickness></object>
  </frame>
  <frame index="2" time="1">
    <object index="2"><velocity x="0.5" y="0" a="0"/><thickness>0.6</thickness></object>
  </frame>
</iceFloeSim>
)";

std::vector<std::int64_t> idsOf(const FrameState& f) {
  std::vector<std::int64_t> ids;
  for (const FrameBody& b : f.bodies) ids.push_back(b.id);
  return ids;
}

}  // namespace

TEST(FrameSeries, AccumulatesChangesRemovalsAndPieces) {
  TempDir dir;
  const std::vector<FrameState> frames = readFrameSeries(dir.write("frames.ice", kThreeFrames));
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_DOUBLE_EQ(frames[1].time, 0.5);
  EXPECT_EQ(idsOf(frames[0]), (std::vector<std::int64_t>{1, 2, 3}));
  EXPECT_EQ(idsOf(frames[1]), (std::vector<std::int64_t>{1, 2, 4}));
  EXPECT_EQ(idsOf(frames[2]), (std::vector<std::int64_t>{1, 2, 4}));

  // The vessel moved in frame 1 and kept its kind, velocity and thickness.
  const FrameBody& vessel = frames[2].bodies[0];
  EXPECT_EQ(vessel.kind, BodyKind::Vessel);
  EXPECT_DOUBLE_EQ(vessel.vertices[0].x, 1);
  EXPECT_DOUBLE_EQ(vessel.velocity.x, 1);
  EXPECT_DOUBLE_EQ(vessel.thickness, 5);
  EXPECT_DOUBLE_EQ(frames[0].bodies[0].vertices[0].x, 0);  // earlier frames keep their own state
  EXPECT_FALSE(vessel.piece);

  // Floe 2 changed only velocity and thickness in frame 2; its shape stays.
  EXPECT_DOUBLE_EQ(frames[1].bodies[1].thickness, 0.5);
  EXPECT_DOUBLE_EQ(frames[2].bodies[1].thickness, 0.6);
  EXPECT_DOUBLE_EQ(frames[2].bodies[1].velocity.x, 0.5);
  EXPECT_DOUBLE_EQ(frames[2].bodies[1].vertices[2].y, 2);

  // The piece appeared in frame 1 with every element.
  const FrameBody& piece = frames[1].bodies[2];
  EXPECT_TRUE(piece.piece);
  EXPECT_EQ(piece.kind, BodyKind::Floe);
  EXPECT_EQ(piece.vertices.size(), 3u);
  EXPECT_DOUBLE_EQ(piece.velocity.y, 2);
  EXPECT_DOUBLE_EQ(piece.angularVelocity, Real(0.1));
}

TEST(FrameSeries, MissingFileNamesItAndTheFix) {
  TempDir dir;
  try {
    readFrameSeries(dir.path() / "frames.ice");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frames.ice"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("output.formats"), std::string::npos);
  }
}

TEST(FrameSeries, NewBodyWithoutCoordinatesIsRefused) {
  TempDir dir;
  const auto file = dir.write("frames.ice", R"(<iceFloeSim numFrames="2">
  <frame index="0"><object index="1"><coordinates>0 0 1 0 0 1</coordinates><thickness>1</thickness></object></frame>
  <frame index="1"><object index="9"><velocity x="1" y="0" a="0"/></object></frame>
</iceFloeSim>)");
  EXPECT_THROW(readFrameSeries(file), InputError);
}
