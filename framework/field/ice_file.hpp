// The thesis .ice simulation file (thesis Appendix B): XML, one <frame> per saved scene; frame 0
// holds every object, later frames only what changed since the previous frame.
//
//   <iceFloeSim numFrames="N">
//     <frame index="0" time="0">
//       <object index="7" kind="vessel">
//         <coordinates>x0 y0 x1 y1 ...</coordinates>   world coordinates, m
//         <velocity x="vx" y="vy" a="omega"/>          m/s, m/s, rad/s
//         <thickness>0.7</thickness>                   m
//       </object>
//     </frame>
//     <frame index="1" time="0.5">
//       <object index="7"><velocity x=".." y=".." a=".."/></object>   only the changed elements
//       <object index="3"><removed/></object>                         gone (rubble, a split parent)
//     </frame>
//   </iceFloeSim>
//
// GEM extensions to the thesis format (a reader that ignores unknown attributes and elements still
// reads the thesis part):
//   - kind="floe|vessel|wall" on <object> (default floe); written for non-floes when an object
//     first appears;
//   - time="t" on <frame>: the simulation time of the frame, s;
//   - <removed/> inside an <object> of a later frame: the object no longer exists from that frame
//     on (rubble that left the simulation, a floe that split). Pieces of a split floe appear as new
//     indices with every element.
// The object index is the body's stable id (World::id); the root name is accepted in any case
// (the thesis writes both iceFloeSim and IceFloeSim).
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "framework/world/world.hpp"
#include "geometry/vec2.hpp"

namespace gem {

// One <object> as written in one frame: the has* flags say which elements were present.
struct IceObject {
  std::int64_t index = -1;
  std::vector<Vec2> coordinates;
  Vec2 velocity{0, 0};
  Real angularVelocity = 0;  // the velocity element's "a" attribute, rad/s
  Real thickness = 0;
  BodyKind kind = BodyKind::Floe;
  bool hasCoordinates = false, hasVelocity = false, hasThickness = false;
  bool hasKind = false;  // the kind attribute was given
  bool removed = false;  // <removed/> (GEM extension)
  std::string place;     // "FILE:LINE:COLUMN" of its <object> element, for messages about the polygon
};

struct IceFrame {
  int index = -1;
  double time = 0;  // the frame's time attribute (GEM extension), 0 when absent
  bool hasTime = false;
  std::vector<IceObject> objects;
};

// Reads and checks every frame, in file order. Throws InputError("FILE", line, column, message)
// for a missing or unreadable file, malformed XML, a wrong root element, a numFrames that does not
// match the frames present, a missing frame 0, a frame 0 object without coordinates or thickness,
// an odd number of coordinate values, fewer than 3 or more than kMaxVertices vertices, a number
// that is not a finite number, a non-positive thickness, an unknown kind, or a duplicate frame or
// object index.
std::vector<IceFrame> readIceFile(const std::filesystem::path& path);

// The bodies of frame 0, in file order: id = object index, origin = "FILE object N". Velocity
// defaults to zero when absent. Convexity and orientation are left to the caller's validation.
// Later frames are checked as XML but not converted (a long run's output may serve as a field).
std::vector<BodySpec> readIceInitialBodies(const std::filesystem::path& path);

}  // namespace gem
