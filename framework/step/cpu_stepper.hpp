// The GEM scheduler with the CPU driver: one step is the fixed phases of docs/model.md 8.
//   1 broadphase  2 narrowphase  3 two-body events  4 solo events  5 motion  6 topology
// (7, the observers, live in the runner). Events come from the registry by name.
#pragma once
#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "framework/step/thread_pool.hpp"
#include "framework/api/broadphase.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/still_bodies.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/step/stepper.hpp"
#include "framework/world/world.hpp"
#include "geometry/sat.hpp"

namespace gem {

// Builds the initial bodies of a scenario (walls, field, [[floes]], vessel) after validating each
// one (convex, finite, 3..19 vertices for floes, positive thickness) and checking that no two
// overlap. Throws InputError naming the body (and the first overlapping pair).
World buildWorld(const Scenario& scenario);

// Throws InputError when a body spec is invalid; reverses clockwise vertices in place.
void validateBodySpec(BodySpec& spec, int maxVertices);

struct EnabledEvent {
  std::string name;
  EventPhase phase;
  std::unique_ptr<EventInstance> instance;
};

class CpuStepper final : public Stepper {
 public:
  explicit CpuStepper(const Scenario& scenario);
  // For tests: a world built by hand, with the scenario's events and broadphase.
  CpuStepper(const Scenario& scenario, World world);
  ~CpuStepper() override;  // GEM_CPU_TIMING=1 prints the phases' times here

  void step() override;

  // An edit through this reference, made before the next step(), is seen by it: the stepper then
  // takes no body for still (m_stillness) and reads every body afresh.
  World& world() {
    m_stillnessKnown = false;
    return m_world;
  }
  const World& world() const { return m_world; }
  const Scenario& scenario() const { return m_scenario; }
  long stepIndex() const override { return m_step; }
  Real time() const override { return m_time; }
  const World& hostWorld() override { return m_world; }
  VesselSample vessel() override;
  std::string device() const override { return "cpu"; }
  std::string backend() const override { return "cpu"; }
  const std::vector<EnabledEvent>& events() const { return m_events; }
  Broadphase& broadphase() { return *m_broadphase; }
  void restartPhaseClock() override {
    m_clock.steps = 0, m_clock.seconds = {}, m_clock.inRounds = {}, m_clock.poolMark = 0;
    m_clock.stepSeconds = {}, m_clock.stepCount = {};
    if (m_pool) m_pool->resetStats();
  }

  // What the last step produced.
  const StepRecords& records() const override { return m_records; }
  const RecordStreams& recordStreams() const { return m_streams; }
  int contactCount() const override { return static_cast<int>(m_contacts.size()); }
  int candidateCount() const { return static_cast<int>(m_pairs.size()); }
  // Of the last step's candidates, those in the broadphase's resting ranges, passed over unread.
  long restingCandidates() const {
    long resting = 0;
    for (const CandidateRange& r : m_restingPairs) resting += r.end - r.begin;
    return resting;
  }
  // Pairs whose boxes overlap that an edge separated (those tested: a pair at rest is not).
  int separatedCount() const { return static_cast<int>(m_lastSeparated.size()); }
  int threads() const { return m_pool ? m_pool->size() : 1; }  // after the first step
  // Bodies the last step's body updates ran for: the others were in blocks of still bodies that
  // touched nothing (m_stillness below).
  int updatedBodies() const { return m_updatedBodies; }
  // The sizes from which a phase runs on the pool at all (docs/performance.md 3.8).
  static constexpr int kParallelBodies = 2048, kParallelPairs = 2048;
  // Contacts from which the pair events run over ranges of contacts, kContactGrain at least a range.
  static constexpr int kParallelContacts = 512, kContactGrain = 128;
  // Bodies or pairs a task takes at least: a small field wakes few threads (on 16 cores, waking all
  // of them for the 456-hexagon field made its step 1.3x slower than one thread's).
  static constexpr int kGrain = 512;
  // The pair views (about 15 nanoseconds a body's view): from this many bodies in contact on,
  // over ranges of kPairViewGrain. Under kParallelBodies they were made on the calling thread: at
  // 10^5 floes after a few thousand steps, 1,000 bodies and 14 us of a two-thread step.
  static constexpr int kParallelPairViews = 512, kPairViewGrain = 128;
  // Contacts and separated pairs from which the narrowphase's parts are joined on the pool.
  static constexpr size_t kParallelJoin = 32768;
  Vec2 vesselIceForce() const override { return m_vesselIceForce; }  // N, world frame, from the step's impulses
  const std::vector<std::pair<std::int64_t, Real>>* contactForces() const override;
  int vesselSlot() const;  // -1 without a vessel
  StepperState saveState() override;
  void restoreState(const StepperState& state) override;

