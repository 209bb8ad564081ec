// Scene parser: YAML -> validated Scene.
//
// Two layers:
//  1. A small reading layer (Field, Map, Range; dem/scene/yaml_reader.hpp) that turns
//     YAML nodes into numbers, vectors, names and model choices, checking type and range
//     and remembering where in the file each value came from, so every error can point
//     at it.
//  2. One function per scene section, which only says what the section contains.
// The first mistake found throws a SceneError; nothing is collected or deferred.
#include "dem/scene/scene_parser.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iomanip>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_set>
#include <utility>
#include <vector>

#include "dem/core/fnv1a.hpp"
#include "dem/core/number_format.hpp"
#include "dem/io/snapshot_reader.hpp"
#include "dem/io/xdmf_index.hpp"
#include "dem/scene/fluid_section.hpp"
#include "dem/scene/yaml_reader.hpp"

namespace grainflow {

namespace {

namespace fs = std::filesystem;

using namespace scene_yaml;  // the reading layer: dem/scene/yaml_reader.hpp

// ---------------------------------------------------------------------------
// Scene sections

// A reference to a material by name; returns its index.
int material_ref(const Field& f, const std::vector<Material>& materials) {
  const std::string name = f.text();
  std::vector<std::string> known;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].name == name) return static_cast<int>(i);
    known.push_back(materials[i].name);
  }
  f.fail("unknown material '" + name + "'; known materials: " + join(known) +
         suggestion(name, known));
}

int material_ref(const Map& m, std::string_view key, const std::vector<Material>& materials) {
  return material_ref(m.get(key, "add `" + std::string(key) + ": <material name>`"), materials);
}

Domain parse_domain(const Field& f) {
  const Map m = f.map({"min", "max", "periodic"});
  Domain d;
  d.lo = m.vec3("min");
  const Field max = m.get("max", "add `max: [x, y, z]`");
  d.hi = max.vec3();
  for (int i = 0; i < 3; ++i) {
    if (!(d.hi[i] > d.lo[i]))
      max.items()[i].fail("value " + max.items()[i].node().Scalar() +
                          " is not greater than domain.min[" + std::to_string(i) + "] = " +
                          format_number(d.lo[i]) + "; each max coordinate must exceed min");
    if (!std::isfinite(d.hi[i] - d.lo[i]))
      max.items()[i].fail("the domain's extent max - min overflows the range of numbers along " +
                          std::string(1, "xyz"[i]) + "; give a domain of a physical size");
  }
  if (const auto p = m.find("periodic")) d.periodic = p->bool3();
  return d;
}

const std::vector<std::string> kTimeKeys = {"step",        "rayleigh_fraction",
                                            "end",         "expected_max_speed",
                                            "max_overlap", "min_steps_per_contact",
                                            "max_step_travel"};

TimeSettings parse_time(const Field& f) {
  const Map m = f.map(kTimeKeys);
  m.exactly_one_of("step", "rayleigh_fraction",
                   "`step` is the time step in s, `rayleigh_fraction` sets it as a fraction of "
                   "the Rayleigh time");
  TimeSettings t;
  t.step = m.maybe_number("step", kPositive);
  t.rayleigh_fraction = m.maybe_number("rayleigh_fraction", kUnitOpenBelow);
  t.end = m.number("end", kPositive);
  t.end_source = f.source().label + ":" + std::to_string(m.find("end")->key_mark().line + 1);
  t.step_source =
      f.source().label + ":" +
      std::to_string(m.find(t.step ? "step" : "rayleigh_fraction")->key_mark().line + 1);
  t.expected_max_speed = m.number_or("expected_max_speed", 1.0, kPositive);
  t.max_overlap = m.number_or("max_overlap", 0.25, Range{0, 1, false, true});
  t.min_steps_per_contact = m.number_or("min_steps_per_contact", 5, kNonNegative);
  t.max_step_travel = m.number_or("max_step_travel", 1.0, kNonNegative);
  return t;
}

// Materials in one scene. Each pair has its own entry in Scene::pairs, so the table
// holds kMaxMaterials^2 / 2 = 500 500 entries at most.
constexpr std::size_t kMaxMaterials = 1000;

// A scene error kept for later: what contacts need is required only when contacts can happen
// (Scene::contacts_possible), which is known once the walls and insertions are read.
using Deferred = std::vector<std::exception_ptr>;
template <class F>
void defer(Deferred& later, F&& check) {
  try {
    check();
  } catch (const SceneError&) {
    later.push_back(std::current_exception());
  }
}

// The thermal properties of a material: required with heat on, refused without it.
void read_material_heat(const Map& m, const std::optional<HeatSettings>& heat, Material& mat) {
  if (!heat) {
    for (const char* key : {"heat_capacity", "conductivity", "heat_source", "real_youngs_modulus"})
      if (const auto f = m.find(key))
        f->fail_at_key(std::string("`") + key +
                       "` is a heat-transfer property, but heat transfer is off; add a top-level "
                       "`heat: {}` block to switch it on, or remove this key");
    return;
  }
  const std::string hint = " (heat is on, " + heat->source + ")";
  mat.heat_capacity =
      m.get("heat_capacity", "add `heat_capacity: <J/(kg K)>`" + hint).number(kPositive);
  mat.conductivity = m.get("conductivity", "add `conductivity: <W/(m K)>`" + hint).number(kPositive);
  mat.heat_source = m.number_or("heat_source", 0.0, kAny);
  // The soft-particle contact-radius corrections need the real material's modulus.
  if (heat->contact_radius == ContactRadiusModel::geometric) {
    if (const auto f = m.find("real_youngs_modulus"))
      f->fail_at_key("`real_youngs_modulus` is used only by the soft-particle contact-radius "
                     "corrections, and heat.contact_radius is geometric (" + heat->source +
                     "); set `contact_radius: morris_static` or `morris_collision`, or remove "
                     "this key");
    return;
  }
  mat.real_youngs_modulus =
      m.get("real_youngs_modulus",
            "add `real_youngs_modulus: <Pa>`, the real material's Young's modulus (heat."
            "contact_radius at " + heat->contact_radius_source + " corrects the contact radius "
            "for it)")
          .number(kPositive);
}

constexpr std::size_t kMaxNameLength = 100;

// A name that becomes a column of log.csv (walls) or a cell of a particle CSV (materials):
// no comma, quote, line break or other control character, which would break the file's
// columns for every reader (a wall "floor, main" shifted the log's columns).
void check_csv_safe_name(const Field& name, const std::string& what) {
  const std::string& text = name.text();
  // A name is a column header and a word in every message: 100 characters at most.
  if (text.size() > kMaxNameLength)
    name.fail(what + " name '" + text.substr(0, 60) + "...' is " + std::to_string(text.size()) +
              " characters long; a name is at most " + std::to_string(kMaxNameLength) +
              " characters (it heads log.csv columns and appears in messages)");
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == ',' || c == '"' || c < 0x20 || c == 0x7f) {
      const std::string shown = c == ','    ? "a comma"
                                : c == '"'  ? "a double quote"
                                : c == '\n' ? "a line break"
                                : c == '\t' ? "a tab"
                                            : "a control character";
      name.fail(what + " name '" + text + "' holds " + shown + " (at character " +
                std::to_string(i + 1) +
                "), which would break the columns of log.csv and of particle CSV files; "
                "use letters, digits, '_', '-' or '.'");
    }
  }
}

std::vector<Material> parse_materials(const Field& f, Deferred& later,
                                      const std::optional<HeatSettings>& heat) {
  std::vector<Material> out;
  std::map<std::string, int> first_line;
  const std::vector<Field> items = f.non_empty_items("define at least one material");
  // The pair table grows as n^2 / 2 (parse_pairs): bound it before building it.
  if (items.size() > kMaxMaterials)
    f.fail_at_key(std::to_string(items.size()) + " materials are listed; at most " +
                  std::to_string(kMaxMaterials) +
                  " are allowed (every pair of materials gets its own contact properties)");
  for (const Field& item : items) {
    const Map m = item.map({"name", "youngs_modulus", "poisson_ratio", "density", "heat_capacity",
                            "conductivity", "heat_source", "real_youngs_modulus"});
    const Field name = m.get("name", "add `name: <material name>`");
    Material mat;
    mat.name = name.text();
    check_csv_safe_name(name, "material");
    if (const auto it = first_line.find(mat.name); it != first_line.end())
      name.fail("duplicate material name '" + mat.name + "' (first defined at line " +
                std::to_string(it->second) + "); give each material a unique name");
    first_line.emplace(mat.name, name.line());
    // "glass[k=2]" names the parcel class of glass with coarse_grain 2 (add_parcel_classes):
    // a material of that name would be mistaken for it in every message and report.
    if (mat.name.find("[k=") != std::string::npos)
      name.fail("material name '" + mat.name +
                "' contains \"[k=\", which names parcel "
                "classes (a material with coarse_grain k, e.g. glass[k=2]); choose another name");
    if (m.find("youngs_modulus"))
      mat.youngs_modulus = m.number("youngs_modulus", kPositive);
    else
      defer(later, [&] { m.number("youngs_modulus", kPositive); });
    if (m.find("poisson_ratio"))
      mat.poisson_ratio = m.number("poisson_ratio", Range{-1, 0.5, false, false});
    else
      defer(later, [&] { m.number("poisson_ratio", Range{-1, 0.5, false, false}); });
    mat.density = m.number("density", kPositive);
    read_material_heat(m, heat, mat);
    out.push_back(mat);
  }
  return out;
}

// restitution (required), friction, rolling_friction, cohesion_energy_density.
void read_pair_properties(const Map& m, MaterialPair& p) {
  p.restitution = m.number("restitution", kUnitOpenBelow);
  p.friction = m.number_or("friction", 0.5, kNonNegative);
  p.rolling_friction = m.number_or("rolling_friction", 0.0, kNonNegative);
  p.cohesion_energy_density = m.number_or("cohesion_energy_density", 0.0, kNonNegative);
}

const std::vector<std::string> kPairPropertyKeys = {"restitution", "friction", "rolling_friction",
                                                    "cohesion_energy_density"};

std::size_t pair_count(std::size_t n) { return n * (n + 1) / 2; }

