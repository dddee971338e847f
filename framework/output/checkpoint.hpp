// A run's checkpoint, RUN_DIR/checkpoint.gem (docs/reliability.md "Checkpoints and resume"): the
// stepper's state, the runner's totals and where each output file stood, written every
// output.checkpoint_every and when a signal stops the run, so that `gem run --resume RUN_DIR` goes
// on from it and ends with the very files an uninterrupted run writes.
//
// The file is a header (what wrote it: the format, GEM's version, the real type, the byte order),
// the payload, and the payload's CRC-32. It is written under a temporary name and renamed, so a
// kill leaves the previous checkpoint or the new one, whole. A checkpoint is resumed by the GEM
// that wrote it; any other, or a damaged file, is refused with exit 2 naming the file.
#pragma once
#include <filesystem>
#include <string>

#include "framework/output/binary_archive.hpp"
#include "framework/step/stepper.hpp"
#include "framework/world/world.hpp"

namespace gem {

inline constexpr const char* kCheckpointFile = "checkpoint.gem";

void putWorld(BinaryWriter& out, const World& world);
void getWorld(BinaryReader& in, World& world);
void putStepperState(BinaryWriter& out, const StepperState& state);
void getStepperState(BinaryReader& in, StepperState& state);

// CRC-32 of bytes (zlib's): a checkpoint's payload, and the scenario.toml it belongs to.
std::uint32_t checksumOf(const std::string& bytes);

// The payload under its header and checksum, atomically.
void writeCheckpointFile(const std::filesystem::path& file, const std::string& payload);
// The payload of a checkpoint this GEM wrote; InputError naming the file when it is missing, was
// written by another version or build, or is damaged.
std::string readCheckpointFile(const std::filesystem::path& file);

}  // namespace gem
