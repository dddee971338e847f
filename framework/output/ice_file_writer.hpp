// Writes a run's frames as a thesis .ice file (the format: framework/field/ice_file.hpp).
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <unordered_map>
#include <vector>

#include "framework/output/binary_archive.hpp"
#include "framework/world/world.hpp"

namespace gem {

// Writes a World over time as a .ice file. Frames stream to a temporary file (memory stays bounded
// by the number of bodies, not frames); finish() writes the final file atomically with the right
// numFrames, since that attribute opens the file. Without finish() no .ice file appears.
class IceFileWriter {
 public:
  explicit IceFileWriter(std::filesystem::path path);
  // Goes on from a checkpoint (save() wrote `in`'s next bytes): the frames written by then, taken
  // from the stopped run's temporary or, when it finished its file (a signal), from that file.
  IceFileWriter(std::filesystem::path path, BinaryReader& in);
  ~IceFileWriter();
  IceFileWriter(const IceFileWriter&) = delete;
  IceFileWriter& operator=(const IceFileWriter&) = delete;

  // Appends a frame at simulation time `time` (s). The first call writes every body; later calls
  // write, per body, only the elements that differ from the values last written for its id by
  // more than a relative 1e-9 (absolute below magnitude 1), plus <removed/> for vanished ids.
  void addFrame(const World& world, double time);
  // Writes the final file. Further addFrame calls are errors; a second finish() does nothing.
  void finish();

  int frameCount() const { return m_frameCount; }
  // For a checkpoint: the frames flushed to the temporary, where they end, and what each id was
  // last written with (later frames are written as changes against it).
  void save(BinaryWriter& out);

 private:
  // What was last written for one id: changes are measured against it, so values that creep by
  // less than the tolerance per frame are still written once they add up.
  struct Written {
    std::vector<Vec2> coordinates;
    Real vx = 0, vy = 0, omega = 0, thickness = 0;
    BodyKind kind = BodyKind::Floe;
    int lastSeenFrame = -1;
  };

  std::filesystem::path m_path;
  std::filesystem::path m_framesPath;  // the temporary holding the <frame> elements
  std::ofstream m_frames;
  std::unordered_map<std::int64_t, Written> m_written;
  int m_frameCount = 0;
  bool m_finished = false;
};

}  // namespace gem