// The complete pair table, in the canonical order Scene::pair expects.
std::vector<MaterialPair> parse_pairs(const Map& top, const std::vector<Material>& materials,
                                      Deferred& later) {
  std::map<std::pair<int, int>, std::pair<MaterialPair, int>> listed;  // (a,b) -> (props, line)
  if (const auto list = top.find("interactions")) {
    std::vector<std::string> keys = kPairPropertyKeys;
    keys.insert(keys.begin(), "materials");
    for (const Field& item : list->items()) {
      const Map m = item.map(keys);
      const Field names = m.get("materials", "add `materials: [name1, name2]`");
      const std::vector<Field> two = names.items();
      if (two.size() != 2)
        names.fail("expected a list of 2 material names, got " + names.got() +
                   "; write it as [glass, steel]");
      MaterialPair p;
      p.a = material_ref(two[0], materials);
      p.b = material_ref(two[1], materials);
      if (p.a > p.b) std::swap(p.a, p.b);
      if (const auto it = listed.find({p.a, p.b}); it != listed.end())
        names.fail("the pair (" + materials[p.a].name + ", " + materials[p.b].name +
                   ") is already given at line " + std::to_string(it->second.second) +
                   "; keep one entry per pair");
      read_pair_properties(m, p);
      listed.emplace(std::make_pair(p.a, p.b), std::make_pair(p, names.line()));
    }
  }
  std::optional<MaterialPair> defaults;
  if (const auto d = top.find("interaction_defaults")) {
    defaults.emplace();
    read_pair_properties(d->map(kPairPropertyKeys), *defaults);
  }

  const int n = static_cast<int>(materials.size());
  std::vector<MaterialPair> table;
  table.reserve(pair_count(materials.size()));
  for (int a = 0; a < n; ++a) {
    for (int b = a; b < n; ++b) {
      MaterialPair p;
      if (const auto it = listed.find({a, b}); it != listed.end()) {
        p = it->second.first;
      } else if (defaults) {
        p = *defaults;
      } else {
        const std::string pair = materials[a].name + ", " + materials[b].name;
        const Field at = top.find("interactions").value_or(top.get("materials"));
        defer(later, [&] {
          at.fail_at_key("no interaction properties for material pair (" + pair +
                         "); add an entry with `materials: [" + pair +
                         "]` to interactions, or give interaction_defaults for unlisted pairs");
        });
        p.restitution = 1;  // never used: no contact can happen if this stands
      }
      p.a = a;
      p.b = b;
      table.push_back(p);
    }
  }
  return table;
}

void parse_hooke(const Field& f, ContactSettings& c) {
  const Map m = f.map({"characteristic_velocity", "stiffness"});
  m.exactly_one_of("characteristic_velocity", "stiffness",
                   "`characteristic_velocity` derives the stiffness from Hertz theory at that "
                   "impact speed, `stiffness` gives it directly");
  c.hooke_characteristic_velocity = m.maybe_number("characteristic_velocity", kPositive);
  if (const auto s = m.find("stiffness")) {
    const Map k = s->map({"normal", "tangential"});
    c.hooke_kn = k.number("normal", kPositive);
    c.hooke_kt = k.maybe_number("tangential", kPositive);
  }
}

ContactSettings parse_contact(const Field& f) {
  const Map m =
      f.map({"normal", "tangential", "rolling", "cohesion", "hooke", "epsd", "dashpot_velocity"});
  ContactSettings c;
  c.normal = m.get("normal", "add `normal: hertz` or `normal: hooke`")
                 .choice<NormalModel>("normal contact model", {{"hertz", NormalModel::hertz},
                                                               {"hooke", NormalModel::hooke}});
  if (const auto t = m.find("tangential"))
    c.tangential = t->choice<TangentialModel>(
        "tangential contact model",
        {{"none", TangentialModel::none}, {"history", TangentialModel::history}});
  if (const auto r = m.find("rolling"))
    c.rolling = r->choice<RollingModel>(
        "rolling resistance model",
        {{"none", RollingModel::none}, {"cdt", RollingModel::cdt}, {"epsd", RollingModel::epsd}});
  if (const auto co = m.find("cohesion"))
    c.cohesion = co->choice<CohesionModel>(
        "cohesion model", {{"none", CohesionModel::none}, {"sjkr", CohesionModel::sjkr}});
  if (const auto d = m.find("dashpot_velocity"))
    c.dashpot_velocity = d->choice<DashpotVelocity>(
        "dashpot velocity",
        {{"half_step", DashpotVelocity::half_step}, {"predicted", DashpotVelocity::predicted}});

  const std::optional<Field> hooke = m.find("hooke");
  if (c.normal == NormalModel::hooke)
    parse_hooke(m.get("hooke",
                      "normal: hooke needs `hooke: {characteristic_velocity: <m/s>}` or "
                      "`hooke: {stiffness: {normal: <N/m>}}`"),
                c);
  else if (hooke)
    hooke->fail_at_key(
        "settings for the hooke model are given but normal is hertz; "
        "set `normal: hooke` or remove this block");

  if (const auto epsd = m.find("epsd")) {
    if (c.rolling != RollingModel::epsd)
      epsd->fail_at_key(
          "settings for the epsd rolling model are given but rolling is not epsd; "
          "set `rolling: epsd` or remove this block");
    c.epsd_damping_ratio =
        epsd->map({"damping_ratio"}).number_or("damping_ratio", 0.3, kUnitClosed);
  }
  return c;
}

// A file named in the scene, resolved against the scene file's folder; it must exist. With
// `missing`, a file that does not exist is no error here: `*missing` gets the error.
std::string existing_file(const Field& file, const std::string& what,
                          std::string* missing = nullptr) {
  const fs::path given = file.text();
  if (file.text().starts_with("~"))
    file.fail(
        "'~' is not expanded in a scene file (the shell expands it, not grain); write the "
        "full path, or a path relative to the scene file's folder");
  const fs::path resolved = given.is_absolute() ? given : file.source().folder / given;
  std::error_code ec;
  if (fs::is_directory(resolved, ec))
    file.fail(what + " '" + given.string() + "' is a directory ('" + resolved.string() +
              "'), not a file; name the file inside it");
  if (fs::exists(resolved, ec) && !fs::is_regular_file(resolved, ec))
    file.fail(what + " '" + given.string() + "' ('" + resolved.string() +
              "') is not a regular file (a device, a pipe or a socket); name a file");
  if (!fs::is_regular_file(resolved, ec)) {
    const std::string error = what + " '" + given.string() + "' not found (looked for '" +
                              resolved.string() +
                              "'); file names are relative to the scene file's folder";
    if (!missing) file.fail(error);
    try {
      file.fail(error);
    } catch (const SceneError& e) {
      *missing = e.what();
    }
  }
  return resolved.string();
}

ParallelSettings parse_parallel(const Field& f) {
  const Map m = f.map({"grid", "balance", "reproducible"});
  ParallelSettings par;
  for (const char* key : {"grid", "balance", "reproducible"})
    if (const auto v = m.find(key))
      par.given.emplace_back(key, f.source().label + ":" + std::to_string(v->key_mark().line + 1));
  if (const auto g = m.find("grid")) {
    const std::vector<Field> items = g->items();
    if (items.size() != 3)
      g->fail("expected a list of 3 whole numbers (ranks along x, y, z), got " + g->got() +
              "; write it as [nx, ny, nz] with nx * ny * nz = the number of MPI ranks");
    for (int a = 0; a < 3; ++a)
      par.grid[a] = static_cast<int>(items[a].integer(Range{1, 1e6, true, true}));
  }
  if (const auto b = m.find("balance")) par.balance = b->boolean();
  if (const auto r = m.find("reproducible")) par.reproducible = r->boolean();
  return par;
}

NeighbourSettings parse_neighbour(const Field& f) {
  NeighbourSettings n;
  n.skin = f.map({"skin"}).maybe_number("skin", kPositive);
  return n;
}

// `motion: {velocity, angular_velocity, axis, axis_point}` of any wall kind.
WallMotion parse_wall_motion(const Field& f) {
  const Map m = f.map({"velocity", "angular_velocity", "axis", "axis_point"});
  WallMotion w;
  w.velocity = m.vec3_or("velocity", Vec3::Zero());
  w.angular_velocity = m.number_or("angular_velocity", 0.0, kAny);
  if (w.angular_velocity != 0) {
    w.axis = m.direction("axis");
    w.axis_point = m.vec3_or("axis_point", Vec3::Zero());
  }
  return w;
}

// A wall's `temperature: <K>` or `heat_flux: <W/m^2>` (neither: adiabatic); only with heat on.
WallThermal parse_wall_thermal(const Map& m, const std::optional<HeatSettings>& heat) {
  WallThermal t;
  const auto temperature = m.find("temperature"), flux = m.find("heat_flux");
  if (!heat) {
    if (const auto f = temperature ? temperature : flux)
      f->fail_at_key("a wall's thermal condition is given, but heat transfer is off; add a "
                     "top-level `heat: {}` block to switch it on, or remove this key");
    return t;
  }
  if (temperature && flux)
    flux->fail_at_key("a wall has either a fixed `temperature` or a fixed `heat_flux`, not both; "
                      "leave both out for an adiabatic wall");
  if (temperature && !heat->conduction)
    temperature->fail_at_key(
        "a wall's fixed `temperature` heats or cools the particles touching it by contact "
        "conduction, which `heat: {conduction: none}` switches off; remove this key (an "
        "adiabatic wall), give the wall a `heat_flux` instead, or set `heat.conduction: "
        "batchelor_obrien`");
  if (temperature) {
    t.kind = WallThermal::Kind::temperature;
    t.value = temperature->number(kPositive);
  } else if (flux) {
    t.kind = WallThermal::Kind::flux;
    t.value = flux->number(kAny);
  }
  return t;
}

