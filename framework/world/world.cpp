#include "framework/world/world.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <thread>
#include <cmath>
#include <stdexcept>
#include <type_traits>

namespace gem {

const char* bodyKindName(BodyKind kind) {
  switch (kind) {
    case BodyKind::Floe:
      return "floe";
    case BodyKind::Vessel:
      return "vessel";
    case BodyKind::Wall:
      return "wall";
  }
  return "unknown";
}

template <class Trig>
static int addRow(World& w, const BodySpec& spec);

int World::addBody(const BodySpec& spec) { return addRow<LibmTrig>(*this, spec); }
int World::addPiece(const BodySpec& spec) { return addRow<PortableTrig>(*this, spec); }

template <class Trig>
static int addRow(World& w, const BodySpec& spec) {
  const int n = static_cast<int>(spec.vertices.size());
  if (n < 3 || n > kMaxVertices) throw std::invalid_argument("World::addBody: vertex count out of range");
  const int slot = w.size();
  w.id.push_back(spec.id >= 0 ? spec.id : w.nextId);
  w.nextId = std::max(w.nextId, w.id.back() + 1);
  w.kind.push_back(spec.kind);
  w.vertexCount.push_back(n);
  w.localVertices.resize(w.localVertices.size() + kMaxVertices, Vec2{0, 0});
  // The vessel's mass is set by its owner (addVessel).
  const BodyMassRow row = bodyMassRow<Trig>(spec.vertices.data(), n, spec.thickness, spec.kind == BodyKind::Wall, w.local(slot));
  w.x.push_back(row.centroid.x);
  w.y.push_back(row.centroid.y);
  w.angle.push_back(0);
  w.vx.push_back(spec.velocity.x);
  w.vy.push_back(spec.velocity.y);
  w.omega.push_back(spec.angularVelocity);
  w.area.push_back(row.area);
  w.thickness.push_back(spec.thickness);
  w.mass.push_back(row.mass);
  w.invMass.push_back(row.invMass);
  w.gyration2.push_back(row.gyration2);
  w.gyrationX2.push_back(row.gyrationX2);
  w.gyrationY2.push_back(row.gyrationY2);
  w.invInertia.push_back(row.invInertia);
  w.principalAngle.push_back(row.principalAngle);
  w.radius.push_back(row.radius);
  return slot;
}

// Rows before the first removed one stay where they are, and the kept runs between removed rows
// move as whole blocks (memmove): a break removes a few floes from a world of up to 10^6.
template <class T>
static void keepIf(std::vector<T>& v, const std::vector<char>& remove, size_t first, size_t stride = 1) {
  size_t out = first, i = first;
  while (i < remove.size()) {
    if (remove[i]) {
      ++i;
      continue;
    }
    size_t end = i;
    while (end < remove.size() && !remove[end]) ++end;
    std::copy(v.begin() + static_cast<std::ptrdiff_t>(i * stride), v.begin() + static_cast<std::ptrdiff_t>(end * stride),
              v.begin() + static_cast<std::ptrdiff_t>(out * stride));
    out += end - i;
    i = end;
  }
  v.resize(out * stride);
}

// keepIf over [first, n) cut into ranges that may run at once (removeBodies on the pool): range t,
// rows [begin[t], begin[t + 1]), reads and writes only its own rows. Its kept rows move down by the
// rows removed before begin[t] (removedBefore[t]), so its first removedBefore[t] kept rows land in
// range t - 1's rows, which that range may still be reading: they are set aside before the ranges
// run and put in place after. A break removes a few rows, so a few rows are set aside.
template <class T>
class RangedCompaction {
 public:
  RangedCompaction(std::vector<T>& v, const std::vector<char>& remove, const std::vector<size_t>& begin,
                   const std::vector<size_t>& removedBefore, size_t stride)
      : m_v(v), m_remove(remove), m_begin(begin), m_removedBefore(removedBefore), m_stride(stride), m_headsFrom(begin.size(), 0) {
    for (size_t t = 0; t + 1 < begin.size(); ++t) {
      m_headsFrom[t] = m_heads.size() / stride;
      size_t need = removedBefore[t];
      for (size_t i = begin[t]; i < begin[t + 1] && need > 0; ++i) {
        if (remove[i]) continue;
        const auto row = v.begin() + static_cast<std::ptrdiff_t>(i * stride);
        m_heads.insert(m_heads.end(), row, row + static_cast<std::ptrdiff_t>(stride));
        --need;
      }
    }
    m_headsFrom.back() = m_heads.size() / stride;
  }
  // Range t's kept rows but its heads, in runs, to begin[t] on.
  void range(size_t t) {
    size_t skip = m_headsFrom[t + 1] - m_headsFrom[t], out = m_begin[t], i = m_begin[t];
    const size_t end = m_begin[t + 1];
    while (i < end) {
      if (m_remove[i]) {
        ++i;
        continue;
      }
      if (skip > 0) {
        --skip, ++i;
        continue;
      }
      size_t runEnd = i;
      while (runEnd < end && !m_remove[runEnd]) ++runEnd;
      std::copy(m_v.begin() + static_cast<std::ptrdiff_t>(i * m_stride), m_v.begin() + static_cast<std::ptrdiff_t>(runEnd * m_stride),
                m_v.begin() + static_cast<std::ptrdiff_t>(out * m_stride));
      out += runEnd - i;
      i = runEnd;
    }
  }
  // Once every range is done: the heads to their places, and the array cut to the kept rows.
  void finish() {
    for (size_t t = 0; t + 1 < m_begin.size(); ++t) {
      const size_t to = m_begin[t] - m_removedBefore[t];
      std::copy(m_heads.begin() + static_cast<std::ptrdiff_t>(m_headsFrom[t] * m_stride),
                m_heads.begin() + static_cast<std::ptrdiff_t>(m_headsFrom[t + 1] * m_stride),
                m_v.begin() + static_cast<std::ptrdiff_t>(to * m_stride));
    }
    const size_t n = m_begin.back(), removed = m_removedBefore.back();
    m_v.resize((n - removed) * m_stride);
  }

