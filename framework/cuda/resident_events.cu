// The events the resident kernel holds: GEM's built-in evaluators, the very structs the CPU driver
// and the device-wide driver call (events/NAME.hpp), compiled into the kernel so that a step is one
// launch. This is the one file of framework/ that includes events/ (tests/layout_test.cpp allows
// it): a built-in event joins the resident driver by one line below. An event not listed here (a
// plugin's) runs on the device-wide driver; simulation.cuda_driver = "auto" picks it.
#include <cstring>

#include "events/autopilot.hpp"
#include "events/drag.hpp"
#include "events/elastic_contact.hpp"
#include "events/environmental_force.hpp"
#include "events/flexural_breaking.hpp"
#include "events/flexural_cut.hpp"
#include "events/impact.hpp"
#include "events/motion.hpp"
#include "events/propulsion.hpp"
#include "events/ship_impact.hpp"
#include "framework/api/cuda_check.hpp"
#include "framework/cuda/resident.cuh"
#include "framework/cuda/resident_kernel.cuh"

namespace gem::cuda {
namespace {

using BuiltIn = resident::EventSet<resident::Pair<Impact>, resident::Pair<ElasticContact>, resident::Pair<ShipImpact>, resident::Solo<Drag>,
                                   resident::Solo<EnvironmentalForce>, resident::Solo<EnvironmentalForce>, resident::Solo<Propulsion>,
                                   resident::Solo<Autopilot>, resident::Motion<Motion>>;

// The topology event the kernel runs itself (breakFloes): flexural_breaking, its Params read from
// each world's row, its cut the host's (events/flexural_cut.hpp).
struct Breaking {
  using Request = BreakRequest;
  using Piece = FloePiece;
  __device__ static int stream(const unsigned char* row, int offset) {
    return resident::paramsAt<FlexuralBreaking::Params>(row, offset).breaks.index;
  }
  __device__ static Real minArea(const unsigned char* row, int offset) {
    return resident::paramsAt<FlexuralBreaking::Params>(row, offset).minArea;
  }
  __device__ static bool cut(const Vec2* local, int n, Vec2 centroid, Real angle, Vec2 velocity, Real omega, const BreakRequest& request,
                             Real minArea, FloePiece pieces[2]) {
    return cutFloe(local, n, centroid, angle, velocity, omega, request, minArea, pieces);
  }
};

struct Entry {
  const char* name;
  ResidentPhase phase;
  std::size_t paramsSize;
};
// By kind: the names the registry knows the events by, in BuiltIn's order.
const Entry kEntries[] = {
    {"impact", kResidentPair, sizeof(Impact::Params)},           {"elastic_contact", kResidentPair, sizeof(ElasticContact::Params)},
    {"ship_impact", kResidentPair, sizeof(ShipImpact::Params)},  {"drag", kResidentSolo, sizeof(Drag::Params)},
    {"wind", kResidentSolo, sizeof(EnvironmentalForce::Params)}, {"current", kResidentSolo, sizeof(EnvironmentalForce::Params)},
    {"propulsion", kResidentSolo, sizeof(Propulsion::Params)},   {"autopilot", kResidentSolo, sizeof(Autopilot::Params)},
    {"motion", kResidentMotion, sizeof(Motion::Params)},
};
static_assert(sizeof(kEntries) / sizeof(kEntries[0]) == BuiltIn::size, "one name per event of the table");

}  // namespace

int residentEventKind(const std::string& name, ResidentPhase phase, std::size_t* paramsSize) {
  for (int k = 0; k < BuiltIn::size; ++k)
    if (name == kEntries[k].name && phase == kEntries[k].phase) {
      if (paramsSize) *paramsSize = kEntries[k].paramsSize;
      return k;
    }
  return -1;
}

bool residentTopologyEvent(const std::string& name, std::size_t* paramsSize) {
  if (name != "flexural_breaking") return false;
  if (paramsSize) *paramsSize = sizeof(FlexuralBreaking::Params);
  return true;
}

std::size_t residentSharedBytes(int bodies, int vertices) {
  int sorted = 1;
  while (sorted < bodies) sorted <<= 1;
  const std::size_t withVertices = residentBodyBytes(sorted) + static_cast<std::size_t>(vertices) * sizeof(Vec2);
  if (withVertices <= kResidentSharedBytes) return withVertices;
  return residentBodyBytes(sorted) <= kResidentSharedBytes ? residentBodyBytes(sorted) : 0;
}

// Dynamic shared memory past 48 KB must be asked for, once per size.
static void allowShared(std::size_t shared) {
  static std::size_t allowed = 0;
  if (shared <= allowed) return;
  GEM_CUDA_CHECK(cudaFuncSetAttribute(resident::residentKernel<BuiltIn, Breaking>, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                      static_cast<int>(kResidentSharedBytes)));
  allowed = kResidentSharedBytes;
}

void launchResident(const ResidentArgs& args, int grid, std::size_t shared, cudaStream_t stream) {
  allowShared(shared);
  if (grid == 1) {
    resident::residentKernel<BuiltIn, Breaking><<<1, kResidentBlock, shared, stream>>>(args, shared > 0);
    GEM_CUDA_CHECK_LAUNCH();
    return;
  }
  ResidentArgs copy = args;
  bool staged = shared > 0;
  void* params[] = {&copy, &staged};
  GEM_CUDA_CHECK(cudaLaunchCooperativeKernel(reinterpret_cast<void*>(resident::residentKernel<BuiltIn, Breaking>),
                                             dim3(static_cast<unsigned>(grid)), dim3(kResidentBlock), params, shared, stream));
}

int residentBlocksPerMultiprocessor(std::size_t shared) {
  allowShared(shared);
  int blocks = 0;
  GEM_CUDA_CHECK(
      cudaOccupancyMaxActiveBlocksPerMultiprocessor(&blocks, resident::residentKernel<BuiltIn, Breaking>, kResidentBlock, shared));
  return blocks;
}

}  // namespace gem::cuda