// A wall must look the same from both sides of a periodic boundary: a particle that leaves
// through one side comes back through the other, and sees the walls there without wrapping.
// A plane whose normal has a component along a periodic axis cuts that axis's sides (the
// particle comes back behind it and is shot out: energy grew 250-fold in a scene that ran to
// "done"); so does a cylinder whose axis is tilted to it, or one across it whose surface
// reaches a periodic side. Meshes are not checked (a floor spanning the periodic width is
// right; docs/scene-reference.md, "Walls").
void check_periodic_wall(const Map& m, const Wall& w, const Domain& d) {
  constexpr const char* axis_name[3] = {"x", "y", "z"};
  constexpr double tolerance = 1e-9;  // of a unit vector's component
  const WallMotion& motion = w.motion;
  for (int a = 0; a < 3; ++a) {
    if (!d.periodic[a]) continue;
    const std::string periodic = std::string(axis_name[a]) + " is periodic (domain.periodic)";
    const std::string unit = "; make " + std::string(axis_name[a]) + " bounded, or ";
    if (w.kind == Wall::Kind::plane && std::abs(w.plane.normal[a]) > tolerance) {
      std::ostringstream o;
      o << "plane '" << w.name << "' has a normal with the component "
        << significant(w.plane.normal[a]) << " along " << axis_name[a] << ", and " << periodic
        << ": a particle leaving through one " << axis_name[a]
        << " side comes back through the other, on the plane's far side" << unit
        << "give the plane a normal perpendicular to " << axis_name[a];
      m.get("normal").fail_at_key(o.str());
    }
    if (w.kind == Wall::Kind::cylinder) {
      const CylinderWall& c = w.cylinder;
      const double along = std::abs(c.axis[a]);
      if (along > tolerance && along < 1 - tolerance) {
        std::ostringstream o;
        o << "cylinder '" << w.name << "' has an axis tilted to " << axis_name[a] << ", and "
          << periodic << ": its surface crosses the " << axis_name[a]
          << " sides, where a particle coming back through the other side finds it elsewhere"
          << unit << "give the cylinder an axis along or perpendicular to " << axis_name[a];
        m.get("axis").fail_at_key(o.str());
      }
      if (along <= tolerance &&
          (c.axis_point[a] - c.radius < d.lo[a] || c.axis_point[a] + c.radius > d.hi[a])) {
        std::ostringstream o;
        o << "cylinder '" << w.name << "' reaches from " << axis_name[a] << " = "
          << significant(c.axis_point[a] - c.radius) << " to "
          << significant(c.axis_point[a] + c.radius) << " m, across the domain's "
          << significant(d.lo[a]) << " to " << significant(d.hi[a]) << " m, and " << periodic
          << ": a particle coming back through the other side does not see it there" << unit
          << "keep the cylinder within the periodic range (its axis point and radius)";
        m.get("radius").fail_at_key(o.str());
      }
    }
    // A translation along a periodic axis carries a cylinder across (unless along its own
    // axis, along which it does not end) and a mesh out of the periodic range: neither is
    // repeated across the periodic sides.
    const bool along_own_axis =
        w.kind == Wall::Kind::cylinder && std::abs(w.cylinder.axis[a]) > 1 - tolerance;
    if (w.kind != Wall::Kind::plane && !along_own_axis && std::abs(motion.velocity[a]) > 0) {
      std::ostringstream o;
      o << (w.kind == Wall::Kind::mesh ? "mesh" : "cylinder") << " '" << w.name << "' moves along "
        << axis_name[a] << " (motion.velocity " << axis_name[a] << " = "
        << significant(motion.velocity[a]) << " m/s), and " << periodic
        << ": a wall is not repeated across the periodic sides, so it would cross them (and "
           "particles coming back through the other side would not find it)"
        << unit << "keep the wall still along " << axis_name[a]
        << (w.kind == Wall::Kind::mesh ? " (a conveyor belt: a still mesh with `surface_velocity`)"
                                       : "");
      m.get("motion").fail_at_key(o.str());
    }
    // A rotation turns a plane's normal (a cylinder's axis) towards a periodic axis unless
    // it is about that axis.
    if (w.kind != Wall::Kind::mesh && motion.angular_velocity != 0 &&
        std::abs(motion.axis[a]) < 1 - tolerance) {
      const Vec3 v = w.kind == Wall::Kind::plane ? w.plane.normal : w.cylinder.axis;
      const Vec3 turned = motion.axis.cross(v);
      if (std::abs(turned[a]) > tolerance) {
        std::ostringstream o;
        o << "wall '" << w.name << "' rotates (motion.angular_velocity) about an axis that "
          << "turns its " << (w.kind == Wall::Kind::plane ? "normal" : "axis") << " towards "
          << axis_name[a] << ", and " << periodic << ": it would then cut the periodic sides"
          << unit << "rotate it about an axis along " << axis_name[a];
        m.get("motion").fail_at_key(o.str());
      }
    }
  }
}

// `names` are the names of the walls already read, to keep them unique.
Wall parse_wall(const Field& item, const std::unordered_set<std::string>& names,
                const std::vector<Material>& materials, const std::optional<HeatSettings>& heat,
                const Domain& domain) {
  const Map m = item.map();
  Wall w;
  w.kind = m.get("type", "add `type: plane`, `type: cylinder` or `type: mesh`")
               .choice<Wall::Kind>("wall type", {{"plane", Wall::Kind::plane},
                                                 {"cylinder", Wall::Kind::cylinder},
                                                 {"mesh", Wall::Kind::mesh}});
  if (const auto motion = m.find("motion")) w.motion = parse_wall_motion(*motion);
  if (w.kind == Wall::Kind::mesh) {
    m.allow_only({"type", "name", "file", "scale", "rotate", "translate", "surface_velocity",
                  "weld_tolerance", "material", "motion", "temperature", "heat_flux"},
                 " (a mesh wall)");
    const Field file = m.get("file", "add `file: <mesh.stl>`");
    w.mesh.file = existing_file(file, "STL file");
    w.mesh.file_source = file.source().label + ":" + std::to_string(file.line());
    w.mesh.scale = m.number_or("scale", 1.0, kPositive);
    if (const auto rot = m.find("rotate")) {
      const Map r = rot->map({"axis", "angle"});
      w.mesh.rotate_axis = r.direction("axis");
      w.mesh.rotate_angle = r.number("angle", kAny) * std::acos(-1.0) / 180;  // degrees
    }
    w.mesh.translate = m.vec3_or("translate", Vec3::Zero());
    w.mesh.surface_velocity = m.vec3_or("surface_velocity", Vec3::Zero());
    w.mesh.weld_tolerance =
        m.number_or("weld_tolerance", w.mesh.weld_tolerance, Range{0, 0.01, true, true});
  } else if (w.kind == Wall::Kind::plane) {
    m.allow_only({"type", "name", "point", "normal", "material", "motion", "temperature",
                  "heat_flux"},
                 " (a plane wall)");
    w.plane.point = m.vec3("point");
    w.plane.normal = m.direction("normal");
  } else {
    m.allow_only(
        {"type", "name", "axis_point", "axis", "radius", "side", "angular_velocity", "material",
         "motion", "temperature", "heat_flux"},
        " (a cylinder wall)");
    CylinderWall& c = w.cylinder;
    c.axis_point = m.vec3("axis_point");
    c.axis = m.direction("axis");
    c.radius = m.number("radius", kPositive);
    if (const auto side = m.find("side"))
      c.inside = side->choice<bool>("cylinder side", {{"inside", true}, {"outside", false}});
    c.angular_velocity = m.number_or("angular_velocity", 0.0, kAny);
  }
  const std::optional<Field> name = m.find("name");
  w.name = name ? name->text() : "wall" + std::to_string(names.size());
  if (name) check_csv_safe_name(*name, "wall");
  check_periodic_wall(m, w, domain);
  if (names.count(w.name) > 0)
    (name ? *name : item).fail("duplicate wall name '" + w.name + "'; give each wall a unique name");
  w.material = material_ref(m, "material", materials);
  w.thermal = parse_wall_thermal(m, heat);
  return w;
}

std::vector<Wall> parse_walls(const Field& f, const std::vector<Material>& materials,
                              const std::optional<HeatSettings>& heat, const Domain& domain) {
  std::vector<Wall> walls;
  std::unordered_set<std::string> names;  // a set: many walls cost linear, not quadratic, time
  for (const Field& item : f.items()) {
    walls.push_back(parse_wall(item, names, materials, heat, domain));
    names.insert(walls.back().name);
  }
  return walls;
}

// The region must lie inside the domain, else particles would be created outside it.
void check_inside_domain(const Field& f, const Vec3& lo, const Vec3& hi, const Domain& d) {
  const char* axis_name[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    const double tol = 1e-12 * (d.hi[i] - d.lo[i]);  // round-off of a cylinder's extent
    if (lo[i] < d.lo[i] - tol || hi[i] > d.hi[i] + tol)
      f.fail_at_key("the region reaches outside the domain along " + std::string(axis_name[i]) +
                    " (region from " + format_number(lo[i]) + " to " + format_number(hi[i]) +
                    ", domain from " + format_number(d.lo[i]) + " to " + format_number(d.hi[i]) +
                    "); keep fill regions inside the domain");
  }
}

Region parse_region(const Field& f, const Domain& domain) {
  const Map m = f.map({"box", "cylinder"});
  m.exactly_one_of("box", "cylinder",
                   "`box: {min, max}` or `cylinder: {base, axis, radius, height}`");
  Region r;
  if (const auto box = m.find("box")) {
    const Map b = box->map({"min", "max"});
    r.kind = Region::Kind::box;
    r.lo = b.vec3("min");
    const Field max = b.get("max", "add `max: [x, y, z]`");
    r.hi = max.vec3();
    for (int i = 0; i < 3; ++i)
      if (!(r.hi[i] > r.lo[i]))
        max.items()[i].fail("value " + max.items()[i].node().Scalar() +
                            " is not greater than min[" + std::to_string(i) + "] = " +
                            format_number(r.lo[i]) + "; each max coordinate must exceed min");
    check_inside_domain(*box, r.lo, r.hi, domain);
    return r;
  }
  const Field cyl = *m.find("cylinder");
  const Map c = cyl.map({"base", "axis", "radius", "height"});
  r.kind = Region::Kind::cylinder;
  r.base = c.vec3("base");
  r.axis = c.direction("axis");
  r.radius = c.number("radius", kPositive);
  r.height = c.number("height", kPositive);
  // Bounding box: the two end discs; a disc of radius R normal to unit a spans
  // R*sqrt(1 - a_i^2) along axis i.
  const Vec3 top = r.base + r.height * r.axis;
  const Vec3 half =
      (Vec3::Ones() - r.axis.cwiseProduct(r.axis)).cwiseMax(0.0).cwiseSqrt() * r.radius;
  check_inside_domain(cyl, r.base.cwiseMin(top) - half, r.base.cwiseMax(top) + half, domain);
  return r;
}

void parse_normal_distribution(const Map& m, SizeDistribution& s) {
  s.mean = m.number("mean", kPositive);
  s.stddev = m.number("stddev", kPositive);
  // Default truncation at mean +- 3 sigma; a non-positive lower bound is clipped to
  // mean/10 so no vanishingly small particle wrecks the time step.
  s.min = m.number_or("min", std::max(s.mean - 3 * s.stddev, 0.1 * s.mean), kPositive);
  s.max = m.number_or("max", s.mean + 3 * s.stddev, kPositive);
  if (!std::isfinite(s.max))
    m.get("stddev").fail("mean + 3 stddev overflows the range of numbers; give a smaller stddev "
                         "or an explicit max");
  if (!(s.min <= s.mean))
    m.find("min").value_or(m.self()).fail("the lower bound " + format_number(s.min) +
                                          " is above the mean " + format_number(s.mean) +
                                          "; need min <= mean <= max");
  if (!(s.max >= s.mean))
    m.find("max").value_or(m.self()).fail("the upper bound " + format_number(s.max) +
                                          " is below the mean " + format_number(s.mean) +
                                          "; need min <= mean <= max");
}

