// Golden hashes: a bit-exact fingerprint of a run, recorded before a refactoring and checked after
// it ("nothing changes in behaviour"). The fingerprint covers every step's outputs (the vessel's
// pose and velocity, its ice force, the contact count, every impact record, the breaking totals)
// and the final state of every body. Each Real is hashed by its bytes: one ulp of difference in any
// of them changes the hash.
#pragma once
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "framework/step/stepper.hpp"
#include "tests/test_support.hpp"

namespace gem::test {

// FNV-1a, 64 bits: simple, dependency-free and good enough to tell two runs apart.
class Fingerprint {
 public:
  template <class T>
  void add(const T& value) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>, "hash fields one by one: padding bytes are not part of a value");
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    for (unsigned char b : bytes) m_hash = (m_hash ^ b) * 1099511628211ull;
  }
  void add(Vec2 v) {
    add(v.x);
    add(v.y);
  }
  template <class T>
  void addAll(const std::vector<T>& values) {
    add(static_cast<std::uint64_t>(values.size()));
    for (const T& v : values) add(v);
  }
  std::uint64_t value() const { return m_hash; }

 private:
  std::uint64_t m_hash = 14695981039346656037ull;
};

// What a fingerprinted run went through: a scene that never touches ice guards nothing.
struct RunActivity {
  long contacts = 0, impacts = 0, floesBroken = 0;
};

// Steps `stepper` `steps` times, fingerprinting as it goes.
inline std::uint64_t fingerprintRun(Stepper& stepper, long steps, RunActivity* activity = nullptr) {
  Fingerprint f;
  for (long s = 0; s < steps; ++s) {
    stepper.step();
    if (activity) {
      activity->contacts += stepper.contactCount();
      activity->impacts += static_cast<long>(::gem::test::impactsOf(stepper).size());
      activity->floesBroken = stepper.floesBroken();
    }
    f.add(stepper.time());
    const VesselSample v = stepper.vessel();
    f.add(v.present);
    f.add(v.position);
    f.add(v.heading);
    f.add(v.velocity);
    f.add(stepper.vesselIceForce());
    f.add(stepper.contactCount());
    for (const ImpactRecord& r : ::gem::test::impactsOf(stepper)) {
      f.add(r.time);
      f.add(r.floeId);
      f.add(r.floeMass);
      f.add(r.thickness);
      f.add(r.apexDeg);
      f.add(r.frameAngleDeg);
      f.add(r.point);
      f.add(r.normal);
      f.add(r.xFromStem);
      f.add(r.yFromCenterline);
      f.add(r.closingSpeed);
      f.add(r.force);
      f.add(r.forceLimit);
      f.add(r.broke);
    }
    f.add(stepper.rubbleMass());
    f.add(stepper.floesBroken());
  }
  const World& w = stepper.hostWorld();
  f.addAll(w.id);
  f.addAll(w.kind);
  f.addAll(w.vertexCount);
  f.add(static_cast<std::uint64_t>(w.localVertices.size()));
  for (int i = 0; i < w.size(); ++i)
    for (int k = 0; k < w.vertexCount[i]; ++k) f.add(w.local(i)[k]);
  for (const auto* column : {&w.x, &w.y, &w.angle, &w.vx, &w.vy, &w.omega, &w.area, &w.thickness, &w.mass, &w.invMass, &w.invInertia,
                             &w.gyration2, &w.gyrationX2, &w.gyrationY2, &w.principalAngle, &w.radius})
    f.addAll(*column);
  return f.value();
}

// The recorded hashes: one "scene hash" pair a line, '#' starts a comment.
inline std::map<std::string, std::string> readGoldenFile(const std::filesystem::path& file) {
  std::map<std::string, std::string> hashes;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string scene, hash;
    if (words >> scene >> hash) hashes[scene] = hash;
  }
  return hashes;
}

inline std::string hex(std::uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
  return text;
}

}  // namespace gem::test