  // Totals since the start.
  double rubbleMass() const override { return m_rubbleMass; }
  long floesBroken() const override { return m_floesBroken; }

  // Whether a step hands its log records to their channels' writers (a plugin's own files, such
  // as rafting.csv). gem check takes one step to see that it stays finite, and writes nothing.
  void setDeliverLogs(bool deliver) { m_deliverLogs = deliver; }

 private:
  // GEM_CPU_TIMING=1: the wall time of each phase of the steps taken, printed as one line on
  // stderr when the stepper goes (docs/performance.md 1.4). Off, a lap is one test of a flag.
  struct PhaseClock {
    enum Phase { Broadphase, Tests, Join, PairEvents, BodyUpdates, Topology, kPhases };
    static constexpr std::array<const char*, kPhases> kNames{
        "broadphase", "narrowphase tests", "narrowphase join", "pair views and events", "body updates", "topology"};
    bool on = false;
    long steps = 0;
    std::array<double, kPhases> seconds{};
    // Of each phase, the time inside rounds on the pool (its ThreadPool::Stats::inRounds grew by it).
    std::array<double, kPhases> inRounds{};
    const ThreadPool* pool = nullptr;
    double poolMark = 0;
    std::chrono::steady_clock::time_point mark;
    // The steps by kind: plain, those that broke floes or re-sorted the bodies (bodies changed
    // slots), and those right after such a step. At 10^5 floes the few of the last two kinds took
    // as much time as all the plain ones (docs/performance.md 3.19).
    enum StepKind { Plain, Renaming, AfterRenaming, kStepKinds };
    std::array<double, kStepKinds> stepSeconds{};
    std::array<long, kStepKinds> stepCount{};
    std::chrono::steady_clock::time_point stepMark;
    void start() {
      if (!on) return;
      mark = stepMark = std::chrono::steady_clock::now();
      if (pool) poolMark = pool->stats().inRounds;
    }
    void endStep(StepKind kind) {
      if (!on) return;
      stepSeconds[kind] += std::chrono::duration<double>(std::chrono::steady_clock::now() - stepMark).count();
      ++stepCount[kind];
    }
    void lap(Phase phase) {
      if (!on) return;
      const auto now = std::chrono::steady_clock::now();
      seconds[phase] += std::chrono::duration<double>(now - mark).count();
      mark = now;
      if (pool) inRounds[phase] += pool->stats().inRounds - poolMark, poolMark = pool->stats().inRounds;
    }
  } m_clock;

  void setUp();
  void narrowphase();
  void bodyUpdates(const StepContext& ctx);
  void noteBlockStill(int b);  // m_blockStill[b] from block b's flags in m_stillness
  void reorderAlongCurve();

  Scenario m_scenario;
  World m_world;
  std::unique_ptr<Broadphase> m_broadphase;
  bool m_broadphaseFromPlugin = false;  // its pairs are normalised (normalizeCandidatePairs)
  std::vector<EnabledEvent> m_events;
  long m_step = 0;
  Real m_time = 0;
  std::int64_t m_vesselId = -1;
  mutable int m_vesselSlotSeen = -1;  // where vesselSlot() last found it