void parse_discrete_distribution(const Map& m, SizeDistribution& s) {
  s.values = m.get("values", "add `values: [r1, r2, ...]`").numbers(kPositive);
  const std::optional<Field> w = m.find("weights");
  if (!w) {
    s.weights.assign(s.values.size(), 1.0 / static_cast<double>(s.values.size()));
    return;
  }
  s.weights = w->numbers(kPositive);
  if (s.weights.size() != s.values.size())
    w->fail(std::to_string(s.weights.size()) + " weights are given for " +
            std::to_string(s.values.size()) + " values; give one weight per radius");
  // Scaled by the largest first, so that weights near the double limit cannot sum to inf.
  const double largest = *std::max_element(s.weights.begin(), s.weights.end());
  double sum = 0;
  for (double& x : s.weights) sum += (x /= largest);
  for (double& x : s.weights) x /= sum;
}

SizeDistribution parse_size_distribution(const Field& f) {
  SizeDistribution s;
  using K = SizeDistribution::Kind;
  // `radius: 5e-4`, a plain number, is the constant distribution.
  if (f.node().IsScalar()) {
    // A word (not a number that is out of range) gets the forms a radius may take.
    const std::string& text = f.node().Scalar();
    if (text.empty() || std::isalpha(static_cast<unsigned char>(text[0])))
      f.fail(
          "expected a radius in m (such as 5e-4) or a size distribution "
          "({distribution: constant, uniform, normal or discrete, ...}), got " +
          f.got());
    s.kind = K::constant;
    s.value = f.number(kPositive);
    return s;
  }
  if (!f.node().IsMap())
    f.fail(
        "expected a radius in m (such as 5e-4) or a size distribution "
        "({distribution: constant, uniform, normal or discrete, ...}), got " +
        f.got());
  const Map m = f.map();
  // Without `distribution`, the form the other keys suggest.
  const char* suggested = m.find("mean") || m.find("stddev")      ? "normal"
                          : m.find("min") || m.find("max")        ? "uniform"
                          : m.find("values") || m.find("weights") ? "discrete"
                                                                  : "constant";
  s.kind = m.get("distribution", "add `distribution: " + std::string(suggested) +
                                     "` (the forms: constant, uniform, normal, discrete)")
               .choice<K>("size distribution", {{"constant", K::constant},
                                                {"uniform", K::uniform},
                                                {"normal", K::normal},
                                                {"discrete", K::discrete}});
  switch (s.kind) {
    case K::constant:
      m.allow_only({"distribution", "value"}, " (a constant size)");
      s.value = m.number("value", kPositive);
      break;
    case K::uniform: {
      m.allow_only({"distribution", "min", "max"}, " (a uniform distribution)");
      s.min = m.number("min", kPositive);
      s.max = m.number("max", kPositive);
      if (s.max < s.min)
        m.get("max").fail("value " + m.get("max").node().Scalar() +
                          " is less than min = " + format_number(s.min) + "; need 0 < min <= max");
      break;
    }
    case K::normal:
      m.allow_only({"distribution", "mean", "stddev", "min", "max"}, " (a normal distribution)");
      parse_normal_distribution(m, s);
      break;
    case K::discrete:
      m.allow_only({"distribution", "values", "weights"}, " (a discrete distribution)");
      parse_discrete_distribution(m, s);
      break;
  }
  return s;
}

double smallest_radius(const SizeDistribution& s) {
  using K = SizeDistribution::Kind;
  switch (s.kind) {
    case K::constant: return s.value;
    case K::uniform:
    case K::normal: return s.min;
    case K::discrete: return *std::min_element(s.values.begin(), s.values.end());
  }
  return s.value;
}

double largest_radius(const SizeDistribution& s) {
  using K = SizeDistribution::Kind;
  switch (s.kind) {
    case K::constant:
      return s.value;
    case K::uniform:
    case K::normal:
      return s.max;
    case K::discrete:
      return *std::max_element(s.values.begin(), s.values.end());
  }
  return s.value;
}

double region_volume(const Region& r) {
  if (r.kind == Region::Kind::box) return (r.hi - r.lo).prod();
  return std::acos(-1.0) * r.radius * r.radius * r.height;
}

// `coarse_grain: k` of a fill or stream insertion (docs/models/coarse-graining.md): k >= 1;
// the size distribution, given for the real particles, becomes the parcels' (times k).
void parse_coarse_grain(const Map& m, Insertion& ins) {
  const auto f = m.find("coarse_grain");
  if (!f) return;
  ins.coarse_grain = f->number(Range{1, 1e3, true, true});
  if (ins.coarse_grain == 1) return;
  SizeDistribution& r = ins.radius;
  const double k = ins.coarse_grain;
  r.value *= k;
  r.min *= k;
  r.max *= k;
  r.mean *= k;
  r.stddev *= k;
  for (double& v : r.values) v *= k;
}

// A csv or snapshot insertion's particles keep their own sizes: refuse coarse_grain there
// before the generic unknown-key message.
void refuse_coarse_grain(const Map& m, const char* kind) {
  if (const auto f = m.find("coarse_grain"))
    f->fail_at_key(std::string("coarse_grain is available on fill and stream insertions; a ") +
                   kind + " insertion takes its particles as they are; remove the key");
}

void parse_fill(const Map& m, const Scene& scene, Insertion& ins) {
  m.allow_only(
      {"type", "region", "count", "volume_fraction", "material", "radius", "velocity", "seed",
       "temperature", "coarse_grain"},
      " (a fill insertion)");
  ins.region =
      parse_region(m.get("region", "add `region: {box: {min: [..], max: [..]}}`"), scene.domain);
  m.exactly_one_of("count", "volume_fraction",
                   "`count` is a number of particles, `volume_fraction` the solid fraction of the "
                   "region");
  if (const auto c = m.find("count")) ins.count = static_cast<long>(c->integer(kPositive));
  ins.volume_fraction = m.maybe_number("volume_fraction", Range{0, 0.6, false, true});
  ins.material = material_ref(m, "material", scene.materials);
  ins.radius = parse_size_distribution(m.get("radius",
                                             "add `radius: <m>` (or a distribution: `radius: "
                                             "{distribution: uniform, min: <m>, max: <m>}`)"));
  parse_coarse_grain(m, ins);
  {
    // Every particle lies whole inside the region (sample_centre, dem/insert/insertion.cpp):
    // a region thinner than the largest sphere the distribution draws places none of those,
    // and the fill, which places the largest first, none at all, whatever the count.
    const Region& g = ins.region;
    const double across =
        g.kind == Region::Kind::box ? (g.hi - g.lo).minCoeff() : std::min(2 * g.radius, g.height);
    const double d = 2 * largest_radius(ins.radius), k = ins.coarse_grain;
    const bool one_size = largest_radius(ins.radius) == smallest_radius(ins.radius);
    if (d - across > kRegionFitTolerance * d)
      m.get("region").fail(
          "the region is " + format_number(across) + " m across at its narrowest, less than " +
          (one_size ? "the particles the fill inserts, "
                    : "the largest particle the fill's radius distribution draws, ") +
          format_number(d) + " m in diameter" +
          (k != 1 ? " (a parcel: the real diameter " + format_number(d / k) +
                        " m times coarse_grain " + format_number(k) + ")"
                  : std::string()) +
          "; every particle lies whole inside the region: make it at least " + format_number(d) +
          " m across" + (k != 1 ? ", or lower coarse_grain" : ""));
  }
  if (ins.count) {
    // Even the smallest spheres the distribution can draw must fit by volume alone;
    // this also bounds what insertion will try to allocate.
    const double r = smallest_radius(ins.radius);
    const double solid = static_cast<double>(*ins.count) * 4.0 / 3.0 * std::acos(-1.0) * r * r * r;
    if (solid > region_volume(ins.region))
      m.get("count").fail(
          std::to_string(*ins.count) + " spheres of radius at least " + format_number(r) +
          " m have a volume of " + format_number(solid) + " m^3, more than the region's " +
          format_number(region_volume(ins.region)) +
          " m^3; lower the count or enlarge the region (random filling "
          "reaches a solid fraction near 0.35)" +
          (ins.coarse_grain != 1
               ? "; the spheres are parcels, coarse_grain " + format_number(ins.coarse_grain) +
                     " times the real radius: a count of real particles is " +
                     "count times coarse_grain^3"
               : std::string()));
  }
  ins.velocity = m.vec3_or("velocity", Vec3::Zero());
  if (const auto s = m.find("seed"))
    ins.seed = static_cast<unsigned>(s->integer(Range{0, double(UINT_MAX), true, true}));
}

void parse_csv(const Map& m, const Scene& scene, Insertion& ins) {
  refuse_coarse_grain(m, "csv");
  m.allow_only({"type", "file", "material", "temperature"}, " (a csv insertion)");
  ins.csv_file = existing_file(m.get("file", "add `file: <particles.csv>`"), "particle file",
                               &ins.csv_missing);
  ins.material = material_ref(m, "material", scene.materials);
}

InsertionFace parse_face(const Field& f) {
  const Map m = f.map({"rectangle", "disc"});
  m.exactly_one_of("rectangle", "disc",
                   "`rectangle: {centre, normal, u, size: [a, b]}` or `disc: {centre, normal, "
                   "radius}`");
  InsertionFace face;
  if (const auto r = m.find("rectangle")) {
    const Map q = r->map({"centre", "normal", "u", "size"});
    face.kind = InsertionFace::Kind::rectangle;
    face.centre = q.vec3("centre");
    face.normal = q.direction("normal");
    const Field u = q.get("u", "add `u: [x, y, z]`, the direction of the first side");
    const Vec3 dir = u.direction();
    const Vec3 in_plane = dir - dir.dot(face.normal) * face.normal;
    if (in_plane.norm() < 1e-6)
      u.fail("is parallel to the normal; give a direction along one side of the rectangle");
    face.u = in_plane.normalized();
    const Field size = q.get("size", "add `size: [a, b]` (side lengths along u and normal x u)");
    const std::vector<double> ab = size.numbers(kPositive);
    if (ab.size() != 2) size.fail("expected 2 side lengths [a, b], got " + size.got());
    face.length_u = ab[0];
    face.length_v = ab[1];
  } else {
    const Map q = m.find("disc")->map({"centre", "normal", "radius"});
    face.kind = InsertionFace::Kind::disc;
    face.centre = q.vec3("centre");
    face.normal = q.direction("normal");
    face.radius = q.number("radius", kPositive);
  }
  return face;
}