 private:
  std::vector<T>& m_v;
  const std::vector<char>& m_remove;
  const std::vector<size_t>& m_begin;
  const std::vector<size_t>& m_removedBefore;
  size_t m_stride;
  std::vector<T> m_heads;
  std::vector<size_t> m_headsFrom;  // range t's heads are rows [m_headsFrom[t], m_headsFrom[t + 1]) of m_heads
};

void World::removeBodies(const std::vector<char>& remove, const TaskRunner& forEachTask) {
  const size_t f = static_cast<size_t>(std::find_if(remove.begin(), remove.end(), [](char r) { return r != 0; }) - remove.begin());
  if (f == remove.size()) return;
  std::vector<std::function<void()>> small = {[&] { keepIf(id, remove, f); }, [&] { keepIf(kind, remove, f); },
                                              [&] { keepIf(vertexCount, remove, f); }};
  for (std::vector<Real>* v : {&x, &y, &angle, &vx, &vy, &omega, &area, &thickness, &mass, &invMass, &invInertia, &gyration2, &gyrationX2,
                               &gyrationY2, &principalAngle, &radius})
    small.push_back([v, &remove, f] { keepIf(*v, remove, f); });
  // Inside a threaded CPU step: an array a task, and the vertices (60 % of the bytes) in ranges of
  // rows besides. As one task they took 4 ms a break at 10^5 floes while the other threads waited.
  // Every row lands at its own place, so the result is the same on any thread count.
  if (forEachTask) {
    constexpr size_t kVertexRanges = 16;
    const size_t n = remove.size();
    std::vector<size_t> begin(kVertexRanges + 1), removedBefore(kVertexRanges + 1, 0);
    for (size_t t = 0; t <= kVertexRanges; ++t) begin[t] = f + (n - f) * t / kVertexRanges;
    for (size_t t = 0; t < kVertexRanges; ++t) {
      const auto from = remove.begin() + static_cast<std::ptrdiff_t>(begin[t]),
                 to = remove.begin() + static_cast<std::ptrdiff_t>(begin[t + 1]);
      removedBefore[t + 1] = removedBefore[t] + static_cast<size_t>(std::count_if(from, to, [](char r) { return r != 0; }));
    }
    RangedCompaction<Vec2> vertices(localVertices, remove, begin, removedBefore, kMaxVertices);
    const size_t arrays = small.size();
    forEachTask(static_cast<int>(arrays + kVertexRanges), [&](int a) {
      const auto task = static_cast<size_t>(a);
      if (task < arrays)
        small[task]();
      else
        vertices.range(task - arrays);
    });
    vertices.finish();
    return;
  }
  // Otherwise, a break in a world of 10^5 floes or more: the vertices are compacted while helper
  // threads do the other arrays (at 10^6 floes one thread took 84 ms a break).
  const size_t moved = remove.size() - f;
  const unsigned helpers = moved < 100000 ? 0u : std::min(3u, std::max(1u, std::thread::hardware_concurrency()) - 1);
  std::vector<std::thread> threads;
  for (unsigned t = 0; t < helpers; ++t)
    threads.emplace_back([&small, t, helpers] {
      for (size_t a = t; a < small.size(); a += helpers) small[a]();
    });
  keepIf(localVertices, remove, f, kMaxVertices);
  if (helpers == 0)
    for (auto& compact : small) compact();
  for (std::thread& t : threads) t.join();
}

// out[k] = v[order[k]] (stride elements each) for k in [k0, k1).
template <class T>
static void gatherOrder(std::vector<T>& out, const std::vector<T>& v, const std::vector<int>& order, size_t stride, size_t k0, size_t k1) {
  for (size_t k = k0; k < k1; ++k)
    for (size_t s = 0; s < stride; ++s) out[k * stride + s] = v[static_cast<size_t>(order[k]) * stride + s];
}

void World::permute(const std::vector<int>& order, const TaskRunner& forEachTask, PermuteRoom* room) {
  // With a runner (a threaded CPU step) an array a task, and the vertices (60 % of the bytes) in
  // ranges of bodies besides: at 10^5 floes the re-sort every 200 steps (docs/model.md 8) took
  // 30 to 40 ms on one thread, as long as 40 steps on 16. Every element lands at its own place,
  // so any thread count gives the same world.
  const size_t n = order.size();
  PermuteRoom local;
  PermuteRoom& into = room ? *room : local;
  // Each array is gathered into its room, which then holds it, and the room the old array: with
  // a caller's room both keep their memory from one permute to the next.
  auto prepare = [](auto& out, const auto& v) {
    out.reserve(v.capacity());  // room kept: else the next break's addBody regrows every array
    out.resize(v.size());
  };
  std::vector<std::function<void()>> tasks;
  auto whole = [&](auto& v, auto& out) {
    tasks.push_back([&v, &out, &order, &prepare, n] {
      prepare(out, v);
      gatherOrder(out, v, order, 1, 0, n);
      v.swap(out);
    });
  };
  whole(id, into.id), whole(kind, into.kind), whole(vertexCount, into.vertexCount);
  const std::array realArrays{&x,    &y,       &angle,      &vx,        &vy,         &omega,      &area,           &thickness,
                              &mass, &invMass, &invInertia, &gyration2, &gyrationX2, &gyrationY2, &principalAngle, &radius};
  static_assert(realArrays.size() == std::tuple_size_v<decltype(PermuteRoom::reals)>, "a room for every Real array");
  for (size_t r = 0; r < realArrays.size(); ++r) whole(*realArrays[r], into.reals[r]);
  std::vector<Vec2>& vertices = into.vertices;
  prepare(vertices, localVertices);
  const int ranges = forEachTask && n >= 16384 ? 16 : 1;
  for (int range = 0; range < ranges; ++range)
    tasks.push_back([&, range] {
      gatherOrder(vertices, localVertices, order, kMaxVertices, n * static_cast<size_t>(range) / static_cast<size_t>(ranges),
                  n * static_cast<size_t>(range + 1) / static_cast<size_t>(ranges));
    });
  const auto run = [&](int t) { tasks[static_cast<size_t>(t)](); };
  if (forEachTask)
    forEachTask(static_cast<int>(tasks.size()), run);
  else
    for (int t = 0; t < static_cast<int>(tasks.size()); ++t) run(t);
  localVertices.swap(vertices);
}

std::vector<int> World::curveOrder(const TaskRunner& forEachTask) const {
  // With a runner, the bounds, the keys and each pass of the sort over 16 ranges of slots: it was
  // all on the calling thread, 1.1 ms a re-sort at 10^5 bodies on one AMD core while the pool
  // waited (docs/performance.md 3.20).
  const int n = size();
  std::vector<int> order(static_cast<size_t>(n));
  if (n == 0) return order;
  const int ranges = forEachTask && n >= 16384 ? 16 : 1;
  auto rangeOf = [&](int r) {
    return std::pair{static_cast<int>(static_cast<long>(n) * r / ranges), static_cast<int>(static_cast<long>(n) * (r + 1) / ranges)};
  };
  auto overRanges = [&](const std::function<void(int)>& task) {
    if (ranges > 1)
      forEachTask(ranges, task);
    else
      task(0);
  };
  // The box of all centroids: each range's, then theirs (min and max give the same whatever the
  // grouping, a NaN skipped either way).
  struct Bounds {
    Real x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  };
  std::vector<Bounds> part(static_cast<size_t>(ranges));
  overRanges([&](int r) {
    Bounds b;
    const auto [begin, end] = rangeOf(r);
    for (int i = begin; i < end; ++i) {
      b.x0 = std::min(b.x0, x[i]), b.x1 = std::max(b.x1, x[i]);
      b.y0 = std::min(b.y0, y[i]), b.y1 = std::max(b.y1, y[i]);
    }
    part[static_cast<size_t>(r)] = b;
  });
  Bounds all;
  for (const Bounds& b : part)
    all.x0 = std::min(all.x0, b.x0), all.x1 = std::max(all.x1, b.x1), all.y0 = std::min(all.y0, b.y0), all.y1 = std::max(all.y1, b.y1);
  const Real scale = curveScale(all.x0, all.y0, all.x1, all.y1);
  // Each slot's key and the slot in one word, the key above: sorted, the words are in key order,
  // ties in slot order, and a pass reads the words in order (read by slot, the keys were a random
  // read of the whole array in every pass after the first).
  // Kept by the calling thread from one re-sort to the next, so that a re-sort does not fault in
  // fresh pages (1.6 MB at 10^5 bodies). Named through references: a task on another thread that
  // named the thread_local itself would get that thread's.
  thread_local std::vector<std::uint64_t> keptWords, keptSorted;
  std::vector<std::uint64_t>& word = keptWords;
  std::vector<std::uint64_t>& sorted = keptSorted;
  word.resize(static_cast<size_t>(n)), sorted.resize(static_cast<size_t>(n));
  overRanges([&](int r) {
    const auto [begin, end] = rangeOf(r);
    for (int i = begin; i < end; ++i)
      word[static_cast<size_t>(i)] = std::uint64_t{curveKey(x[i], y[i], all.x0, all.y0, scale)} << 32 | static_cast<std::uint32_t>(i);
  });
  // A stable sort by key of the slots in slot order, so ties stay in slot order: four passes of a
  // counting sort on 8 bits each of the key (a least-significant-digit radix sort; at 10^5 bodies
  // a tenth of std::sort's time). A pass counts each range's digits, places each range's share of a
  // digit after the earlier digits' and the earlier ranges' share of its own (on the calling
  // thread, reading every range's counts digit by digit), and each range then moves its words in
  // order: the same places as one pass over all the slots. Three passes of 11 bits made that
  // placing 2,048 digits by 16 ranges, counts the other threads had just written: 0.65 ms a re-sort
  // on two AMD threads, more than the rest of the sort (docs/performance.md 3.22).
  constexpr int kDigitBits = 8, kDigits = 1 << kDigitBits;
  std::vector<std::array<int, kDigits>> start(static_cast<size_t>(ranges));
  for (const int shift : {32, 32 + kDigitBits, 32 + 2 * kDigitBits, 32 + 3 * kDigitBits}) {
    auto digitOf = [&](std::uint64_t w) { return static_cast<size_t>((w >> shift) & (kDigits - 1)); };
    overRanges([&](int r) {
      std::array<int, kDigits>& count = start[static_cast<size_t>(r)];
      count.fill(0);
      const auto [begin, end] = rangeOf(r);
      for (int k = begin; k < end; ++k) ++count[digitOf(word[static_cast<size_t>(k)])];
    });
    int placed = 0;
    for (int d = 0; d < kDigits; ++d)
      for (std::array<int, kDigits>& count : start) {
        const int c = count[static_cast<size_t>(d)];
        count[static_cast<size_t>(d)] = placed;
        placed += c;
      }
    overRanges([&](int r) {
      std::array<int, kDigits>& at = start[static_cast<size_t>(r)];
      const auto [begin, end] = rangeOf(r);
      for (int k = begin; k < end; ++k) {
        const std::uint64_t w = word[static_cast<size_t>(k)];
        sorted[static_cast<size_t>(at[digitOf(w)]++)] = w;
      }
    });
    word.swap(sorted);
  }
  overRanges([&](int r) {
    const auto [begin, end] = rangeOf(r);
    for (int k = begin; k < end; ++k) order[static_cast<size_t>(k)] = static_cast<int>(word[static_cast<size_t>(k)] & 0xffffffffu);
  });
  return order;
}

double World::floeMass() const {
  double total = 0;
  for (int i = 0; i < size(); ++i)
    if (kind[i] == BodyKind::Floe) total += mass[i];
  return total;
}

int World::count(BodyKind k) const {
  int c = 0;
  for (BodyKind b : kind) c += (b == k);
  return c;
}

}  // namespace gem
