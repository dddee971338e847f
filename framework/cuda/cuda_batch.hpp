// The device state of the CUDA backend shared by one or several cases (CudaBatch), and the helpers
// the backend's host files share. Internal to framework/cuda/.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "framework/api/device_broadphase.hpp"
#include "framework/cuda/cuda_stepper.hpp"
#include "framework/cuda/device_step.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/world/world.hpp"

namespace gem {

// Wall time in parts: lap() gives the seconds since the last lap (or since it was made).
class Stopwatch {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - m_last).count();
    m_last = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point m_last = std::chrono::steady_clock::now();
};

// Runs alive on each device in this process (a sweep runs several at once).
std::atomic<int>& liveOn(int device);

// The scenario's broadphase on the device (nullptr: the step's built-in grid, uniform_grid).
std::unique_ptr<cuda::CudaBroadphase> deviceBroadphase(const Scenario& scenario);

// The device state of one run, or of several cases run together (a world each). It owns the
// device and the step loop; each case (a CudaStepper) keeps its own host mirror and hands out
// its own world's records. With several worlds, body ids on the device are the case's own plus
// world x idStride (unique over the state, so contacts' onset keys never mix worlds), and a
// world's device slots are the state's slots of that world in ascending order.
class CudaBatch {
 public:
  CudaBatch(std::vector<CudaStepper*> members, int deviceOrdinal);
  ~CudaBatch();

  int worlds() const { return static_cast<int>(m_members.size()); }
  cuda::DeviceStep& device() { return *m_device; }
  const cuda::DeviceBatchResult& result() const { return *m_result; }
  long resultFirst() const { return m_resultFirst; }  // step index of result().steps[0]
  // The rows of record stream q that world w recorded in result().steps[k], in device order.
  std::pair<const int*, const int*> rowsOf(int q, size_t k, int w) const;
  std::int64_t idOffset(int world) const { return static_cast<std::int64_t>(world) * m_idStride; }
  int worldOfId(std::int64_t id) const { return static_cast<int>(id / m_idStride); }
  // World w's device slot `local` in the shared state.
  int sharedSlot(int world, int local) { return worlds() == 1 ? local : slotsOfWorld(world)[static_cast<size_t>(local)]; }
  const std::vector<int>& slotsOfWorld(int world);

  // The host mirrors to the device (set-up; a strategy that could not follow a re-sort).
  void uploadAll();
  // Step `step` of every case is on the host (a case asking for it runs the next batch of steps).
  void ensureStep(long step);
  // A case's topology edit: its device slots removedLocal leave, its mirror's rows from
  // [firstAdded..] are appended (applied once every case is done with the step).
  void addEdit(int world, const std::vector<int>& removedLocal, const World& mirror, int firstAdded);
  // A case finished its step: the last one of a step applies the edits and re-sorts when due.
  void finishedStep(long step);
  std::vector<int> vesselDofs() const;

  struct HostTimes {
    long batches = 0, topologies = 0, resorts = 0;
    double batch = 0, fetch = 0, events = 0, edit = 0, bookkeeping = 0, resort = 0, ordering = 0;
  } times;  // host wall time by part (GEM_CUDA_TIMING=1 prints it when the state goes), s

 private:
  void runBatch(long step);
  void followDeviceEdits();  // the mirrors after the resident kernel's breaks (runBatch)
  void followOrder(const std::vector<int>& order, const std::vector<int>& worldBefore);  // after a re-sort
  void applyEdits();
  void reSortAlongCurve();

  std::vector<CudaStepper*> m_members;
  int m_deviceOrdinal;
  std::unique_ptr<cuda::DeviceStep> m_device;
  std::unique_ptr<cuda::DeviceBatchResult> m_result;
  // rowsOf's index, made once a batch (each case then reads its own rows, not every case's):
  // stream q's rows by (step, world), as offsets into the rows.
  std::vector<int> m_rowOffsets[kMaxRecordStreams], m_rows[kMaxRecordStreams];
  void indexRows();
  long m_resultFirst = 0;
  std::int64_t m_idStride = std::int64_t(1) << 62;  // one world: the ids as they are
  std::vector<std::vector<int>> m_slotsOfWorld;     // empty: stale
  int m_finished = 0;                               // cases done with the current step
  long m_stepsDone = 0;
  // The step's edits, applied together: shared slots, and the new bodies with their worlds.
  std::vector<int> m_removed;
  World m_added;
  std::vector<int> m_addedWorlds;
  bool m_edited = false;
};

}  // namespace gem
