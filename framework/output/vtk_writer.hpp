// ParaView output (docs/scenario.md "Outputs"): one VTK XML PolyData file per frame,
// runDir/frames/frame_NNNNNN.vtp, and the time series runDir/frames.pvd that lists them.
// Each body is one polygon cell; points are its world vertices (z = 0). Cell data: id (Int64, the
// GlobalIds), kind (Int32: 0 floe, 1 vessel, 2 wall) and kind_name (its name), speed (m/s, the
// active scalar ParaView colours by), velocity (m/s, 3 components, z = 0), angular_velocity
// (rad/s), thickness (m), area (m^2), mass (kg), broken (1 for a piece a break made), and
// contact_force (N) when the stepper keeps it. ASCII, so
// the files diff and grep, or binary: zlib-compressed appended data for large fields. Every file is
// written atomically and frames.pvd is rewritten after each frame, so a run that dies leaves a
// series that opens.
#pragma once
#include <filesystem>
#include <cstdint>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "framework/output/binary_archive.hpp"
#include "framework/world/world.hpp"

namespace gem {

class VtkSeriesWriter {
 public:
  // Creates runDir/frames (and runDir) if needed; throws std::runtime_error when it cannot.
  // binary: appended, zlib-compressed arrays (output.vtk_encoding = "binary"), else ASCII.
  explicit VtkSeriesWriter(std::filesystem::path runDir, bool binary = false);
  // Goes on from a checkpoint (save() wrote `in`'s next bytes): its frames listed again, and any
  // frame the stopped run wrote after the checkpoint removed.
  VtkSeriesWriter(std::filesystem::path runDir, bool binary, BinaryReader& in);

  // Writes the next frame_NNNNNN.vtp for simulation time `time` (s) and rewrites frames.pvd.
  // contactForces (optional, Stepper::contactForces): each body's contact force by id, written as
  // the contact_force cell array (0 for a body not listed).
  void addFrame(const World& world, double time, const std::vector<std::pair<std::int64_t, Real>>* contactForces = nullptr);
  // The .pvd is already whole after every frame; finish() only refuses later frames.
  void finish();

  int frameCount() const { return static_cast<int>(m_entries.size()); }
  // For a checkpoint: the frames' times and the bodies of frame 0.
  void save(BinaryWriter& out) const;

 private:
  void writeCollection();                   // frames.pvd
  static std::string frameFile(int index);  // "frames/frame_NNNNNN.vtp"
  struct Entry {
    double time;
    std::string file;  // relative to the run folder, as ParaView resolves it from the .pvd
  };
  std::filesystem::path m_runDir;
  std::vector<Entry> m_entries;
  bool m_binary = false;
  std::unordered_set<std::int64_t> m_firstIds;  // the bodies of frame 0: any other id is a piece
  bool m_finished = false;
};

}  // namespace gem
