#include "broadphase/kept_list/neighbour_list.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "framework/api/errors.hpp"

namespace gem {

bool NeighbourList::update(const World& world) {
  if (!m_valid) return true;
  const int n = world.size();
  if (n != static_cast<int>(m_x0.size())) return true;
  const Real* x = world.x.data();
  const Real* y = world.y.data();
  const Real* angle = world.angle.data();
  const Real* radius = world.radius.data();
  const std::int64_t* id = world.id.data();
  const Real limit = kRebuildTrigger * m_skin / 2;
  for (int i = 0; i < n; ++i) {
    // A reorder or an in-place replacement without invalidate() would make the list point at the
    // wrong bodies: the ids guard against it for the price of one load per body.
    if (id[i] != m_id0[i]) return true;
    if (m_direct[i]) continue;  // its pairs are found afresh every step
    const Real dx = x[i] - m_x0[i], dy = y[i] - m_y0[i];
    // The farthest a point at distance R from the centroid moves under a turn of da is the chord
    // 2 R |sin(da / 2)| <= R |da wrapped to [-pi, pi]|: an angle that was wrapped by the motion code
    // (a jump of 2 pi) then counts as no turn, as it should. The wrap is rare, so it is branched.
    Real da = std::fabs(angle[i] - m_angle0[i]);
    if (da > kPi) da = std::fabs(std::remainder(da, Real(2) * kPi));
    if (std::sqrt(dx * dx + dy * dy) + radius[i] * da > limit) {
      m_direct[i] = 1;
      m_directList.push_back(i);
      if (static_cast<int>(m_directList.size()) > kMaxDirect) return true;
    }
  }
  return false;
}

void NeighbourList::begin() { m_raw.clear(); }

// A counting sort by a (O(bodies + pairs)), then an insertion sort of each row by b: rows hold a
// handful of pairs, so this beats std::sort's log factor at every rebuild.
void NeighbourList::sortRaw(int bodyCount) {
  m_pairs.resize(m_raw.size());
  m_count.assign(static_cast<size_t>(bodyCount) + 1, 0);
  for (const ListedPair& p : m_raw) ++m_count[p.a + 1];
  for (int k = 0; k < bodyCount; ++k) m_count[k + 1] += m_count[k];
  for (const ListedPair& p : m_raw) m_pairs[m_count[p.a]++] = p;
  // m_count[a] is now the end of row a, and the start of row a + 1.
  int begin = 0;
  for (int a = 0; a < bodyCount; ++a) {
    const int end = m_count[a];
    for (int k = begin + 1; k < end; ++k) {
      const ListedPair v = m_pairs[k];
      int q = k - 1;
      while (q >= begin && m_pairs[q].b > v.b) {
        m_pairs[q + 1] = m_pairs[q];
        --q;
      }
      m_pairs[q + 1] = v;
    }
    begin = end;
  }
}

void NeighbourList::finish(const World& world) {
  const int n = world.size();
  bool sorted = true;
  for (size_t k = 1; k < m_raw.size() && sorted; ++k)
    sorted = m_raw[k - 1].a < m_raw[k].a || (m_raw[k - 1].a == m_raw[k].a && m_raw[k - 1].b < m_raw[k].b);
  if (sorted)
    m_pairs.swap(m_raw);
  else
    sortRaw(n);
  // Drop wall-wall pairs and duplicates, and fix each pair's reach for the per-step filter.
  size_t out = 0;
  for (size_t k = 0; k < m_pairs.size(); ++k) {
    ListedPair p = m_pairs[k];
    if (world.kind[p.a] == BodyKind::Wall && world.kind[p.b] == BodyKind::Wall) continue;
    if (world.kind[p.a] == BodyKind::Vessel || world.kind[p.b] == BodyKind::Vessel) continue;  // direct
    if (out > 0 && m_pairs[out - 1].a == p.a && m_pairs[out - 1].b == p.b) continue;
    const Real reach = world.radius[p.a] + world.radius[p.b];
    p.reach2 = reach * reach;
    m_pairs[out++] = p;
  }
  m_pairs.resize(out);
  m_x0.assign(world.x.begin(), world.x.end());
  m_y0.assign(world.y.begin(), world.y.end());
  m_angle0.assign(world.angle.begin(), world.angle.end());
  m_id0.assign(world.id.begin(), world.id.end());
  m_direct.assign(n, 0);
  m_directList.clear();
  for (int i = 0; i < n; ++i)
    if (world.kind[i] == BodyKind::Vessel) m_direct[i] = 1, m_directList.push_back(i);
  m_valid = true;
  ++m_rebuilds;
}

void NeighbourList::filterByCircles(const World& world, std::vector<CandidatePair>& out) {
  // Branch-free: every listed pair is written to a scratch row and kept by advancing the count;
  // about a third pass, so a branch would mispredict often. The scratch never shrinks. Pairs of a
  // direct body are skipped here: the direct pass below finds them.
  if (m_filtered.size() < m_pairs.size()) m_filtered.resize(m_pairs.size());
  const Real* x = world.x.data();
  const Real* y = world.y.data();
  const char* direct = m_direct.data();
  CandidatePair* dst = m_filtered.data();
  size_t count = 0;
  for (const ListedPair& p : m_pairs) {
    const Real dx = x[p.a] - x[p.b], dy = y[p.a] - y[p.b];
    dst[count] = {p.a, p.b};
    count += (dx * dx + dy * dy <= p.reach2) & !(direct[p.a] | direct[p.b]);
  }
  if (m_directList.empty()) {
    out.assign(m_filtered.begin(), m_filtered.begin() + static_cast<std::ptrdiff_t>(count));
    return;
  }
  // Direct bodies (the vessel, and floes that moved more than half the skin since the build) are
  // tested against every body: one pass each, a microsecond per thousand bodies, instead of a
  // rebuild of the whole list every few steps while the vessel shoves floes at its own speed.
  const Real* radius = world.radius.data();
  const int n = world.size();
  m_directPairs.clear();
  for (int v : m_directList) {
    for (int j = 0; j < n; ++j) {
      if (j == v || (direct[j] && j < v)) continue;  // a pair of two direct bodies is found once
      if (world.kind[v] == BodyKind::Wall && world.kind[j] == BodyKind::Wall) continue;
      const Real dx = x[v] - x[j], dy = y[v] - y[j], reach = radius[v] + radius[j];
      if (dx * dx + dy * dy <= reach * reach) m_directPairs.push_back(j < v ? CandidatePair{j, v} : CandidatePair{v, j});
    }
  }
  auto before = [](CandidatePair p, CandidatePair q) { return p.a < q.a || (p.a == q.a && p.b < q.b); };
  std::sort(m_directPairs.begin(), m_directPairs.end(), before);
  out.resize(count + m_directPairs.size());
  std::merge(m_filtered.begin(), m_filtered.begin() + static_cast<std::ptrdiff_t>(count), m_directPairs.begin(), m_directPairs.end(),
             out.begin(), before);
}

void KeptListBroadphase::findCandidates(const World& world, std::vector<CandidatePair>& pairs) {
  if (m_list.update(world)) {
    m_list.begin();
    build(world, m_list);
    m_list.finish(world);
  }
  filter(world, pairs);
}

void AxisSweep::build(const World& world, const std::vector<Real>& h, Real floor, NeighbourList& list) {
  const int n = world.size();
  const Real* x = world.x.data();
  m_lo.resize(n);
  for (int i = 0; i < n; ++i) m_lo[i] = x[i] - std::max(floor / 2, h[i]);
  if (static_cast<int>(m_order.size()) != n) {
    m_order.resize(n);
    for (int i = 0; i < n; ++i) m_order[i] = i;
  }
  // Insertion sort by lo, O(n + inversions); after a reorder of the world the old order means
  // nothing, so past a work budget sort afresh.
  long moves = 0;
  const long budget = 16L * n + 1024;
  for (int k = 1; k < n && moves <= budget; ++k) {
    const int v = m_order[k];
    const Real key = m_lo[v];
    int q = k - 1;
    while (q >= 0 && m_lo[m_order[q]] > key) {
      m_order[q + 1] = m_order[q];
      --q;
      ++moves;
    }
    m_order[q + 1] = v;
  }
  if (moves > budget) std::sort(m_order.begin(), m_order.end(), [&](int p, int q) { return m_lo[p] < m_lo[q]; });

  m_slot.resize(n), m_x.resize(n), m_y.resize(n), m_h.resize(n), m_sortedLo.resize(n), m_hi.resize(n);
  for (int k = 0; k < n; ++k) {
    const int i = m_order[k];
    m_slot[k] = i, m_x[k] = x[i], m_y[k] = world.y[i], m_h[k] = h[i], m_sortedLo[k] = m_lo[i];
    m_hi[k] = x[i] + std::max(floor / 2, h[i]);
  }
  for (int k = 0; k < n; ++k) {
    const Real hi = m_hi[k];
    for (int q = k + 1; q < n && m_sortedLo[q] <= hi; ++q) {
      const Real dx = m_x[k] - m_x[q], dy = m_y[k] - m_y[q], reach = std::max(floor, m_h[k] + m_h[q]);
      if (dx * dx + dy * dy <= reach * reach) list.add(m_slot[k], m_slot[q]);
    }
  }
}

BroadphaseSettings checkedSettings(const BroadphaseSettings& settings) {
  auto check = [](Real value, const char* key) {
    if (!std::isfinite(value) || value < 0)
      throw InputError(std::string("broadphase ") + key + " must be a finite length >= 0 m, got " + std::to_string(value));
  };
  check(settings.skin, "skin");
  check(settings.fixedRadius, "fixed_radius");
  check(settings.cellSize, "cell_size");
  return settings;
}

Real largestFloeRadius(const World& world) {
  Real floe = 0, movable = 0;
  for (int i = 0; i < world.size(); ++i) {
    if (world.kind[i] == BodyKind::Floe && world.radius[i] > floe) floe = world.radius[i];
    if (world.kind[i] != BodyKind::Wall && world.radius[i] > movable) movable = world.radius[i];
  }
  return floe > 0 ? floe : movable;
}

}  // namespace gem
