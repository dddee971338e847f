// World: removing bodies keeps the survivors' order and every array in step (a break in a world of
// 10^5 bodies or more compacts the arrays on helper threads, which this also covers); the re-sort's
// order and permutation.
#include "framework/world/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <utility>
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

// The re-sort (CpuStepper's every 200 steps): World::curveOrder is the slots sorted by their
// Morton key, ties in slot order, on one thread or as tasks on a runner, and World::permute moves
// every array's row k to order[k]'s, on one thread or as tasks (past 16,384 bodies the vertices go
// in ranges too).
TEST(World, CurveOrderAndPermuteOnOneThreadOrAsTasks) {
  World before = squares(40000);
  // Positions scattered so that the order changes, several bodies on one spot so that keys tie.
  for (int i = 0; i < before.size(); ++i) {
    const unsigned h = static_cast<unsigned>(i / 3) * 2654435761u;
    before.x[i] = static_cast<Real>(h % 4096u), before.y[i] = static_cast<Real>((h >> 12) % 4096u);
  }
  const std::vector<int> order = before.curveOrder();
  Real x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (int i = 0; i < before.size(); ++i)
    x0 = std::min(x0, before.x[i]), x1 = std::max(x1, before.x[i]), y0 = std::min(y0, before.y[i]), y1 = std::max(y1, before.y[i]);
  const Real scale = curveScale(x0, y0, x1, y1);
  std::vector<std::pair<std::uint32_t, int>> keys;
  for (int i = 0; i < before.size(); ++i) keys.emplace_back(curveKey(before.x[i], before.y[i], x0, y0, scale), i);
  std::sort(keys.begin(), keys.end());
  ASSERT_EQ(order.size(), keys.size());
  int ties = 0;
  for (size_t k = 0; k < keys.size(); ++k) {
    ASSERT_EQ(order[k], keys[k].second) << "position " << k;
    ties += k > 0 && keys[k].first == keys[k - 1].first;
  }
  EXPECT_GT(ties, 1000) << "no tied keys: the slot order of ties went untested";
  int orderTasks = 0;
  const std::vector<int> pooledOrder = before.curveOrder([&](int count, const std::function<void(int)>& task) {
    orderTasks = count;
    for (int t = count - 1; t >= 0; --t) task(t);  // any order of the tasks gives the same order
  });
  EXPECT_GT(orderTasks, 1) << "the curve order was not split into ranges";
  EXPECT_EQ(pooledOrder, order) << "the curve order differs as tasks";

  World alone = before;
  alone.x.reserve(2 * alone.x.size()), alone.localVertices.reserve(2 * alone.localVertices.size());
  const size_t roomX = alone.x.capacity(), roomVertices = alone.localVertices.capacity();
  alone.permute(order);
  // The arrays keep their room: exact-size arrays after every re-sort made the next break's
  // addBody regrow (copy) all of them, 30 ms at 10^5 floes.
  EXPECT_GE(alone.x.capacity(), roomX);
  EXPECT_GE(alone.localVertices.capacity(), roomVertices);
  int tasks = 0;
  World pooled = before;
  pooled.permute(order, [&](int count, const std::function<void(int)>& task) {
    tasks = count;
    for (int t = count - 1; t >= 0; --t) task(t);  // any order of the tasks gives the same world
  });
  EXPECT_GT(tasks, 19 + 1) << "the vertices were not split into ranges";
  const std::vector<char> keepAll(before.size(), 0);
  for (const World* w : {&alone, &pooled})  // row k of the result is row order[k] of before
    for (size_t k = 0; k < order.size(); ++k) ASSERT_EQ(w->id[k], before.id[static_cast<size_t>(order[k])]);
  expectCompacted(alone, pooled, keepAll);  // nothing removed: every array equal row by row
  std::vector<int> inverse(order.size());
  for (size_t k = 0; k < order.size(); ++k) inverse[static_cast<size_t>(order[k])] = static_cast<int>(k);
  alone.permute(inverse);
  expectCompacted(before, alone, keepAll);  // and back again: every array moved with its row

  // With a kept room (the CPU stepper's re-sorts), the second and third permutes write over the
  // arrays the earlier ones left, one of them after the world grew by a body: the same worlds.
  World::PermuteRoom room;
  World roomed = before;
  roomed.permute(order, nullptr, &room);
  expectCompacted(pooled, roomed, keepAll);
  roomed.permute(inverse, nullptr, &room);
  expectCompacted(before, roomed, keepAll);
  World grown = before;
  BodySpec extra;
  extra.vertices = {{-10, -10}, {-8, -10}, {-8, -8}, {-10, -8}};
  extra.thickness = 0.7;
  grown.addBody(extra), roomed.addBody(extra);
  std::vector<int> reversed(static_cast<size_t>(grown.size()));
  for (size_t k = 0; k < reversed.size(); ++k) reversed[k] = grown.size() - 1 - static_cast<int>(k);
  grown.permute(reversed);
  roomed.permute(reversed, nullptr, &room);
  expectCompacted(grown, roomed, std::vector<char>(static_cast<size_t>(grown.size()), 0));
}

// Bodies of 3 to 24 vertices, permuted again and again through one kept room (the CPU stepper's
// re-sorts), on one thread and as tasks: every array must equal a permute without a room, the
// unused vertices of each row zero included, and a removal must keep every row whole.
TEST(World, KeptRoomsAndRemovalsKeepRowsOfEveryVertexCountWhole) {
  World w;
  BodySpec s;
  for (int i = 0; i < 20000; ++i) {
    const int sides = 3 + (i * 7) % 22;  // 3 .. 24
    s.vertices.clear();
    for (int k = 0; k < sides; ++k) {
      const Real a = 2 * 3.14159265358979 * k / sides;
      s.vertices.push_back({3.0 * i + std::cos(a), std::sin(a)});
    }
    w.addBody(s);
  }
  auto asTasks = [](int count, const std::function<void(int)>& task) {
    for (int t = count - 1; t >= 0; --t) task(t);
  };
  World::PermuteRoom room, pooledRoom;
  World roomed = w, pooled = w;
  unsigned h = 12345;
  for (int round = 0; round < 4; ++round) {
    std::vector<int> order(static_cast<size_t>(w.size()));
    for (int k = 0; k < w.size(); ++k) order[static_cast<size_t>(k)] = k;
    for (size_t k = order.size() - 1; k > 0; --k) {  // a shuffle, the same for all three worlds
      h = h * 1664525u + 1013904223u;
      std::swap(order[k], order[h % (k + 1)]);
    }
    w.permute(order);
    roomed.permute(order, nullptr, &room);
    pooled.permute(order, asTasks, &pooledRoom);
    const std::vector<char> keepAll(static_cast<size_t>(w.size()), 0);
    expectCompacted(w, roomed, keepAll);
    expectCompacted(w, pooled, keepAll);
  }
  for (int i = 0; i < w.size(); ++i)
    for (int v = w.vertexCount[i]; v < kMaxVertices; ++v) ASSERT_EQ(roomed.local(i)[v].x, 0) << "body " << i << " vertex " << v;
  // A break's compaction (World::removeBodies), on one thread and as tasks (ranges of rows).
  std::vector<char> remove(static_cast<size_t>(w.size()), 0);
  for (int i = 0; i < w.size(); ++i) remove[static_cast<size_t>(i)] = i % 3 == 1 || (i > 9000 && i < 9100);
  World alone = w, tasked = w;
  alone.removeBodies(remove);
  tasked.removeBodies(remove, asTasks);
  expectCompacted(w, alone, remove);
  expectCompacted(w, tasked, remove);
}