void parse_stream(const Map& m, const Scene& scene, Insertion& ins) {
  m.allow_only({"type", "face", "mass_rate", "count_rate", "start", "stop", "material", "radius",
                "velocity", "seed", "temperature", "coarse_grain"},
               " (a stream insertion)");
  const Field face = m.get("face", "add `face: {disc: {centre, normal, radius}}`");
  ins.face = parse_face(face);
  for (int a = 0; a < 3; ++a)
    if (ins.face.centre[a] < scene.domain.lo[a] || ins.face.centre[a] > scene.domain.hi[a])
      face.fail("the face centre lies outside the domain; new particles would be removed at once");
  m.exactly_one_of("mass_rate", "count_rate",
                   "`mass_rate` in kg/s or `count_rate` in particles per second");
  ins.mass_rate = m.maybe_number("mass_rate", kPositive);
  ins.count_rate = m.maybe_number("count_rate", kPositive);
  ins.start = m.number_or("start", 0.0, kNonNegative);
  ins.stop = m.maybe_number("stop", kPositive);
  if (ins.stop && *ins.stop <= ins.start)
    m.get("stop").fail("stop " + exact_number(*ins.stop) + " s must be later than start (" +
                       exact_number(ins.start) + " s)");
  ins.material = material_ref(m, "material", scene.materials);
  ins.radius = parse_size_distribution(m.get("radius",
                                             "add `radius: <m>` (or a distribution: `radius: "
                                             "{distribution: uniform, min: <m>, max: <m>}`)"));
  parse_coarse_grain(m, ins);
  // Each particle enters whole inside the face's outline (StreamInsertion::sample); a face
  // narrower than the largest one would put it at the centre, sticking out of the outline.
  const double r_max = largest_radius(ins.radius);
  const bool rectangle = ins.face.kind == InsertionFace::Kind::rectangle;
  const double across =
      rectangle ? std::min(ins.face.length_u, ins.face.length_v) : 2 * ins.face.radius;
  if (2 * r_max - across > kRegionFitTolerance * 2 * r_max) {
    const double k = ins.coarse_grain;
    face.fail(std::string(rectangle ? "the rectangle's shorter side is " : "the disc is ") +
              format_number(across) + " m" + (rectangle ? "" : " across") +
              ", narrower than the largest particle the stream inserts, " +
              format_number(2 * r_max) + " m in diameter" +
              (k != 1 ? " (a parcel: the radius up to " + format_number(r_max / k) +
                            " m times coarse_grain " + format_number(k) + ")"
                      : std::string()) +
              "; every particle enters whole inside the face: make it at least " +
              format_number(2 * r_max) + " m across" + (k != 1 ? ", or lower coarse_grain" : ""));
  }
  // Along a bounded axis every particle the face can place must lie whole inside the domain:
  // a face reaching beyond a bounded side delivers particles that are removed at once (they
  // were counted as delivered). Across a periodic side the candidates wrap.
  for (const double r : {largest_radius(ins.radius), smallest_radius(ins.radius)}) {
    for (int a = 0; a < 3; ++a) {
      if (scene.domain.periodic[a]) continue;
      double reach = r;  // how far a particle of radius r can reach from the face centre
      if (rectangle) {
        const Vec3 v = ins.face.normal.cross(ins.face.u);
        reach += std::abs(ins.face.u[a]) * std::max(0.0, ins.face.length_u / 2 - r) +
                 std::abs(v[a]) * std::max(0.0, ins.face.length_v / 2 - r);
      } else {
        const double n = ins.face.normal[a];
        reach += std::max(0.0, ins.face.radius - r) * std::sqrt(std::max(0.0, 1 - n * n));
      }
      const double c = ins.face.centre[a];
      const double tol = 1e-9 * (scene.domain.hi[a] - scene.domain.lo[a]);  // round-off
      if (c - reach < scene.domain.lo[a] - tol || c + reach > scene.domain.hi[a] + tol) {
        const char* axis = "xyz";
        const double from = scene.domain.lo[a] + reach, to = scene.domain.hi[a] - reach;
        face.fail(std::string("the face reaches beyond the domain along ") + axis[a] +
                  ": particles entering through it span " + axis[a] + " from " +
                  format_number(c - reach) + " to " + format_number(c + reach) +
                  " m, and the domain is bounded there, from " + format_number(scene.domain.lo[a]) +
                  " to " + format_number(scene.domain.hi[a]) +
                  " m; particles outside it would be removed at once. " +
                  (from <= to ? "Move the face's centre to " + std::string(1, axis[a]) +
                                    " between " + format_number(from) + " and " +
                                    format_number(to) + " m, or shrink the face"
                              : std::string("Shrink the face")) +
                  ", or make " + axis[a] + " periodic (domain.periodic)");
      }
    }
  }
  if (ins.start >= scene.time.end)
    m.get("start").fail("start " + exact_number(ins.start) + " s is not before time.end (" +
                        exact_number(scene.time.end) +
                        " s): the stream would insert nothing; lower start or raise time.end");
  ins.velocity = m.vec3_or("velocity", Vec3::Zero());
  if (const auto s = m.find("seed"))
    ins.seed = static_cast<unsigned>(s->integer(Range{0, double(UINT_MAX), true, true}));
}

// A snapshot of coarse-grained parcels carries the parcel classes of the scene that wrote it
// (SnapshotClasses); the parser gives this scene the same classes (add_parcel_classes). A file
// that cannot be read is reported when the insertion reads it (exit code 2 or 1).
void parse_snapshot_classes(const Field& file, const Scene& scene, Insertion& ins) {
  SnapshotClasses c;
  try {
    c = read_snapshot_classes(ins.snapshot_file);
  } catch (const SnapshotReadError&) {
    return;
  }
  if (c.parcels_without_classes)
    file.fail("the snapshot '" + ins.snapshot_file +
              "' holds coarse-grained parcels (its dataset /coarse_grain has k != 1) but not "
              "their classes (the root attributes material_coarse_grain and material_real, "
              "which an older grainflow did not write): its material indices cannot be mapped to "
              "parcel classes of this scene. "
              "Continue that run from one of its checkpoints (grain run --restart), or rerun "
              "its scene with this grainflow and insert from the new snapshot");
  const std::size_t listed = scene.materials.size();
  ins.snapshot_material_names = c.names;
  if (!c.names.empty() && c.k.empty()) {  // real particles: one class per named material
    c.k.assign(c.names.size(), 1.0);
    for (std::size_t m = 0; m < c.names.size(); ++m) c.real.push_back(static_cast<int>(m));
  }
  if (!c.names.empty() && c.names.size() != c.k.size())
    file.fail("the snapshot '" + ins.snapshot_file + "' names " + std::to_string(c.names.size()) +
              " materials (root attribute material_names) "
              "but has classes for " +
              std::to_string(c.k.size()) +
              " (material_coarse_grain); the file was changed or damaged after it was written");
  // This scene's index of the writer's listed material m, by name when the file names it.
  const auto here = [&](int m) {
    if (c.names.empty()) return m;
    for (std::size_t i = 0; i < listed; ++i)
      if (scene.materials[i].name == c.names[static_cast<std::size_t>(m)])
        return static_cast<int>(i);
    return -1;
  };
  for (std::size_t m = 0; m < c.k.size(); ++m) {
    const std::size_t known = c.names.empty() ? listed : c.names.size();
    const bool listed_here = c.real[m] >= 0 && static_cast<std::size_t>(c.real[m]) < known;
    // With names, a class's listed material is one of the writer's own (k = 1) materials.
    const bool real_is_listed =
        c.names.empty() || !listed_here || c.k[static_cast<std::size_t>(c.real[m])] == 1;
    if (!(c.k[m] >= 1 && c.k[m] <= 1e3) || c.real[m] < 0 || (c.k[m] == 1 && c.real[m] != int(m)) ||
        !real_is_listed)
      file.fail("the snapshot '" + ins.snapshot_file + "' has a broken parcel class: material " +
                std::to_string(m) + " with k = " + format_number(c.k[m]) + " and listed material " +
                std::to_string(c.real[m]) +
                " (root attributes material_coarse_grain, material_real; allowed: k in [1, "
                "1000], a listed material's own index for k = 1); the file was changed or "
                "damaged after it was written");
    // A parcel class is named after its listed material and k (add_parcel_classes: glass[k=2]);
    // a name that says otherwise was edited, and which of the two is meant cannot be told.
    if (!c.names.empty() && listed_here) {
      const std::string& name = c.names[m];
      const std::string expected = c.k[m] == 1 ? name
                                               : c.names[static_cast<std::size_t>(c.real[m])] +
                                                     "[k=" + format_number(c.k[m]) + "]";
      if (name != expected || (c.k[m] == 1 && name.find("[k=") != std::string::npos))
        file.fail("the snapshot '" + ins.snapshot_file + "' names its material " +
                  std::to_string(m) + " '" + name + "' (root attribute material_names), but " +
                  (c.k[m] == 1
                       ? std::string("its class is a listed material (k = 1)")
                       : "its class is parcels of k = " + format_number(c.k[m]) + " of material '" +
                             c.names[static_cast<std::size_t>(c.real[m])] +
                             "' (material_coarse_grain, material_real), named '" + expected + "'") +
                  "; the file was changed or damaged after it was written");
    }
    if (!listed_here)
      file.fail("the snapshot '" + ins.snapshot_file + "' holds material " + std::to_string(m) +
                (c.k[m] == 1 ? std::string()
                             : " (parcels of k = " + format_number(c.k[m]) + " of material " +
                                   std::to_string(c.real[m]) + ")") +
                ", but this scene lists " + std::to_string(listed) +
                " material(s) (allowed: 0 to " + std::to_string(listed - 1) +
                "); list the materials in the order of the scene that wrote it");
    if (c.k[m] != 1 && here(c.real[m]) < 0) {
      std::string names;
      for (std::size_t i = 0; i < listed; ++i)
        names += (names.empty() ? "" : ", ") + scene.materials[i].name;
      file.fail("the snapshot '" + ins.snapshot_file +
                "' holds parcels of k = " + format_number(c.k[m]) + " of material '" +
                c.names[static_cast<std::size_t>(c.real[m])] +
                "', and this scene lists no material of that name (it lists " + names +
                "); add it to `materials`");
    }
    ins.coarse_grain = std::max(ins.coarse_grain, c.k[m]);
  }
  for (int& real : c.real) real = here(real);
  ins.snapshot_class_k = std::move(c.k);
  ins.snapshot_class_real = std::move(c.real);
}

