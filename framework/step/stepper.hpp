// A backend steps a scenario's world: the CPU one (CpuStepper) or a device one. The runner and the
// benchmarks see only this interface, so a backend added later (CUDA) changes neither.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/api/errors.hpp"
#include "framework/api/event_api.hpp"
#include "framework/api/step_records.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/world/world.hpp"

namespace gem {

// The vessel's state after the last step, cheap to read every step.
struct VesselSample {
  bool present;
  Vec2 position;
  Real heading;
  Vec2 velocity;
};

// What a checkpoint keeps of a stepper (docs/reliability.md "Checkpoints"): with it a stepper made
// anew from the same scenario goes on exactly as the one that wrote it would have, bit for bit.
// Everything else a stepper holds (world vertices, boxes, the broadphase's lists, buffers) is
// derived from these, or only saves work.
struct StepperState {
  World world;  // every body, in the slot order of the stepper that saved it
  long step = 0;
  Real time = 0;
  // The id pairs (lower id first, sorted) in contact after the last step: a contact's onset (a
  // pair that did not touch then) is part of the physics.
  std::vector<std::pair<std::int64_t, std::int64_t>> touching;
  double rubbleMass = 0;
  long floesBroken = 0;
};

class Stepper {
 public:
  virtual ~Stepper() = default;
  virtual void step() = 0;
  virtual long stepIndex() const = 0;
  virtual Real time() const = 0;
  // The whole state on the host; a device backend copies it here when asked (outputs, frames).
  virtual const World& hostWorld() = 0;
  virtual VesselSample vessel() = 0;
  // What the last step produced.
  // The rows the events recorded (record streams: ship_impact's impacts, say), in the CPU's order.
  virtual const StepRecords& records() const = 0;
  virtual int contactCount() const = 0;
  virtual Vec2 vesselIceForce() const = 0;  // N, from the step's impulses on the vessel
  // Totals since the start.
  virtual double rubbleMass() const = 0;
  virtual long floesBroken() const = 0;
  virtual std::string device() const = 0;
  virtual std::string backend() const = 0;  // "cpu", "cuda"
  // The backend's driver that steps: "cpu", or the CUDA driver ("resident", "device").
  virtual std::string driver() const { return backend(); }
  // Wall seconds the backend's device has spent stepping so far, copies of results included (its
  // share when cases run together is the whole batch's); 0 for a backend without a device.
  virtual double deviceSeconds() const { return 0; }
  // A backend's phase clocks (GEM_CPU_TIMING=1) count from here on: `gem bench` calls it after its
  // warm-up, so that the clocks time the steps the bench times.
  virtual void restartPhaseClock() {}
  // The magnitude of each body's contact force over the last step (the sum of its contacts'
  // impulses / dt, N), by body id, sorted by id, bodies without contact left out; null for a
  // backend that does not keep it (the ParaView frames then have no contact_force array).
  virtual const std::vector<std::pair<std::int64_t, Real>>* contactForces() const { return nullptr; }
  // Checkpoints: the state after the last step, and a stepper just made from the same scenario set
  // to one. A backend that cannot (a case stepped together with others) throws BackendUnsupported.
  // Whether the state after the last step is on the host now (a device backend's is only between
  // two copy-back batches): a checkpoint is written then.
  virtual bool stateOnHost() const { return true; }
  virtual StepperState saveState();
  virtual void restoreState(const StepperState& state);
};

// A backend that cannot run this scenario (e.g. an event without a driver for it). Bad input when
// the backend was asked for by name; with "auto", makeStepper falls back to the CPU instead.
class BackendUnsupported : public InputError {
 public:
  using InputError::InputError;
};

struct BackendEntry {
  std::string name;
  std::function<bool()> available;  // a device exists
  std::function<std::string()> deviceName;
  std::function<std::unique_ptr<Stepper>(const Scenario&)> make;
  // Sweeps on a machine with several devices: the runs that this host thread makes next use device
  // `worker` modulo the device count (a sweep's workers, over MPI ranks and threads, spread over the
  // GPUs of their node). Empty for a backend without devices.
  std::function<void(int worker)> useDeviceForWorker;
  // Sweeps on a device: cases whose batchKey is the same and not "" may run together in one device
  // state (makeTogether: a stepper each, stepped together by runScenariosTogether), each exactly as
  // alone. deviceCount: the devices this process sees. All three empty for the CPU.
  std::function<std::string(const Scenario&)> batchKey;
  std::function<std::vector<std::unique_ptr<Stepper>>(const std::vector<const Scenario*>&)> makeTogether;
  std::function<int()> deviceCount;
};

void registerBackend(BackendEntry entry);
const BackendEntry* findBackend(const std::string& name);
std::vector<std::string> backendNames();

// "auto" is "cuda" when that backend is built and a device is present, else "cpu". Asking for a
// backend that is not built, or has no device, is an InputError that says so.
std::string resolveBackend(const std::string& requested);
// The scenario's backend, made. With backend = "auto", a device backend that cannot run the
// scenario (BackendUnsupported) gives way to the CPU, with a note on stderr.
std::unique_ptr<Stepper> makeStepper(const Scenario& scenario);

// "" when every body of `world` has a finite state after step `step` (1-based, at time `time`);
// else the first body that does not, with its whole state: "step 1 (t = 0.1 s): body 3 (floe) has a
// state that is no longer finite (x .., y .., angle .., vx .., vy .., omega ..)". gem run stops
// with it, and gem check refuses a first step that gives it.
std::string nonFiniteState(const World& world, long step, double time);

}  // namespace gem
