// World: removing bodies keeps the survivors' order and every array in step (a break in a world of
// 10^5 bodies or more compacts the arrays on helper threads, which this also covers).
#include "framework/world/world.hpp"

#include <gtest/gtest.h>

#include <vector>

using namespace gem;

namespace {

World squares(int n) {
  World w;
  BodySpec s;
  for (int i = 0; i < n; ++i) {
    const Real x = 3.0 * i, side = 1.0 + (i % 7) * 0.25;  // sizes vary, so the rows differ
    s.vertices = {{x, 0}, {x + side, 0}, {x + side, side}, {x, side}};
    s.thickness = 0.5 + (i % 3) * 0.1;
    w.addBody(s);
  }
  return w;
}

// Every array of `after` is `before` without the removed rows, in order.
void expectCompacted(const World& before, const World& after, const std::vector<char>& remove) {
  int k = 0;
  for (int i = 0; i < before.size(); ++i) {
    if (remove[i]) continue;
    ASSERT_LT(k, after.size());
    ASSERT_EQ(after.id[k], before.id[i]) << "row " << k;
    ASSERT_EQ(after.kind[k], before.kind[i]);
    ASSERT_EQ(after.vertexCount[k], before.vertexCount[i]);
    for (int v = 0; v < kMaxVertices; ++v) {
      ASSERT_EQ(after.local(k)[v].x, before.local(i)[v].x);
      ASSERT_EQ(after.local(k)[v].y, before.local(i)[v].y);
    }
    for (auto field : {&World::x, &World::y, &World::angle, &World::vx, &World::vy, &World::omega, &World::area, &World::thickness,
                       &World::mass, &World::invMass, &World::invInertia, &World::gyration2, &World::gyrationX2, &World::gyrationY2,
                       &World::principalAngle, &World::radius})
      ASSERT_EQ((after.*field)[k], (before.*field)[i]) << "row " << k;
    ++k;
  }
  EXPECT_EQ(k, after.size());
}

}  // namespace

TEST(World, RemoveBodiesKeepsTheSurvivorsInOrder) {
  const World before = squares(500);
  std::vector<char> remove(before.size(), 0);
  for (int i : {0, 1, 17, 250, 251, 499}) remove[i] = 1;
  World after = before;
  after.removeBodies(remove);
  expectCompacted(before, after, remove);
}

TEST(World, RemoveBodiesFromALargeWorldUsesHelpersAndKeepsEveryArray) {
  const World before = squares(160000);  // past the 10^5 rows moved at which helpers compact
  std::vector<char> remove(before.size(), 0);
  for (int i : {5, 6, 40000, 99999, 159999}) remove[i] = 1;
  World after = before;
  after.removeBodies(remove);
  expectCompacted(before, after, remove);
  std::vector<char> none(after.size(), 0);
  World same = after;
  same.removeBodies(none);  // nothing flagged: nothing changes
  EXPECT_EQ(same.id, after.id);
}