void parse_snapshot(const Map& m, const Scene& scene, Insertion& ins) {
  refuse_coarse_grain(m, "snapshot");
  m.allow_only({"type", "file", "keep_velocity", "temperature"}, " (a snapshot insertion)");
  const Field file = m.get("file", "add `file: <particles_000020.h5>`");
  ins.snapshot_file = existing_file(file, "snapshot file");
  if (const auto k = m.find("keep_velocity")) ins.keep_velocity = k->boolean();
  parse_snapshot_classes(file, scene, ins);
}

// The initial temperature of an insertion's particles: required with heat on for fill and
// stream (a csv file may give a `T` column, a snapshot a temperature dataset instead: checked
// when they are read), refused with heat off.
void parse_insertion_temperature(const Map& m, const Scene& scene, Insertion& ins) {
  const auto t = m.find("temperature");
  if (!scene.heat) {
    if (t)
      t->fail_at_key("an initial temperature is given, but heat transfer is off; add a top-level "
                     "`heat: {}` block to switch it on, or remove this key");
    return;
  }
  if (t)
    ins.temperature = t->number(kPositive);
  else if (ins.kind == Insertion::Kind::fill || ins.kind == Insertion::Kind::stream)
    m.get("temperature", "add `temperature: <K>`, the particles' initial temperature (heat is on, " +
                             scene.heat->source + ")");
}

std::vector<Insertion> parse_insertions(const Field& f, const Scene& scene) {
  std::vector<Insertion> out;
  for (const Field& item : f.items()) {
    const Map m = item.map();
    Insertion ins;
    ins.source = item.source().label + ":" + std::to_string(item.line());
    // Without a `seed`, insert[i] draws from seed 1 + i: two fills of equal regions (or a
    // stream after a fill) with one default seed drew the same numbers, the second bed an
    // exact copy of the first shifted, the stream's radii the fill's.
    ins.seed = static_cast<unsigned>(1 + out.size());
    ins.kind = m.get("type", "add `type: fill`, `csv`, `stream` or `snapshot`")
                   .choice<Insertion::Kind>("insertion type",
                                            {{"fill", Insertion::Kind::fill},
                                             {"csv", Insertion::Kind::csv},
                                             {"stream", Insertion::Kind::stream},
                                             {"snapshot", Insertion::Kind::snapshot}});
    switch (ins.kind) {
      case Insertion::Kind::fill: parse_fill(m, scene, ins); break;
      case Insertion::Kind::csv: parse_csv(m, scene, ins); break;
      case Insertion::Kind::stream: parse_stream(m, scene, ins); break;
      case Insertion::Kind::snapshot:
        parse_snapshot(m, scene, ins);
        break;
    }
    parse_insertion_temperature(m, scene, ins);
    out.push_back(std::move(ins));
  }
  return out;
}

OutputSettings parse_output(const Field& f, const TimeSettings& time, bool heat) {
  const Map m =
      f.map({"directory", "snapshot_interval", "log_interval", "progress", "checkpoint_interval",
             "checkpoint_keep", "fields", "start", "stop", "contacts", "wall_loads"});
  OutputSettings o;
  for (const char* key : {"directory", "snapshot_interval", "log_interval", "progress",
                          "checkpoint_interval", "checkpoint_keep"})
    if (const auto v = m.find(key))
      o.given.emplace_back(key, f.source().label + ":" + std::to_string(v->key_mark().line + 1));
  if (const auto d = m.find("directory")) {
    o.directory = d->text();
    if (o.directory.starts_with("~"))
      d->fail(
          "'~' is not expanded in a scene file (the shell expands it, not grain); write the "
          "full path, or a path relative to the working directory");
    if (o.directory.find_first_not_of(" \t") == std::string::npos)
      d->fail("the folder name is only spaces; name a folder");
  }
  o.snapshot_interval = m.maybe_number("snapshot_interval", kPositive);
  o.log_interval = m.maybe_number("log_interval", kPositive);
  if (const auto p = m.find("progress")) o.progress = p->boolean();
  if (const auto c = m.find("contacts")) o.contacts = c->boolean();
  if (const auto w = m.find("wall_loads")) o.wall_loads = w->boolean();
  o.checkpoint_interval = m.maybe_number("checkpoint_interval", kPositive);
  if (const auto k = m.find("checkpoint_keep"))
    o.checkpoint_keep = static_cast<int>(k->integer(Range{1, 1000, true, true}));
  if (const auto fields = m.find("fields")) {
    std::vector<std::string> names;
    for (const SnapshotField& s : snapshot_fields) names.emplace_back(s.name);
    o.fields = snapshot_required_fields;
    for (const Field& item : fields->non_empty_items("list the snapshot fields to write, e.g. "
                                                     "[velocity, radius, force]; allowed: " +
                                                     join(names))) {
      if (!item.node().IsScalar())
        item.fail("expected a field name, got " + item.got() + "; allowed: " + join(names));
      const std::string name = item.node().Scalar();
      const SnapshotFieldSet bit = snapshot_field_bit(name);
      if (bit == 0)
        item.fail("unknown snapshot field '" + name + "'; allowed: " + join(names) +
                  suggestion(name, names));
      if (bit == snapshot_field_bit("temperature") && !heat)
        item.fail("the field 'temperature' needs heat transfer, which is off; add a top-level "
                  "`heat: {}` block or remove 'temperature' from the list");
      o.fields |= bit;
    }
  } else if (heat) {
    o.fields |= snapshot_field_bit("temperature");  // the default set, and the temperature
  }
  o.start = m.maybe_number("start", kNonNegative);
  o.stop = m.maybe_number("stop", kPositive);
  if (o.start && o.stop && !(*o.start < *o.stop))
    m.get("stop").fail("output.stop (" + format_number(*o.stop) +
                       " s) must be after output.start (" + format_number(*o.start) +
                       " s); snapshots are written at times in [start, stop]");
  if (o.start && *o.start > time.end)
    m.get("start").fail("output.start (" + exact_number(*o.start) + " s) is after time.end (" +
                        exact_number(time.end) +
                        " s): no snapshot would be written; give a start <= time.end");
  return o;
}

// `heat: {conduction: batchelor_obrien | none,
//         contact_radius: geometric | morris_static | morris_collision}`
// (docs/models/heat-transfer.md).
HeatSettings parse_heat(const Field& f) {
  HeatSettings h;
  h.source = f.source().label + ":" + std::to_string(f.line());
  if (f.node().IsNull()) return h;  // `heat:` alone, as `heat: {}`
  const Map m = f.map({"conduction", "contact_radius"});
  if (const auto c = m.find("conduction"))
    h.conduction = c->choice<bool>("contact conduction law",
                                   {{"batchelor_obrien", true}, {"none", false}});
  if (const auto a = m.find("contact_radius")) {
    h.contact_radius = a->choice<ContactRadiusModel>(
        "contact radius for conduction",
        {{"geometric", ContactRadiusModel::geometric},
         {"morris_static", ContactRadiusModel::morris_static},
         {"morris_collision", ContactRadiusModel::morris_collision}});
    h.contact_radius_source = f.source().label + ":" + std::to_string(a->line());
  }
  return h;
}

// Whether any two bodies of the scene can touch (Scene::contacts_possible).
bool contacts_possible(const Scene& s) {
  if (!s.walls.empty()) return true;
  long particles = 0;
  for (const Insertion& ins : s.insertions) {
    switch (ins.kind) {
      case Insertion::Kind::fill:
        if (!ins.count) return true;  // a volume fraction: many
        particles += *ins.count;
        break;
      case Insertion::Kind::csv: {
        std::ifstream in(ins.csv_file);
        if (!in) return true;  // read (and refused) later
        std::string line;
        long rows = -1;  // the header
        while (std::getline(in, line))
          if (line.find_first_not_of(" \t\r") != std::string::npos && line[0] != '#') ++rows;
        particles += std::max(0L, rows);
        break;
      }
      case Insertion::Kind::stream:
      case Insertion::Kind::snapshot:
        return true;
    }
    if (particles > 1) return true;
  }
  return particles != 1;  // an empty scene keeps every key (nothing is gained by leaving any out)
}

// One parcel class per (listed material, k != 1) the insertions use: a copy of the material
// with Material::coarse_grain = k, and every pair property of its real material; each such
// insertion then inserts that class (Insertion::coarse_grain). Classes follow the listed
// materials in the order the insertions first ask for them, so a scene always gives the
// same indices (snapshots and checkpoints store the index).
void add_parcel_classes(Scene& s) {
  const std::size_t listed = s.materials.size();
  const auto parcel_class = [&](int real, double k) {
    for (std::size_t c = listed; c < s.materials.size(); ++c)
      if (s.materials[c].real_material == real && s.materials[c].coarse_grain == k)
        return static_cast<int>(c);
    Material parcel = s.materials[static_cast<std::size_t>(real)];
    parcel.name += "[k=" + format_number(k) + "]";
    parcel.coarse_grain = k;
    parcel.real_material = real;
    s.materials.push_back(parcel);
    return static_cast<int>(s.materials.size() - 1);
  };
  for (Insertion& ins : s.insertions) {
    if (ins.kind == Insertion::Kind::snapshot) {
      // The writer's material indices, in its order of classes, to this scene's.
      const std::vector<double>& k = ins.snapshot_class_k;
      ins.material_map.clear();
      for (std::size_t m = 0; m < k.size(); ++m) {
        const int real = ins.snapshot_class_real[m];  // -1: no material of its name here
        ins.material_map.push_back(k[m] == 1 || real < 0 ? real : parcel_class(real, k[m]));
      }
      continue;
    }
    if (ins.coarse_grain == 1) continue;
    ins.material = parcel_class(ins.material, ins.coarse_grain);
  }
  if (s.materials.size() == listed) return;
  const auto real = [&](int m) {
    const int r = s.materials[static_cast<std::size_t>(m)].real_material;
    return r < 0 ? m : r;
  };
  const int n = static_cast<int>(s.materials.size());
  std::vector<MaterialPair> table;
  table.reserve(pair_count(s.materials.size()));
  for (int a = 0; a < n; ++a)
    for (int b = a; b < n; ++b) {
      MaterialPair p = s.pair(real(a), real(b));
      p.a = a;
      p.b = b;
      table.push_back(p);
    }
  s.pairs = std::move(table);
}

