#include "framework/output/checkpoint.hpp"

#include <zlib.h>

#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "framework/api/input_size.hpp"
#include "framework/output/atomic_file.hpp"

namespace gem {

namespace {

constexpr char kMagic[8] = {'G', 'E', 'M', 'C', 'K', 'P', 'T', '\n'};
constexpr std::uint32_t kFormat = 1;
constexpr std::uint32_t kByteOrderProbe = 0x01020304;

// What wrote a checkpoint: a file from another version or build is refused, not misread.
std::string writerText() { return fmt::format("gem {} real {} format {}", GEM_VERSION, sizeof(Real) == 8 ? "double" : "float", kFormat); }

}  // namespace

std::uint32_t checksumOf(const std::string& bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  size_t at = 0;
  while (at < bytes.size()) {  // crc32 takes a uInt length
    const auto n = static_cast<uInt>(std::min<size_t>(bytes.size() - at, 1u << 30));
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + at), n);
    at += n;
  }
  return static_cast<std::uint32_t>(crc);
}

// Every array of World, in its order. A member added to World must be added here too, or a resumed
// run would lose it: the size check below fails the build as a reminder.
static_assert(sizeof(World) == 20 * sizeof(std::vector<Real>) + sizeof(std::int64_t),
              "World changed: keep putWorld and getWorld (framework/output/checkpoint.cpp) in step with it");

void putWorld(BinaryWriter& out, const World& w) {
  out.put(w.id), out.put(w.kind), out.put(w.vertexCount), out.put(w.localVertices);
  out.put(w.x), out.put(w.y), out.put(w.angle), out.put(w.vx), out.put(w.vy), out.put(w.omega);
  out.put(w.area), out.put(w.thickness), out.put(w.mass), out.put(w.invMass), out.put(w.invInertia);
  out.put(w.gyration2), out.put(w.gyrationX2), out.put(w.gyrationY2), out.put(w.principalAngle), out.put(w.radius);
  out.put(w.nextId);
}

void getWorld(BinaryReader& in, World& w) {
  in.get(w.id), in.get(w.kind), in.get(w.vertexCount), in.get(w.localVertices);
  in.get(w.x), in.get(w.y), in.get(w.angle), in.get(w.vx), in.get(w.vy), in.get(w.omega);
  in.get(w.area), in.get(w.thickness), in.get(w.mass), in.get(w.invMass), in.get(w.invInertia);
  in.get(w.gyration2), in.get(w.gyrationX2), in.get(w.gyrationY2), in.get(w.principalAngle), in.get(w.radius);
  in.get(w.nextId);
  const size_t n = w.id.size();
  const bool consistent = w.kind.size() == n && w.vertexCount.size() == n && w.localVertices.size() == n * kMaxVertices &&
                          w.x.size() == n && w.y.size() == n && w.angle.size() == n && w.vx.size() == n && w.vy.size() == n &&
                          w.omega.size() == n && w.area.size() == n && w.thickness.size() == n && w.mass.size() == n &&
                          w.invMass.size() == n && w.invInertia.size() == n && w.gyration2.size() == n && w.gyrationX2.size() == n &&
                          w.gyrationY2.size() == n && w.principalAngle.size() == n && w.radius.size() == n;
  if (!consistent) throw InputError("checkpoint: damaged (the world's arrays differ in length)");
  for (const int count : w.vertexCount)
    if (count < 3 || count > kMaxVertices) throw InputError("checkpoint: damaged (a body with " + std::to_string(count) + " vertices)");
}

void putStepperState(BinaryWriter& out, const StepperState& s) {
  putWorld(out, s.world);
  out.put(s.step), out.put(s.time), out.put(s.touching), out.put(s.rubbleMass), out.put(s.floesBroken);
}

void getStepperState(BinaryReader& in, StepperState& s) {
  getWorld(in, s.world);
  in.get(s.step), in.get(s.time), in.get(s.touching), in.get(s.rubbleMass), in.get(s.floesBroken);
}

void writeCheckpointFile(const std::filesystem::path& file, const std::string& payload) {
  BinaryWriter header;
  header.put(kByteOrderProbe);
  header.put(writerText());
  header.put(static_cast<std::uint64_t>(payload.size()));
  AtomicFile out(file);
  out.stream().write(kMagic, sizeof kMagic);
  out.stream().write(header.bytes().data(), static_cast<std::streamsize>(header.bytes().size()));
  out.stream().write(payload.data(), static_cast<std::streamsize>(payload.size()));
  const std::uint32_t crc = checksumOf(payload);
  out.stream().write(reinterpret_cast<const char*>(&crc), sizeof crc);
  out.commit();
}

std::string readCheckpointFile(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (std::filesystem::exists(file, ec)) requireRegularFile(file, "checkpoint file");  // a folder, a pipe: said as such
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError(name + ": no checkpoint here (a run writes one every output.checkpoint_every, and when Ctrl-C or SIGTERM stops it)");
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(name + ": cannot be read");
  const std::string bytes = text.str();
  if (bytes.size() < sizeof kMagic || bytes.compare(0, sizeof kMagic, kMagic, sizeof kMagic) != 0)
    throw InputError(name + ": not a GEM checkpoint");
  const std::string rest = bytes.substr(sizeof kMagic);
  BinaryReader reader(rest, name);
  if (reader.get<std::uint32_t>() != kByteOrderProbe) throw InputError(name + ": written on a machine of another byte order");
  const auto writer = reader.get<std::string>();
  if (writer != writerText())
    throw InputError(fmt::format("{}: written by {}; this is {}: resume it with the GEM that wrote it", name, writer, writerText()));
  const auto size = reader.get<std::uint64_t>();
  const size_t start = sizeof kMagic + sizeof(std::uint32_t) + sizeof(std::uint64_t) + writer.size() + sizeof(std::uint64_t);
  if (size > bytes.size() || bytes.size() - start != size + sizeof(std::uint32_t)) throw InputError(name + ": cut short or damaged");
  std::string payload = bytes.substr(start, size);
  std::uint32_t crc = 0;
  std::memcpy(&crc, bytes.data() + start + size, sizeof crc);
  if (crc != checksumOf(payload)) throw InputError(name + ": damaged (its checksum does not match)");
  return payload;
}

}  // namespace gem
