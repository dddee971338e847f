#include "framework/scenario/scenario.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"
#include "framework/world/constants.hpp"
#include "framework/scenario/toml_limits.hpp"

namespace fs = std::filesystem;

namespace gem {

namespace {

// A table value given to a table merges into it, key by key and table by table below, as dotted
// --set's would: `--set simulation={dt=1}` sets simulation.dt and keeps the table's other keys
// (TOML's own meaning, the whole table replaced, dropped them silently). Any other value, an
// array included, replaces what is there.
void mergeValue(toml::table& into, std::string_view key, const toml::node& value) {
  toml::node* there = into.get(key);
  const toml::table* given = value.as_table();
  if (!given || !there || !there->is_table()) {
    into.insert_or_assign(key, value);
    return;
  }
  for (const auto& [k, v] : *given) mergeValue(*there->as_table(), k.str(), v);
}

// "a.b.c=VALUE": VALUE in TOML syntax (1.5, true, "x", [1, 2]); a bare word is taken as a string.
// An inline table ({dt = 1}) merges into the table already there (mergeValue).
void applyOverride(toml::table& root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--set {}: expected KEY=VALUE, e.g. simulation.dt=0.05", assignment));
  const std::string key = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  checkTomlLimits(assignment, "--set");
  toml::table parsed;
  try {
    parsed = toml::parse("value = " + text);
  } catch (const toml::parse_error&) {
    parsed = toml::table{{"value", text}};
  }
  // One value (an array may span lines): a newline must not slip a second key in unseen.
  if (parsed.size() != 1) throw InputError(fmt::format("--set {}: the value must be one TOML value, with no other key after it", key));
  toml::table* table = &root;
  std::stringstream path(key);
  std::string part;
  std::vector<std::string> parts;
  while (std::getline(path, part, '.')) parts.push_back(part);
  // Bare TOML keys joined by dots, each part named: "simulation..dt" or ".dt" would otherwise make
  // a key "" that the scenario's reader blames on the file, not on the --set.
  const bool bare = !key.empty() && key.back() != '.' && std::all_of(parts.begin(), parts.end(), [](const std::string& name) {
    return !name.empty() && std::all_of(name.begin(), name.end(), [](unsigned char c) { return std::isalnum(c) || c == '_' || c == '-'; });
  });
  if (!bare)
    throw InputError(fmt::format("--set {}=...: the key must be names of letters, digits, _ and - joined by dots, e.g. simulation.dt",
                                 key.size() > 80 ? key.substr(0, 80) + "..." : key));
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    toml::node* next = table->get(parts[i]);
    if (!next) next = &table->insert_or_assign(parts[i], toml::table{}).first->second;
    if (!next->is_table()) throw InputError(fmt::format("--set {}: {} is not a table", assignment, parts[i]));
    table = next->as_table();
  }
  mergeValue(*table, parts.back(), *parsed.get("value"));
}

// The largest |coordinate| of a domain's edge, m: far past any ice field (10,000 km), and small enough
// that the walls' and the field's arithmetic (spans, areas, cell counts) stays finite.
constexpr Real kMostDomainCoordinate = kMostCoordinate;
// A wall at least a centimetre thick: 1e-308 m made a rectangle too thin to be convex in doubles
// ("[domain] wall along y0: the polygon is not convex", naming no key).
constexpr Real kLeastWallThickness = 0.01;  // m

// The vessel's length and beam, and its hull's coordinates (m): from a model in a tank to ten
// kilometres; the default hull drawn from them stays a convex polygon of finite area.
constexpr Real kLeastHullSize = Real(0.1), kMostHullSize = 1e4;

constexpr Real kMostDt = 3600;  // s
// At least a microsecond: the step's forces are impulses over dt, and below about 1e-308 s 1/dt is
// inf (dt = 5e-324 s once wrote NaN to every ice_force_x of timeseries.csv, exit 0).
constexpr Real kLeastDt = 1e-6;  // s

Domain readDomain(TableReader& t, const Scenario& s) {
  Domain d = s.domain;
  auto within = [](Real v) { return std::fabs(v) <= kMostDomainCoordinate; };
  if (auto x = t.findReals("x")) {
    if (x->size() != 2 || !((*x)[0] < (*x)[1])) t.fail("x", "expected [x0, x1] with x0 < x1");
    if (!within((*x)[0]) || !within((*x)[1])) t.fail("x", fmt::format("each edge must be within +-{:g} m", kMostDomainCoordinate));
    d.x0 = (*x)[0], d.x1 = (*x)[1];
  } else {
    t.recordDefault("x", toml::array{static_cast<double>(d.x0), static_cast<double>(d.x1)});
  }
  if (auto y = t.findReals("y")) {
    if (y->size() != 2 || !((*y)[0] < (*y)[1])) t.fail("y", "expected [y0, y1] with y0 < y1");
    if (!within((*y)[0]) || !within((*y)[1])) t.fail("y", fmt::format("each edge must be within +-{:g} m", kMostDomainCoordinate));
    d.y0 = (*y)[0], d.y1 = (*y)[1];
  } else {
    t.recordDefault("y", toml::array{static_cast<double>(d.y0), static_cast<double>(d.y1)});
  }
  return d;
}

void readField(TableReader& t, Scenario& s) {
  s.fieldKind = t.getChoice("kind", "random_convex", {"random_convex", "hexagons", "file"});
  if (s.fieldKind == "file") {
    const std::string file = t.getPath("file", "");
    if (file.empty()) t.fail("file", "kind = \"file\" needs file = \"path/to/field.ice\"");
    s.fieldFile = fs::path(file).is_absolute() ? fs::path(file) : s.file.parent_path() / file;
    t.finish();
    return;
  }
  const Real concentration = t.getPositive("concentration", s.fieldKind == "hexagons" ? Real(0.46) : Real(0.4));
  // A random field of thickness groups takes each floe's thickness from its group: field.thickness
  // is then read only when given, so that a run's scenario.toml shows no default that took no effect.
  const bool thicknessFromGroups = s.fieldKind == "random_convex" && t.has("groups") && !t.has("thickness");
  if (thicknessFromGroups) t.accept("thickness");
  const Real thickness = thicknessFromGroups ? Real(0.7) : t.getRealIn("thickness", Real(0.7), kLeastIceThickness, kMostIceThickness);
  const Real minGap = t.getNonNegative("min_gap", Real(0.05));
  if (s.fieldKind == "hexagons") {
    HexagonFieldSpec& h = s.hexagonField;
    h.domain = s.domain;
    h.concentration = concentration;
    h.thickness = thickness;
    h.minGap = minGap;
    h.size = t.getPositive("size", Real(10.1));
    h.rotationJitterDeg = t.getNonNegative("rotation_jitter_deg", 3);
    h.count = static_cast<int>(t.getInt("count", 0, 0, 100000000));
    h.seed = s.seed;
  } else {
    RandomFieldSpec& r = s.randomField;
    r.domain = s.domain;
    r.concentration = concentration;
    r.thickness = thickness;
    r.minGap = minGap;
    r.count = static_cast<int>(t.getInt("count", 0, 0, 100000000));
    r.sizeMean = t.getPositive("size_mean", r.sizeMean);
    r.sizeSd = t.getNonNegative("size_sd", r.sizeSd);
    r.sizeMin = t.getPositive("size_min", r.sizeMin);
    r.sizeMax = t.getPositive("size_max", r.sizeMax);
    r.minSides = static_cast<int>(t.getInt("min_sides", r.minSides, 3, kMaxFloeVertices));
    r.maxSides = static_cast<int>(t.getInt("max_sides", r.maxSides, 3, kMaxFloeVertices));
    r.maxAspect = t.getPositive("max_aspect", r.maxAspect);
    r.seed = s.seed;
    if (const toml::array* groups = t.findArray("groups")) {
      for (size_t g = 0; g < groups->size(); ++g) {
        const toml::table* gt = groups->get(g)->as_table();
        if (!gt) t.failAt(*groups->get(g), "field.groups: expected tables { coverage = ..., thickness = ... }");
        TableReader gr(gt, fmt::format("field.groups[{}]", g), s.fileName);
        ThicknessGroup group{gr.getPositive("coverage", 0), gr.getRealIn("thickness", Real(0.7), kLeastIceThickness, kMostIceThickness)};
        if (!gr.has("coverage") || !gr.has("thickness")) gr.fail("coverage", "each group needs coverage and thickness");
        gr.finish();
        r.groups.push_back(group);
      }
    }
  }
  t.finish();
}

void readFloes(const toml::array& floes, TableReader& parent, Scenario& s) {
  for (size_t k = 0; k < floes.size(); ++k) {
    const toml::table* ft = floes.get(k)->as_table();
    if (!ft) parent.failAt(*floes.get(k), "floes: expected [[floes]] tables");
    TableReader t(ft, fmt::format("floes[{}]", k), s.fileName);
    BodySpec spec;
    spec.kind = BodyKind::Floe;
    auto vertices = t.findPoints("vertices");
    if (!vertices) t.fail("vertices", "each floe needs vertices = [[x, y], ...]");
    spec.vertices = *vertices;
    spec.thickness = t.getRealIn("thickness", Real(0.7), kLeastIceThickness, kMostIceThickness);
    spec.velocity = t.getVec2("velocity", Vec2{0, 0});
    if (!(std::fabs(spec.velocity.x) <= kMostStartSpeed && std::fabs(spec.velocity.y) <= kMostStartSpeed)) {
      t.report("velocity",
               fmt::format("each component must be within +-{:g} m/s, got [{}, {}]", kMostStartSpeed, spec.velocity.x, spec.velocity.y));
      spec.velocity = Vec2{0, 0};
    }
    spec.angularVelocity = t.getRealIn("angular_velocity", 0, -kMostStartAngularSpeed, kMostStartAngularSpeed);
    const auto& src = ft->source();
    // Where the floe was written: its line in the file, or the --set that gave the floes.
    std::string setBy;
    for (const std::string& o : s.overrides)
      if (o.rfind("floes=", 0) == 0) setBy = o;
    spec.origin = src.path ? fmt::format("{}:{}:{}: floes[{}]", s.fileName, src.begin.line, src.begin.column, k)
                           : fmt::format("--set {}: floes[{}]", setBy.empty() ? std::string("floes=...") : setBy, k);
    t.finish();
    s.floes.push_back(std::move(spec));
  }
}

// Open-water speed for a bollard thrust when the scenario gives none: the thesis's pairs (issue 2;
// thesis 6.2.1: 23 kN 1.4 m/s ... 740 kN 6.5 m/s), interpolated linearly in log T - log V, so
// that --set vessel.bollard_thrust=92e3 alone gives the thesis's 2.6 m/s.
Real openWaterSpeedFor(Real bollardThrust) {
  static const Real table[][2] = {{23e3, 1.4}, {46e3, 1.9}, {92e3, 2.6}, {181.5e3, 3.6}, {370e3, 4.9}, {740e3, 6.5}};
  constexpr int n = 6;
  const Real t = std::max<Real>(bollardThrust, 1);
  int k = 0;
  while (k < n - 2 && t > table[k + 1][0]) ++k;
  const Real f = std::log(t / table[k][0]) / std::log(table[k + 1][0] / table[k][0]);
  return table[k][1] * std::exp(f * std::log(table[k + 1][1] / table[k][1]));
}

void readVessel(TableReader& t, Scenario& s) {
  VesselSpec& v = s.vessel;
  v.present = true;
  // Each key in a range that keeps the first step finite (docs/scenario.md 2.5): beyond it the hull,
  // the mass properties or the first step overflowed, and the error named vessel.vertices or
  // came from gem run at step 1.
  v.length = t.getRealIn("length", v.length, kLeastHullSize, kMostHullSize);
  v.beam = t.getRealIn("beam", v.beam, kLeastHullSize, kMostHullSize);
  v.mass = t.getRealIn("mass", v.mass, 1, 1e12);
  v.draft = t.getPositive("draft", v.draft, 1000);
  v.position = t.getVec2("position", v.position);
  if (!(std::fabs(v.position.x) <= kMostDomainCoordinate && std::fabs(v.position.y) <= kMostDomainCoordinate)) {
    t.report("position",
             fmt::format("each coordinate must be within +-{:g} m, got [{}, {}]", kMostDomainCoordinate, v.position.x, v.position.y));
    v.position = VesselSpec{}.position;
  }
  v.headingDeg = t.getRealIn("heading_deg", 0, -360, 360);
  v.dof = static_cast<int>(t.getInt("dof", 1, 1, 3));
  if (v.dof == 2) t.fail("dof", "must be 1 (surge) or 3 (surge, sway, yaw)");
  v.bollardThrust = t.getRealIn("bollard_thrust", v.bollardThrust, 0, 1e8);
  v.openWaterSpeed = t.getRealIn("open_water_speed", openWaterSpeedFor(v.bollardThrust), Real(0.01), kMostStartSpeed);
  v.speed = t.getRealIn("speed", v.openWaterSpeed, 0, kMostStartSpeed);  // docs/model.md 7: starts at V_ow
  // No vertices: the default hull, drawn to length and beam (defaultHull); it stays unwritten in a
  // run's scenario.toml, so that a changed length or beam still reshapes it.
  auto hull = t.findPoints("vertices");
  auto frames = t.findReals("frame_angle_deg");
  if (hull) {
    if (hull->size() < 3)
      t.fail("vertices", fmt::format("a hull needs at least 3 vertices, got {} (leave the key out for the default hull)", hull->size()));
    if (!frames) t.fail("vertices", "a hull given by vertices also needs frame_angle_deg (one per edge)");
    for (const Vec2& p : *hull)
      if (!(std::fabs(p.x) <= kMostHullSize && std::fabs(p.y) <= kMostHullSize))
        t.fail("vertices", fmt::format("each coordinate must be within +-{:g} m (the ship frame), got [{}, {}]", kMostHullSize, p.x, p.y));
    if (frames->size() != hull->size())
      t.fail("frame_angle_deg", fmt::format("needs one angle per hull edge: {} vertices, {} angles", hull->size(), frames->size()));
    for (Real b : *frames)
      if (b < 0 || b >= 90) t.fail("frame_angle_deg", fmt::format("angles must be in [0, 90) degrees, got {}", b));
    v.hull = *hull;
    v.frameAnglesDeg = *frames;
  } else if (frames) {
    t.fail("frame_angle_deg", "only with vertices = [...] (the default hull has its own)");
  }
  t.finish();
}

// Whether the ray from p along the unit vector d (t >= 0) meets the rectangle [lo, hi].
bool rayMeetsBox(Vec2 p, Vec2 d, Vec2 lo, Vec2 hi) {
  double near = 0, far = std::numeric_limits<double>::infinity();
  const double from[2] = {p.x, p.y}, along[2] = {d.x, d.y}, low[2] = {lo.x, lo.y}, high[2] = {hi.x, hi.y};
  for (int axis = 0; axis < 2; ++axis) {
    if (std::fabs(along[axis]) < 1e-12) {  // along the other axis (cos 90 deg is 6e-17, not 0)
      if (from[axis] < low[axis] || from[axis] > high[axis]) return false;
      continue;
    }
    double a = (low[axis] - from[axis]) / along[axis], b = (high[axis] - from[axis]) / along[axis];
    if (a > b) std::swap(a, b);
    near = std::max(near, a), far = std::min(far, b);
    if (near > far) return false;
  }
  return true;
}

// A vessel the [domain] says can never reach the field (docs/scenario.md 2.5, `position`): the
// vessel sails forward along its heading (a 3-DOF vessel along the autopilot's set track, through
// its start along the set heading), so the line it sails from `position` must come within the
// hull's reach of the domain's rectangle; with walls it starts between them, since it cannot cross
// one. The domain's ends are open: a vessel before the field, facing it, is the usual start. With
// no [domain] nothing is checked (the field is then where the floes are), nor with a plugin's event
// enabled (see below). Explicit floes and a .ice field's objects may lie anywhere: the domain
// bounds the generated field and the statistics, not the bodies, and floes leave it through its
// open ends in any run.
void checkVesselCanReachDomain(Scenario& s) {
  const VesselSpec& v = s.vessel;
  if (!v.present || !s.hasDomain) return;
  // An event from a plugin may steer or carry the vessel in ways the check cannot foresee (its own
  // autopilot, a towline): with one enabled, the start is taken as given.
  for (const EventEntry* e : Registry::global().events()) {
    if (e->origin == "built-in") continue;
    const auto setting = s.events.find(e->name);
    if (setting != s.events.end() ? setting->second.enabled : e->enabledByDefault) return;
  }
  // An error already reported about one of these keys took the key's default: what follows from
  // that default is no new error.
  if (const ErrorCollector* errors = ErrorCollector::active())
    for (const char* key : {"vessel.position", "vessel.heading_deg", "vessel.dof", "vessel.length", "vessel.beam", "vessel.vertices"})
      if (errors->followsFrom(fmt::format(" {}:", key))) return;
  TableReader t(s.root["vessel"].as_table(), "vessel", s.fileName);
  const Domain& d = s.domain;
  const std::string domain = fmt::format("[domain] x = [{}, {}], y = [{}, {}]", d.x0, d.x1, d.y0, d.y1);
  const std::string value = fmt::format("[{}, {}]", v.position.x, v.position.y);
  if (s.walls && !(v.position.y >= d.y0 && v.position.y <= d.y1))
    return t.report("position", fmt::format("{} lies outside the channel between the walls of the {}: the vessel can never reach "
                                            "the field; start it between y = {} and y = {}",
                                            value, domain, d.y0, d.y1));
  // The hull's reach from its centroid (its farthest vertex, m), as the stop rule vessel_left_field
  // takes it; a hull of no area (refused when the world is built) takes its span instead.
  Real reach = 0, span = 0;
  const HullGeometry hull = hullGeometry(v);
  for (const Vec2& a : hull.vertices) {
    reach = std::max(reach, norm(a));
    for (const Vec2& b : hull.vertices) span = std::max(span, norm(a - b));
  }
  if (!(std::isfinite(reach) && reach > 0)) reach = span;
  const Vec2 lo{d.x0 - reach, d.y0 - reach}, hi{d.x1 + reach, d.y1 + reach};
  std::vector<Real> headings{v.headingDeg};
  // A 3-DOF vessel turns to the autopilot's set heading (its event checks the value later).
  if (v.dof == 3)
    if (const auto set = s.root["events"]["autopilot"]["heading_deg"].value<double>(); set && std::fabs(*set) <= 360)
      headings.push_back(static_cast<Real>(*set));
  for (const Real h : headings)
    if (rayMeetsBox(v.position, Vec2{std::cos(h * kPi / 180), std::sin(h * kPi / 180)}, lo, hi)) return;
  const std::string course = headings.size() == 1 || headings[0] == headings[1]
                                 ? fmt::format("heading {} deg", v.headingDeg)
                                 : fmt::format("heading {} deg or the autopilot's {} deg", headings[0], headings[1]);
  t.report("position",
           fmt::format("{}, sailing at {}, never comes within the hull's reach ({:.3g} m from its centroid) of the {}: the vessel "
                       "can never reach the field; place it before the field, facing it",
                       value, course, reach, domain));
}

// output.checkpoint_every: a whole number of steps (1000), or a wall-clock interval as a string
// ("90s", "10min", "2h"): a batch job's time limit is wall-clock time.
void readCheckpointEvery(TableReader& t, OutputSpec& o) {
  const toml::node* every = t.findNode("checkpoint_every");
  if (!every) return;
  const std::string expected =
      "output.checkpoint_every: expected a number of steps from 1 to 2e9 (1000) or a wall-clock interval (\"90s\", \"10min\", \"2h\")";
  if (const auto steps = every->value_exact<std::int64_t>()) {
    if (*steps < 1 || *steps > 2000000000) return t.reportAt(*every, fmt::format("{}, got {}", expected, *steps));
    o.checkpointEverySteps = static_cast<long>(*steps);
    return;
  }
  const auto text = every->value_exact<std::string>();
  if (!text) return t.reportAt(*every, expected);
  double value = 0;
  size_t used = 0;
  try {
    value = std::stod(*text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string unit = text->substr(std::min(used, text->size()));
  const double scale = unit == "s" ? 1 : unit == "min" ? 60 : unit == "h" ? 3600 : 0;
  const double seconds = value * scale;
  if (used == 0 || scale == 0 || !(seconds >= 1 && seconds <= 1e7))
    return t.reportAt(*every, fmt::format("{}; an interval is 1 s to 1e7 s, a number followed by s, min or h, got \"{}\"", expected,
                                          text->substr(0, 100)));
  o.checkpointEverySeconds = seconds;
}

void readOutput(TableReader& t, Scenario& s) {
  OutputSpec& o = s.output;
  const std::string dir = t.getPath("dir", "");
  if (!dir.empty()) o.dir = fs::path(dir).is_absolute() ? fs::path(dir) : s.file.parent_path() / dir;
  o.frameEvery = static_cast<int>(t.getInt("frame_every", o.frameEvery, 0, 1000000000));
  o.timeseriesEvery = static_cast<int>(t.getInt("timeseries_every", o.timeseriesEvery, 1, 1000000000));
  if (const toml::array* formats = t.findArray("formats")) {
    o.formats.clear();
    for (const toml::node& f : *formats) {
      auto name = f.value_exact<std::string>();
      if (!name || (*name != "vtk" && *name != "ice")) t.failAt(f, "output.formats: valid formats are \"vtk\" and \"ice\"");
      // Twice would write one set of frames (it was taken as once): say so rather than guess.
      if (name && std::find(o.formats.begin(), o.formats.end(), *name) != o.formats.end())
        t.failAt(f, fmt::format("output.formats: \"{}\" is listed twice", *name));
      o.formats.push_back(*name);
    }
  } else {
    toml::array formatsTaken;
    for (const std::string& f : o.formats) formatsTaken.push_back(f);
    t.recordDefault("formats", std::move(formatsTaken));
  }
  o.vtkBinary = t.getChoice("vtk_encoding", "ascii", {"ascii", "binary"}) == "binary";
  readCheckpointEvery(t, o);
  t.finish();
}

// [[plugins]]: path (relative to the scenario's folder) and override. Each is required from the
// registry's plugin loader now (its names are then valid below); the
// loader's message (what differs, which symbol is missing, which names clash) gets this entry's
// file:line:column. The path is written back absolute, so a copy of root (a sweep case's
// scenario.toml) still finds it.
void readPlugins(const toml::array& plugins, TableReader& top, Scenario& s) {
  for (size_t k = 0; k < plugins.size(); ++k) {
    const toml::node& p = *plugins.get(k);
    const toml::table* pt = p.as_table();
    if (!pt) top.failAt(p, "plugins: expected [[plugins]] tables");
    TableReader t(pt, "plugins", s.fileName);
    PluginSpec spec;
    if (!t.has("path")) t.failAt(p, "plugins: each [[plugins]] needs a path = \"...\" (to the plugin's .so)");
    spec.path = t.getPath("path", "");
    if (spec.path.empty()) {  // refused (an empty path): it would name the scenario's folder
      t.finish();
      continue;
    }
    // Read as "plugins" (the messages name no index), so its default is recorded here by index.
    if (DefaultsRecorder* recorder = DefaultsRecorder::active(); recorder && !t.has("override"))
      recorder->record(fmt::format("plugins[{}].override", k), false);
    spec.override = t.getBool("override", false);
    t.finish();
    if (spec.path.is_relative()) spec.path = s.file.parent_path() / spec.path;
    spec.path = spec.path.lexically_normal();
    try {
      requirePluginLibrary(spec.path, spec.override);
    } catch (const InputError& e) {
      t.fail("path", e.what());
    }
    const_cast<toml::table*>(pt)->insert_or_assign("path", spec.path.string());
    s.plugins.push_back(spec);
  }
}

// A strategy's settings from `t` into `settings` (docs/scenario.md [broadphase.NAME]): only the
// keys the strategy declares; any other broadphase key is refused, naming the strategies that do
// take it. A key set twice (in [simulation] and in [broadphase.NAME]) is refused too.
void readBroadphaseSettings(TableReader& t, const BroadphaseEntry& strategy, BroadphaseSettings& settings) {
  // The strategy's settings are this table's keys whether it gives them or not: an unknown key's
  // message lists them among the valid ones.
  for (const std::string& key : strategy.settings) t.accept(key);
  for (const std::string& key : broadphaseSettingKeys()) {
    if (!t.has(key)) continue;
    const auto& own = strategy.settings;
    if (std::find(own.begin(), own.end(), key) == own.end()) {
      std::vector<std::string> takers;
      for (const BroadphaseEntry* b : Registry::global().broadphases())
        if (std::find(b->settings.begin(), b->settings.end(), key) != b->settings.end()) takers.push_back(b->name);
      t.fail(key, fmt::format("the broadphase \"{}\" has no setting {} ({}); {} take{} it", strategy.name, key,
                              own.empty() ? "it has no settings" : "its settings: " + fmt::format("{}", fmt::join(own, ", ")),
                              fmt::join(takers, ", "), takers.size() == 1 ? "s" : ""));
    }
    if (std::find(settings.given.begin(), settings.given.end(), key) != settings.given.end())
      t.fail(key, "given twice: in [simulation] and in [broadphase." + strategy.name + "]; keep one");
    settings.given.push_back(key);
    if (key == "skin") settings.skin = t.getNonNegative(key, settings.skin);
    if (key == "fixed_radius") settings.fixedRadius = t.getNonNegative(key, settings.fixedRadius);
    if (key == "cell_size") settings.cellSize = t.getNonNegative(key, settings.cellSize);
  }
}

// [broadphase.NAME] tables: each names a registered strategy and holds only its settings. The
// chosen strategy's table applies; another's is still checked (a sweep may switch strategies).
void readBroadphaseTables(const toml::table& tables, Scenario& s) {
  TableReader all(&tables, "broadphase", s.fileName);
  for (const auto& [name, node] : tables) {
    const std::string key(name.str());
    const BroadphaseEntry* strategy = nullptr;
    try {
      strategy = &Registry::global().broadphase(key);
    } catch (const InputError& e) {
      all.fail(key, e.what());
    }
    if (!node.is_table()) all.fail(key, "expected a table [broadphase." + key + "] of the strategy's settings");
    all.accept(key);
    TableReader t(node.as_table(), "broadphase." + key, s.fileName);
    BroadphaseSettings settings = key == s.broadphase ? s.broadphaseSettings : BroadphaseSettings{};
    readBroadphaseSettings(t, *strategy, settings);
    t.finish();
    if (key == s.broadphase) s.broadphaseSettings = settings;
  }
  all.finish();
}

}  // namespace

double fieldMemoryNeed(double floes) { return floes * 3072; }

// A generated field's size is known before it is made: refuse one that could not fit in this
// machine's memory, with the estimate, instead of growing until std::bad_alloc (docs/scenario.md).
// About 3 KB a floe: its polygon and state, and the step's per-body and per-contact buffers.
void checkFieldMemory(const Scenario& s) {
  if (s.fieldKind != "random_convex" && s.fieldKind != "hexagons") return;
  const double area = (static_cast<double>(s.domain.x1) - s.domain.x0) * (static_cast<double>(s.domain.y1) - s.domain.y0);
  double floes = 0;
  if (s.fieldKind == "hexagons") {
    floes = s.hexagonField.count > 0
                ? s.hexagonField.count
                : area * s.hexagonField.concentration / (static_cast<double>(s.hexagonField.size) * s.hexagonField.size);
  } else {
    const RandomFieldSpec& r = s.randomField;
    const double meanArea = static_cast<double>(r.sizeMean) * r.sizeMean + static_cast<double>(r.sizeSd) * r.sizeSd;
    floes = r.count > 0 ? r.count : area * r.concentration / meanArea;
  }
  const double need = fieldMemoryNeed(floes), have = machineMemory();
  if (need > 0.8 * have || floes > 2e8)
    throw InputError(
        s.fileName, 0, 0,
        fmt::format("field: about {:.3g} floes (the domain's {:.3g} m^2 x concentration / floe area), which need about {:.3g} GB; "
                    "this machine has {:.3g} GB: make the [domain] smaller or the floes larger",
                    floes, area, need / 1e9, have / 1e9));
}

const toml::table* Scenario::eventTable(const std::string& name) const {
  const toml::table* events = (document ? *document : root)["events"].as_table();
  return events ? (*events)[name].as_table() : nullptr;
}

namespace {

// The scenario's tables into s (loadScenario: s.root parsed, overrides applied).
void readScenarioTables(Scenario& s) {
  TableReader top(&s.root, "", s.fileName);
  // Plugins first: their events and broadphases are valid names in the sections below.
  requireEnvironmentPluginLibraries();
  if (const toml::array* plugins = top.findArray("plugins")) readPlugins(*plugins, top, s);
  {
    TableReader t(top.findTable("simulation"), "simulation", s.fileName);
    // At most an hour: a longer step is no ship-in-ice step, and from 1e300 s the first one overflowed.
    s.dt = t.getRealIn("dt", s.dt, kLeastDt, kMostDt);
    const bool hasSteps = t.has("steps");
    s.duration = t.getPositive("duration", s.duration);
    const std::int64_t steps = t.getInt("steps", 0, 1, 2000000000);
    if (hasSteps && t.has("duration")) t.fail("steps", "give either duration or steps, not both");
    if (!hasSteps) {
      // duration / dt is checked as a double before it becomes a count: 1e300 s, or dt = 1e-300 s,
      // would overflow it (docs/scenario.md: at most 2e9 steps).
      const double count = static_cast<double>(s.duration) / static_cast<double>(s.dt);
      if (!(count >= 0.5)) t.fail("duration", fmt::format("shorter than one step of dt = {} s", s.dt));
      if (!(count <= 2e9)) t.fail("duration", fmt::format("duration / dt = {:.3g} steps, more than the 2e9 a run may take", count));
    }
    s.steps = hasSteps ? static_cast<long>(steps) : static_cast<long>(std::llround(s.duration / s.dt));
    if (hasSteps) s.duration = static_cast<Real>(s.steps) * s.dt;
    // The step's time, k x dt, stays finite to the end (dt = 1e308 s would make it inf by step 2).
    if (!std::isfinite(s.duration)) t.fail("dt", fmt::format("steps x dt = {} x {:g} s is not a finite time", s.steps, s.dt));
    s.backend = t.getChoice("backend", "auto", {"auto", "cpu", "cuda"});
    const std::string defaultBroadphase = s.broadphase;
    s.broadphase = t.getString("broadphase", s.broadphase);
    try {
      Registry::global().broadphase(s.broadphase);  // unknown name: lists the valid ones
    } catch (const InputError& e) {
      t.report("broadphase", e.what());
      s.broadphase = defaultBroadphase;  // read on with the default (the error is recorded)
    }
    s.seed = static_cast<std::uint64_t>(t.getInt("seed", 1, 0, INT64_MAX));
    // The older home of the broadphase settings; [broadphase.NAME] is the strategy's own table.
    readBroadphaseSettings(t, Registry::global().broadphase(s.broadphase), s.broadphaseSettings);
    s.mortonSort = t.getBool("morton_sort", true);
    s.copyBackEvery = static_cast<int>(t.getInt("copy_back_every", s.copyBackEvery, 1, 100000));
    s.cudaBlockSize = static_cast<int>(t.getInt("cuda_block_size", s.cudaBlockSize, 32, 1024));
    if (s.cudaBlockSize % 32 != 0) t.fail("cuda_block_size", "must be a multiple of 32 (a whole number of warps)");
    s.cudaDriver = t.getChoice("cuda_driver", s.cudaDriver, {"auto", "resident", "device"});
    s.threads = static_cast<int>(t.getInt("threads", s.threads, 0, 1024));
    s.stopWhen = t.getChoice("stop_when", s.stopWhen, {"duration", "vessel_left_field", "distance"});
    if (s.stopWhen == "distance" && !t.has("stop_distance"))
      t.fail("stop_when", "stop_when = \"distance\" needs simulation.stop_distance (m)");
    if (s.stopWhen != "distance" && t.has("stop_distance")) t.fail("stop_distance", "only read with stop_when = \"distance\"");
    // Read only where it applies: a recorded default beside another stop rule would be refused.
    if (s.stopWhen == "distance")
      s.stopDistance = t.getPositive("stop_distance", Real(1));
    else
      t.accept("stop_distance");
    t.finish();
  }
  if (const toml::table* b = top.findTable("broadphase")) readBroadphaseTables(*b, s);
  if (const toml::table* d = top.findTable("domain")) {
    TableReader t(d, "domain", s.fileName);
    s.hasDomain = true;
    s.domain = readDomain(t, s);
    s.walls = t.getBool("walls", false);
    // Without walls wall_thickness is read only when given (checked all the same): a run's
    // scenario.toml shows no default that took no effect.
    if (s.walls || t.has("wall_thickness"))
      s.wallThickness = t.getRealIn("wall_thickness", s.wallThickness, kLeastWallThickness, kMostDomainCoordinate);
    else
      t.accept("wall_thickness");
    t.finish();
  }
  if (const toml::table* v = top.findTable("vessel")) {
    TableReader t(v, "vessel", s.fileName);
    readVessel(t, s);
  }
  if (const toml::table* f = top.findTable("field")) {
    TableReader t(f, "field", s.fileName);
    readField(t, s);
  }
  if (const toml::array* floes = top.findArray("floes")) readFloes(*floes, top, s);
  if (const toml::table* events = top.findTable("events")) {
    for (const auto& [key, node] : *events) {
      const std::string name(key.str());
      if (!Registry::global().findEvent(name)) {
        top.reportAt(node, fmt::format("events.{}: unknown event{} (valid: {})", name, didYouMean(name, Registry::global().eventNames()),
                                       fmt::join(Registry::global().eventNames(), ", ")));
        continue;
      }
      const toml::table* table = node.as_table();
      if (!table) top.failAt(node, fmt::format("events.{}: expected a table [events.{}]", name, name));
      bool enabled = true;
      if (const toml::node* e = table->get("enabled")) {
        auto b = e->value_exact<bool>();
        if (!b) top.failAt(*e, fmt::format("events.{}.enabled: expected true or false", name));
        enabled = *b;
      }
      s.events[name] = Scenario::EventSetting{enabled};
    }
  }
  {
    s.output.dir = fs::current_path() / "runs" / s.file.stem();
    TableReader t(top.findTable("output"), "output", s.fileName);
    readOutput(t, s);
  }
  top.finish();

  if (s.stopWhen != "duration" && !s.vessel.present)
    TableReader(top.findTable("simulation"), "simulation", s.fileName)
        .fail("stop_when", fmt::format("stop_when = \"{}\" follows the vessel, and this scenario has no [vessel]", s.stopWhen));
  checkVesselCanReachDomain(s);
  if (s.fieldKind != "none" && s.fieldKind != "file" && !s.hasDomain)
    throw InputError(fmt::format("{}: a generated [field] needs a [domain] with x = [x0, x1] and y = [y0, y1]", s.fileName));
  // The field was read before [domain] may have been: bind the generators to the final domain.
  s.randomField.domain = s.domain;
  s.hexagonField.domain = s.domain;
  checkFieldMemory(s);
}

}  // namespace

Scenario loadScenario(const fs::path& file, const std::vector<std::string>& overrides) {
  Scenario s;
  s.fileName = file.string();
  const std::string text = readTomlFile(s.fileName, "scenario");  // bounded before the parser sees it
  s.file = fs::absolute(file);
  try {
    s.root = toml::parse(text, s.file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(s.fileName, static_cast<int>(e.source().begin.line), static_cast<int>(e.source().begin.column),
                     std::string(e.description()));
  }
  for (const std::string& o : overrides) applyOverride(s.root, o);
  s.overrides = overrides;
  const OverrideScope blameSet(s.overrides);  // an error in a --set value names the --set
  if (s.root.empty())
    throw InputError(fmt::format("{}: nothing in it: a scenario needs at least a [simulation] table or bodies", s.fileName));

  // Every error of the tables at once (each bad value is recorded and its default used), then
  // any that stopped the reading: the user fixes them in one round.
  ErrorCollector errors;
  // The defaults every table took (the run's scenario.toml writes them beside the keys given).
  const DefaultsRecorder defaults(*s.defaultsTaken);
  try {
    readScenarioTables(s);
  } catch (const InputError& e) {
    if (!errors.followsFrom(e.what())) errors.add(e.what());
  }
  errors.throwIfAny();
  // The document with its lines and columns, shared by every copy of s (a copied toml table
  // loses them), so that an event's error names its line; root becomes a copy to edit.
  s.document = std::make_shared<const toml::table>(std::move(s.root));
  s.root = *s.document;
  return s;
}

}  // namespace gem