// The models coarse graining does not scale yet refuse parcels (k != 1), naming both keys.
void check_coarse_grain_models(Scene& s, const Map& top) {
  const std::vector<double> k = s.coarse_grain_table();
  if (k.empty()) return;
  const Insertion* first = nullptr;
  for (const Insertion& ins : s.insertions)
    if (ins.coarse_grain != 1 && first == nullptr) first = &ins;
  const std::string where = first->kind == Insertion::Kind::snapshot
                                ? "the parcels (k up to " + format_number(first->coarse_grain) +
                                      ") of the snapshot '" + first->snapshot_file +
                                      "' (the insertion at " + first->source + ")"
                                : "coarse_grain " + format_number(first->coarse_grain) +
                                      " (the insertion at " + first->source + ")";
  // A stiffness in N/m is one contact's, not scaled with the parcel: the energy-conserving
  // rule needs k_n, k_t in proportion to k, which the characteristic-velocity form gives.
  if (s.contact.normal == NormalModel::hooke && s.contact.hooke_kn)
    top.get("contact")
        .map()
        .get("hooke")
        .map()
        .get("stiffness")
        .fail_at_key(
            "a fixed Hooke stiffness is the same for every contact, so it does not grow with the "
            "parcels as the energy-conserving scaling asks (k_n in proportion to k), " +
            where +
            "; use `hooke: {characteristic_velocity: <m/s>}`, whose stiffness follows each "
            "contact's radius and mass (docs/models/coarse-graining.md), or " +
            (first->kind == Insertion::Kind::snapshot
                 ? std::string("real particles (k = 1) in the snapshot")
                 : std::string("coarse_grain: 1")));
  if (!s.fluid) return;
  for (FluidForce f : s.fluid->forces)
    if (f == FluidForce::saffman_mei || f == FluidForce::magnus ||
        f == FluidForce::rotational_drag)
      top.get("fluid").map().get("forces").fail_at_key(
          "the forces saffman_mei, magnus and rotational_drag are not scaled for "
          "coarse-grained parcels, " + where +
          "; allowed with parcels: drag, pressure_gradient, viscous, buoyancy, virtual_mass "
          "(docs/models/coarse-graining.md)");
  s.fluid->coarse_grain = k;
}

const std::vector<std::string> kTopLevelKeys = {
    "domain",  "gravity",   "time",  "materials", "interactions", "interaction_defaults",
    "contact", "neighbour", "walls", "insert",    "output", "parallel", "fluid", "heat"};

// One line "path = value" per scalar under `node` (Scene::model_record).
void add_model_lines(const YAML::Node& node, const std::string& path, const Source& src, Scene& s) {
  if (node.IsMap()) {
    // Sorted by a std::map, which copy-constructs the nodes: assigning a YAML::Node (as
    // std::sort does) writes into the node it refers to.
    std::map<std::string, YAML::Node> entries;
    for (const auto& kv : node) entries.emplace(kv.first.Scalar(), kv.second);
    for (const auto& [key, value] : entries) add_model_lines(value, path + "." + key, src, s);
    return;
  }
  if (node.IsSequence()) {
    for (std::size_t k = 0; k < node.size(); ++k)
      add_model_lines(node[k], path + "[" + std::to_string(k) + "]", src, s);
    return;
  }
  std::string value = node.IsScalar() ? node.Scalar() : "~";
  // A number in its shortest exact form: 1e-3 and 0.001 are one value.
  char* end = nullptr;
  const double number = std::strtod(value.c_str(), &end);
  if (!value.empty() && end != nullptr && *end == '\0' && std::isfinite(number)) {
    char buffer[32];
    const auto [last, error] = std::to_chars(buffer, buffer + sizeof buffer, number);
    if (error == std::errc()) value.assign(buffer, last);
  }
  std::ostringstream line;
  line << path << " = " << value << "\n";
  s.model_record += line.str();
  std::ostringstream where;
  where << src.label << ":" << node.Mark().line + 1;
  s.model_sources.push_back(where.str());
}

// A mesh wall's STL file enters the model by its contents, not its name: the line
// "walls[k].file = <name>" becomes "walls[k].file_content = <FNV-1a 64 digest>, <bytes> bytes"
// (same position, same source line), so that a restart refuses a changed mesh and accepts the
// same file moved or renamed (check_model).
void record_mesh_contents(Scene& s) {
  std::string record;
  std::istringstream lines(s.model_record);
  for (std::string line; std::getline(lines, line);) {
    for (std::size_t k = 0; k < s.walls.size(); ++k) {
      const std::string key = "walls[" + std::to_string(k) + "].file = ";
      if (s.walls[k].kind != Wall::Kind::mesh || !line.starts_with(key)) continue;
      std::ifstream in(s.walls[k].mesh.file, std::ios::binary);
      std::uint64_t digest = kFnv1a64Start;
      std::uint64_t bytes = 0;
      char buffer[1 << 16];
      while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
        const auto n = static_cast<std::size_t>(in.gcount());
        digest = fnv1a64(std::string_view(buffer, n), digest);
        bytes += n;
      }
      char hex[17];
      std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(digest));
      line = "walls[" + std::to_string(k) + "].file_content = fnv1a64 " + hex + ", " +
             std::to_string(bytes) + " bytes";
    }
    record += line + "\n";
  }
  s.model_record = record;
}

// A normal radius distribution is drawn cut to [min, max]; where the cut moves the mean of
// the radii drawn by more than 1 % (a wide stddev meets the default lower bound mean/10, as in
// mean 2e-3, stddev 2e-3: radii of mean 2.64e-3), a note gives the mean and standard deviation
// of the cut distribution (Johnson, Kotz & Balakrishnan 1994, Continuous Univariate
// Distributions 1, sec. 10.1): with a = (min - mean)/stddev, b = (max - mean)/stddev,
// Z = Phi(b) - Phi(a), the mean is mean + stddev (phi(a) - phi(b))/Z and the variance
// stddev^2 (1 + (a phi(a) - b phi(b))/Z - ((phi(a) - phi(b))/Z)^2).
void note_cut_normal_radii(const Map& top, Scene& s) {
  const auto list = top.find("insert");
  if (!list) return;
  const std::vector<Field> items = list->items();
  for (std::size_t i = 0; i < items.size() && i < s.insertions.size(); ++i) {
    const SizeDistribution& d = s.insertions[i].radius;
    if (d.kind != SizeDistribution::Kind::normal || !(d.stddev > 0)) continue;
    const auto phi = [](double x) {
      return std::exp(-0.5 * x * x) / std::sqrt(2 * std::numbers::pi);
    };
    const auto Phi = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
    const double a = (d.min - d.mean) / d.stddev, b = (d.max - d.mean) / d.stddev;
    const double z = Phi(b) - Phi(a);
    if (!(z > 0)) continue;
    const double shift = (phi(a) - phi(b)) / z;
    const double mean = d.mean + d.stddev * shift;
    const double sd =
        d.stddev * std::sqrt(std::max(0.0, 1 + (a * phi(a) - b * phi(b)) / z - shift * shift));
    if (std::abs(mean - d.mean) <= 0.01 * d.mean) continue;
    std::ostringstream o;
    o.precision(4);
    o << "the normal distribution is drawn cut to [min, max] = [" << d.min << ", " << d.max
      << "] m, so the radii drawn have mean " << mean << " m (" << std::showpos
      << 100 * (mean / d.mean - 1) << std::noshowpos << " % on the given mean " << d.mean
      << " m) and standard deviation " << sd << " m (the given " << d.stddev
      << " m is the uncut distribution's); for radii of mean " << d.mean
      << " m, give a smaller stddev or min and max symmetric about the mean";
    s.notes.push_back(items[i].map().get("radius").note_at_key(o.str()));
  }
}

// Settings that are accepted (a scene may keep them while a model is switched off) but have no
// effect in this scene: each named in Scene::notes, with what would use it.
void note_unused_settings(const Map& top, Scene& s) {
  if (s.contacts_possible) {
    std::vector<Field> pairs;
    if (const auto list = top.find("interactions")) pairs = list->items();
    if (const auto d = top.find("interaction_defaults")) pairs.push_back(*d);
    for (const Field& item : pairs) {
      const Map m = item.map();
      const auto unused = [&](const char* key, bool off, bool only_if_positive,
                              const std::string& why) {
        const auto v = m.find(key);
        if (!v || !off || (only_if_positive && !(v->number() > 0))) return;
        s.notes.push_back(v->note_at_key(format_number(v->number()) + " has no effect: " + why));
      };
      unused("rolling_friction", s.contact.rolling == RollingModel::none, true,
             "contact.rolling is none, so contacts resist no rolling; name `rolling: cdt` or "
             "`rolling: epsd` in contact to use it");
      unused("cohesion_energy_density", s.contact.cohesion == CohesionModel::none, true,
             "contact.cohesion is none, so contacts do not attract; name `cohesion: sjkr` in "
             "contact to use it");
      unused("friction", s.contact.tangential == TangentialModel::none, true,
             "contact.tangential is none, so contacts are frictionless; name `tangential: "
             "history` in contact (the default) to use it");
    }
    // The mirror: a rolling or cohesion model named while every pair's coefficient is 0 (the
    // default) does nothing, though the contact law line names it.
    // Pairs that can touch: a particle material with another or with a wall's (a CSV or
    // snapshot file may hold any material: then every one counts as a particle's). A
    // coefficient on a pair of wall materials only acts nowhere.
    const std::size_t n = s.materials.size();
    std::vector<char> particle(n, 0), wall(n, 0);
    bool any_material = s.insertions.empty();
    for (const Insertion& ins : s.insertions) {
      if (ins.kind == Insertion::Kind::csv || ins.kind == Insertion::Kind::snapshot)
        any_material = true;
      else if (ins.material >= 0 && static_cast<std::size_t>(ins.material) < n)
        particle[static_cast<std::size_t>(ins.material)] = 1;
    }
    if (any_material) std::fill(particle.begin(), particle.end(), 1);
    for (const Wall& w : s.walls)
      if (w.material >= 0 && static_cast<std::size_t>(w.material) < n)
        wall[static_cast<std::size_t>(w.material)] = 1;
    const auto can_touch = [&](const MaterialPair& q) {
      const auto a = static_cast<std::size_t>(q.a), b = static_cast<std::size_t>(q.b);
      if (a >= n || b >= n) return true;
      return (particle[a] && (particle[b] || wall[b])) || (particle[b] && wall[a]);
    };
    const auto none_positive = [&](double MaterialPair::*coefficient) {
      return std::none_of(s.pairs.begin(), s.pairs.end(), [&](const MaterialPair& q) {
        return can_touch(q) && q.*coefficient > 0;
      });
    };
    const auto model_key = [&](const char* key) -> std::optional<Field> {
      const auto c = top.find("contact");
      return c && c->node().IsMap() ? c->map().find(key) : std::nullopt;
    };
    if (s.contact.rolling != RollingModel::none && none_positive(&MaterialPair::rolling_friction))
      if (const auto k = model_key("rolling"))
        s.notes.push_back(k->note_at_key(
            k->node().Scalar() +
            " has no effect: no pair of materials has a rolling_friction above 0 (the default "
            "is 0) among the pairs that can touch (particles with particles or walls), so "
            "contacts resist no rolling; give `rolling_friction: <mu_r>` in "
            "interaction_defaults or interactions"));
    if (s.contact.cohesion != CohesionModel::none &&
        none_positive(&MaterialPair::cohesion_energy_density))
      if (const auto k = model_key("cohesion"))
        s.notes.push_back(k->note_at_key(
            k->node().Scalar() +
            " has no effect: no pair of materials has a cohesion_energy_density above 0 (the "
            "default is 0) among the pairs that can touch (particles with particles or walls), so "
            "contacts do not attract; give `cohesion_energy_density: "
            "<J/m^3>` in interaction_defaults or interactions"));
  }
  if (const auto o = top.find("output")) {
    const Map m = o->map();
    if (const auto k = m.find("checkpoint_keep"); k && !s.output.checkpoint_interval)
      s.notes.push_back(k->note_at_key(
          k->node().Scalar() +
          " has no effect: no checkpoint_interval is given, so the run writes no periodic "
          "checkpoints to keep; add `checkpoint_interval: <s>`"));
    if (const auto w = m.find("wall_loads"); w && s.output.wall_loads && s.walls.empty())
      s.notes.push_back(w->note_at_key("true has no effect: the scene has no walls"));
  }
  // A wall's surface moving in its own plane (a cylinder turning about its axis, a mesh
  // conveyor) acts only through friction and rolling resistance.
  if (s.contacts_possible && s.contact.tangential == TangentialModel::none &&
      s.contact.rolling == RollingModel::none)
    if (const auto walls = top.find("walls"))
      for (const Field& wall : walls->items())
        for (const char* key : {"angular_velocity", "surface_velocity"}) {
          const auto v = wall.map().find(key);
          if (!v || (v->node().IsScalar() ? v->number() == 0 : v->vec3().isZero(0))) continue;
          s.notes.push_back(v->note_at_key(
              "is given but has no effect: the wall's surface moves in its own plane, which "
              "only friction and rolling resistance feel, and contact.tangential and "
              "contact.rolling are none; name `tangential: history` in contact to use it"));
        }
  if (const auto walls = top.find("walls"))
    for (const Field& wall : walls->items()) {
      const auto motion = wall.map().find("motion");
      if (!motion || !motion->node().IsMap()) continue;
      const Map m = motion->map();
      const auto w = m.find("angular_velocity");
      if (w && w->number() != 0) continue;
      for (const char* key : {"axis", "axis_point"})
        if (const auto a = m.find(key))
          s.notes.push_back(a->note_at_key(
              "is given but has no effect: the wall does not rotate (motion.angular_velocity "
              "is 0); give `angular_velocity: <rad/s>` to turn it about this axis"));
    }
}