  // Per-step buffers, kept to avoid allocation.
  // Each body's world vertices, kMaxVertices a row, in the row m_vertexRow names for its slot: a
  // re-sort or a break renames the rows (followBodiesToNewSlots) instead of moving 384 bytes a
  // body (at 10^5 floes, moving them took 6 ms a rename on one core). Rows freed by removed bodies
  // are reused (m_freeRows); anything else that changes the slots makes the rows the slots again.
  std::vector<Vec2> m_worldVertices;
  std::vector<int> m_vertexRow, m_freeRows;
  int m_rowCount = 0;  // rows in use or free
  Vec2* worldVerticesOf(int i) { return &m_worldVertices[static_cast<size_t>(m_vertexRow[static_cast<size_t>(i)]) * kMaxVertices]; }
  std::vector<Box> m_boxes;  // world-aligned bounding box of each body, this step
  struct Pose {
    std::int64_t id;
    Real x, y, angle;
    bool operator==(const Pose&) const = default;
  };
  World::PermuteRoom m_permuteRoom;  // the re-sort's arrays, kept from one re-sort to the next
  std::vector<Pose> m_vertexPose;    // the pose m_worldVertices and m_boxes were computed for, by slot
  // Set for the coming narrowphase by the body updates (or by the narrowphase itself after an edit
  // or a restored state), through refreshPose; a re-sort or a break moves them with the bodies.
  std::vector<char> m_moved;                                  // this step: the body's pose differs from the last step's
  std::vector<char> m_active;                                 // this step: moved, or in a contact at the last step
  bool refreshPose(int i, bool inContact, bool movedBefore);  // body i's m_moved (returned), m_active, and vertices and box
  // After a re-sort or a break: what the last body updates left by slot follows each body, by its
  // id, to its new slot (followBodiesToNewSlots), and the next narrowphase learns that the slots
  // changed hands (m_slotsRenamed: "touched before" then searches the last contacts by id).
  void followBodiesToNewSlots();
  bool m_slotsRenamed = false;
  std::vector<int> m_oldSlotOfId;  // followBodiesToNewSlots' table: each id's slot before (stale where no slot held the id)
  // Its buffers, by the new slots, swapped in: they keep their memory from one rename to the next.
  // m_oldSlot: by new slot, the old slot its body came from (-1: none); m_takenBy: by old slot, the
  // new slot that took its body (a repeated id, against the World's rule, takes it once).
  std::vector<int> m_nextVertexRow, m_oldSlot, m_takenBy;
  struct FollowPart {  // a range's rows freed and new slots without a row, in slot order
    std::vector<int> freeRows, newSlots;
  };
  std::vector<FollowPart> m_followParts;
  std::vector<Box> m_nextBoxes;
  std::vector<Pose> m_nextVertexPose;
  std::vector<char> m_nextMoved, m_nextActive, m_nextStillness;
  // By slot, what the last body updates did to each body (docs/performance.md 3.12): kMoving (a bit
  // of its position, angle or velocities changed), kStillInContact (none did, but it had contacts)
  // or kStill (neither; and its pose is the one its vertices were made for). Known while nothing has
  // edited the world since (m_stillnessKnown), through re-sorts and breaks, which move the flags
  // with their bodies; the poses' flags, vertices and boxes the body updates left (refreshPose)
  // hold as long, and the narrowphase then takes them as they are. The body updates leave out a
  // block of kStill bodies none of which has a contact now, while every solo and motion event of
  // the run is time invariant (m_skipStillBodies): the same state, no contact and the same events
  // give the very same bits, so its update would write nothing.
  enum Stillness : char { kMoving = 0, kStillInContact = 1, kStill = 2 };
  std::vector<char> m_stillness;
  bool m_stillnessKnown = false;
  bool m_skipStillBodies = false;
  int m_updatedBodies = 0;
  std::vector<CandidatePair> m_pairs;
  std::vector<CandidateRange> m_restingPairs;  // ranges of m_pairs that hold pairs of two kStill bodies only
  std::vector<CandidateRange> m_toScan;        // the narrowphase's: the stretches between them
  std::vector<long> m_scanBefore;              // the candidates in the stretches before each, and all of them last
  std::vector<int> m_contactA, m_contactB;
  std::vector<PairContact> m_contacts;
  std::vector<PairSlot> m_slots;
  std::vector<PairBody> m_pairBodies;  // set for the bodies of this step's contacts only
  std::vector<std::pair<std::int64_t, std::int64_t>> m_previousContacts, m_currentContacts;
  bool m_previousSorted = true;  // m_previousContacts is sorted (it is kept in contact order until searched)
  // The contacts of the narrowphase, body by body, built in O(contacts) (no pass over every slot,
  // which at 10^5 floes was a serial tenth of a millisecond a step, several times over): the pair
  // views, the gather and the next step's "touched before" all read it.
  struct ContactsByBody {
    std::vector<unsigned> stamp;  // by slot: == current when the body has contacts
    std::vector<int> start, count;
    std::vector<int> entries;  // k x 2 + side (1 for b), each body's together and in contact order
    std::vector<int> bodies;   // the bodies with contacts, in order of their first contact
    unsigned current = 0;
    void build(const std::vector<int>& a, const std::vector<int>& b, int n);
    bool has(int i) const { return static_cast<size_t>(i) < stamp.size() && stamp[static_cast<size_t>(i)] == current; }
  };
  ContactsByBody m_byBody;
  // By slot, at the end of the last narrowphase, the id there, so that a candidate learns whether
  // it touched before from its body's contacts of the last step (m_byBody with m_contactA/B, not yet
  // overwritten) instead of a search of m_previousContacts. Copied afresh only after a step in which
  // a slot changed hands (a re-sort, a break, a restored state): copied every step, it was 16 bytes
  // a body of memory traffic for nothing, in a step bound by memory on many threads.
  std::vector<std::int64_t> m_lastSlotId;
  bool touchedAtLastStep(int a, int b) const;
  // The pairs whose polygons a full test found apart, in candidate order, with the edge that
  // separated them: next step that edge is tried first (only ever to reject; sat.hpp).
  struct SeparatedPair {
    int a, b;
    SeparatingEdge axis;
  };
  std::vector<SeparatedPair> m_lastSeparated, m_separated;
  // simulation.threads: the pool (null for one thread) and each task's share of the narrowphase,
  // joined in task order so that the contacts are in pair order whatever the thread count.
  std::unique_ptr<ThreadPool> m_pool;
  bool m_poolChecked = false;
  struct NarrowphasePart {
    std::vector<int> a, b;
    std::vector<PairContact> contacts;
    std::vector<std::pair<std::int64_t, std::int64_t>> keys;
    std::vector<SeparatedPair> separated;
    std::vector<int> boxSurvivors;  // scratch: the candidates of its range whose boxes overlap, the first `survivors`
    int survivors = 0;
  };
  std::vector<NarrowphasePart> m_parts;
  std::vector<long> m_survivorsBefore;              // the box survivors of the parts before each part, and all of them last
  std::vector<std::pair<size_t, size_t>> m_joinAt;  // each part's first contact and separated pair in the join
  void joinParts(int tasks);
  // range(begin, end) over contiguous ranges that cover [0, n), on the pool's threads: from `from`
  // items on, `grain` items a range at least.
  void forEachRange(int n, const std::function<void(int, int)>& range, int from = kParallelBodies, int grain = kGrain);
  // The same with each range's index, 0 .. rangesFor(n) - 1 in the order of the ranges, for ranges
  // that fill a part of their own to be joined in order.
  void forEachPart(int n, const std::function<void(int, int, int)>& range, int from = kParallelBodies, int grain = kGrain);
  int rangesFor(int n, int from = kParallelBodies, int grain = kGrain) const;
  // The body updates' blocks: slots [b kBlock, (b + 1) kBlock), each updated whole (its views made
  // once and kept in the cache) or left out whole. By block: whether every body holds kStill
  // (m_blockStill, kept with m_stillness), whether one has a contact this step, and this step's
  // blocks to update.
  static constexpr int kBlock = 256;
  std::vector<char> m_blockStill, m_blockTouched;
  std::vector<int> m_blocksToUpdate;
  RecordStreams m_streams;  // opened by the events as their Params are parsed
  StepRecords m_records;    // the last step's rows
  bool m_deliverLogs = true;
  // The pair phase's record buffers, per range of contacts and stream (range x streams + stream),
  // and the rows each holds.
  std::vector<std::vector<unsigned char>> m_pairRecordRows;
  std::vector<int> m_pairRecordRoom;
  Vec2 m_vesselIceForce{0, 0};
  // The sum of a body's contact impulses (N s) and the body's id, by the slots of the gather (the
  // breaks and re-sorts after it move bodies between slots). Its force, |sum| / dt, is taken when
  // contactForces() is asked, not with a square root and a division for every body in contact every
  // step: only a frame reads it.
  std::vector<Vec2> m_contactImpulseOfSlot;
  std::vector<std::int64_t> m_contactForceId;
  // The non-zero ones by id, built when contactForces() is asked (a frame is written), not every step.
  mutable std::vector<std::pair<std::int64_t, Real>> m_contactForces;
  mutable bool m_contactForcesBuilt = false;
  double m_rubbleMass = 0;
  long m_floesBroken = 0;
};

}  // namespace gem