Scene build_scene(const Field& root) {
  if (!root.node().IsDefined() || root.node().IsNull())
    root.fail("the scene is empty; it needs at least domain, time, materials and contact");
  if (!root.node().IsMap())
    root.fail("expected top-level keys (domain:, time:, materials:, contact:, ...), got " +
              root.got() + "; see docs/scene-reference.md");
  const Map top = root.map(kTopLevelKeys);
  Scene s;
  s.file = root.source().label;
  s.domain = parse_domain(top.get("domain", "add `domain: {min: [x, y, z], max: [x, y, z]}`"));
  s.gravity = top.vec3_or("gravity", Vec3::Zero());
  s.time = parse_time(top.get("time", "add `time: {step: <s>, end: <s>}`"));
  if (const auto h = top.find("heat")) s.heat = parse_heat(*h);
  Deferred for_contacts;  // errors that stand only if contacts can happen
  s.materials =
      parse_materials(top.get("materials", "add a list of materials"), for_contacts, s.heat);
  s.pairs = parse_pairs(top, s.materials, for_contacts);
  if (const auto c = top.find("contact"))
    s.contact = parse_contact(*c);
  else
    defer(for_contacts, [&] { top.get("contact", "add `contact: {normal: hertz}`"); });
  // The corrections are Hertz's contact radius at the real modulus: a Hooke spring's overlap
  // is not Hertz's, so they are not offered with it.
  if (s.heat && s.heat->contact_radius != ContactRadiusModel::geometric &&
      s.contact.normal == NormalModel::hooke)
    top.get("heat").map().get("contact_radius").fail_at_key(
        "the soft-particle contact-radius corrections (morris_static, morris_collision) are "
        "built for `contact: {normal: hertz}` only; with `normal: hooke` use "
        "`contact_radius: geometric`");
  if (const auto n = top.find("neighbour")) s.neighbour = parse_neighbour(*n);
  if (const auto w = top.find("walls")) s.walls = parse_walls(*w, s.materials, s.heat, s.domain);
  if (const auto i = top.find("insert")) {
    s.insertions = parse_insertions(*i, s);
    add_parcel_classes(s);
  }
  if (const auto o = top.find("output"))
    s.output = parse_output(*o, s.time, s.heat.has_value());
  else if (s.heat)
    s.output.fields |= snapshot_field_bit("temperature");
  if (const auto p = top.find("parallel")) s.parallel = parse_parallel(*p);
  if (const auto f = top.find("fluid"))
    s.fluid = parse_fluid_section(*f, s.gravity, s.domain, s.heat);
  check_coarse_grain_models(s, top);
  // Parcels: the snapshots carry k and the real-particle count unless the scene lists fields.
  const bool fields_listed = top.find("output") && top.get("output").map().find("fields");
  if (!s.coarse_grain_table().empty() && !fields_listed)
    s.output.fields |= snapshot_field_bit("coarse_grain") | snapshot_field_bit("real_count");
  s.contacts_possible = contacts_possible(s);
  if (s.contacts_possible && !for_contacts.empty()) std::rethrow_exception(for_contacts.front());
  for (const char* section : {"domain", "gravity", "materials", "interactions",
                              "interaction_defaults", "contact", "walls", "heat", "fluid"})
    if (const auto f = top.find(section)) add_model_lines(f->node(), section, root.source(), s);
  record_mesh_contents(s);
  note_unused_settings(top, s);
  note_cut_normal_radii(top, s);
  // The Rayleigh time needs the elastic constants of every material a particle uses.
  if (s.time.rayleigh_fraction)
    for (const Material& mat : s.materials)
      if (mat.youngs_modulus == 0)
        top.get("time").map(kTimeKeys).get("rayleigh_fraction").fail_at_key(
            "the Rayleigh time needs youngs_modulus and poisson_ratio of material '" + mat.name +
            "', which are left out (no contact can happen in this scene); give `step: <s>` "
            "instead");
  return s;
}

// YAML forbids tabs in indentation, and yaml-cpp's message for them is cryptic:
// name the first offending line at or before the error instead.
void raise_if_tab_indented(const std::string& text, int error_line, const Source& src) {
  std::istringstream lines(text);
  std::string line;
  for (int n = 0; n <= error_line && std::getline(lines, line); ++n) {
    const std::size_t first = line.find_first_not_of(" \t");
    const std::size_t tab = line.find('\t');
    if (tab != std::string::npos && tab < first) {
      YAML::Mark m = start_of_file();
      m.line = n;
      m.column = static_cast<int>(tab);
      raise(src, m, "YAML syntax error: a tab is used for indentation; indent with spaces only");
    }
  }
}

YAML::Node load_yaml(const std::string& text, const Source& src) {
  // A scene is one document: a `---` line after content starts a second one, whose keys
  // YAML::Load would drop without a word. Found in the text (yaml-cpp's LoadAll loops for
  // ever on some inputs, such as a lone ',').
  {
    std::istringstream lines(text);
    bool content = false;
    int n = 0, ended = -1;  // ended: the line of a document-end marker '...'
    const auto is_marker = [](const std::string& line, const char* marker) {
      return line.starts_with(marker) &&
             (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r');
    };
    for (std::string line; std::getline(lines, line); ++n) {
      const bool marker = is_marker(line, "---");
      const std::size_t from = line.find_first_not_of(" \t\r");
      const bool keys = from != std::string::npos && line[from] != '#' && line[from] != '%';
      if (ended >= 0 && keys) {
        YAML::Mark at = start_of_file();
        at.line = ended;
        raise(src, at,
              std::string("the YAML document ends here (a '...' line), and ") +
                  (marker ? "a second one starts at line " : "the keys after it, from line ") +
                  std::to_string(n + 1) +
                  ", would not be read: a scene is one document; remove the '...' line" +
                  (marker ? " and the '---' line" : ""));
      }
      if (is_marker(line, "...")) {
        ended = n;
        continue;
      }
      if (marker && content) {
        YAML::Mark at = start_of_file();
        at.line = n;
        raise(src, at,
              "a second YAML document starts here (a '---' line after the first one's keys): a "
              "scene is one document, and the keys after '---' would not be read; remove the "
              "'---' line");
      }
      const std::size_t first = line.find_first_not_of(" \t\r");
      if (!marker && first != std::string::npos && line[first] != '#' && line[first] != '%')
        content = true;
    }
  }
  try {
    return YAML::Load(text);
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp stops at a fixed depth (500 in 0.7) instead of overflowing the stack,
    // with only "bad file" as its message.
    raise(src, e.mark,
          "YAML syntax error: brackets or indentation nest " + std::to_string(e.depth()) +
              " levels deep; a scene needs at most a few levels (check for unclosed '[' or '{')");
  } catch (const YAML::ParserException& e) {
    raise_if_tab_indented(text, e.mark.line, src);
    raise(src, e.mark,
          "YAML syntax error: " + e.msg +
              "; check indentation, brackets, quotes and the ':' after each key");
  } catch (const YAML::Exception& e) {
    raise(src, e.mark.line >= 0 ? e.mark : start_of_file(),
          "the file cannot be read as YAML: " + e.msg);
  }
}

}  // namespace

Scene parse_scene(const std::string& yaml_text, const std::string& file_label) {
  const Source src{file_label, fs::path(file_label).parent_path()};
  const Field root(src, load_yaml(yaml_text, src), "", start_of_file());
  return build_scene(root);
}

std::string read_scene_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (std::error_code ec; fs::is_directory(path, ec))
    throw SceneError(path, 0, 0, "is a directory, not a scene file; name the .yaml file in it");
  if (!in)
    throw SceneError(path, 0, 0,
                     "cannot open the scene file; check the path (relative paths are taken from "
                     "the working directory " +
                         fs::current_path().string() + ")");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw SceneError(path, 0, 0, "cannot read the scene file; check its permissions");
  return text.str();
}

Scene load_scene(const std::string& path) { return parse_scene(read_scene_file(path), path); }

}  // namespace grainflow
