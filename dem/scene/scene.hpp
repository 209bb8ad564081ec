#pragma once
// The scene: everything a run needs, as parsed and validated from the YAML file.
// Plain data; the parser (scene_parser.hpp) guarantees every invariant documented
// here, so the engine never re-validates.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dem/core/types.hpp"
#include "dem/fluid/prescribed_fluid.hpp"

namespace grainflow {

struct Material {
  std::string name;
  // Y > 0 [Pa], -1 < nu < 0.5; both 0 when not given, which only a scene in which no contact
  // can happen allows (Scene::contacts_possible).
  double youngs_modulus = 0;
  double poisson_ratio = 0;
  double density = 0;         // > 0 [kg/m^3]
  // Heat transfer (Scene::heat; docs/models/heat-transfer.md): given for every material when
  // heat is on, else 0.
  double heat_capacity = 0;  // c_p > 0 [J/(kg K)]
  double conductivity = 0;   // k > 0 [W/(m K)]
  double heat_source = 0;    // q [W/kg], any sign (0: none)
  // The real material's Young's modulus [Pa] > 0 when heat.contact_radius corrects the
  // contact radius of soft particles (HeatSettings::contact_radius), else 0.
  double real_youngs_modulus = 0;
  // Coarse graining (docs/models/coarse-graining.md): a particle of this material is a
  // parcel of radius k r standing for k^3 real particles of radius r, with the real material's
  // properties. The parser adds one such parcel class per (material, k != 1) an insertion
  // asks for, a copy of the real material `real_material` with `coarse_grain` = k and every
  // pair property of it; a material the scene lists has k = 1 and is its own real material.
  double coarse_grain = 1;  // k >= 1
  int real_material = -1;   // index of the listed material (-1: this one)
};

// Properties of a pair of materials (symmetric). Pairs not listed use the
// scene's `interaction_defaults` if given; the parser rejects a scene where a
// needed pair has neither.
struct MaterialPair {
  int a = 0, b = 0;                      // material indices
  double restitution = 0.5;              // (0, 1]
  double friction = 0.5;                 // sliding friction coefficient mu >= 0
  double rolling_friction = 0.0;         // mu_r >= 0
  double cohesion_energy_density = 0.0;  // SJKR k_c >= 0 [J/m^3]
};

enum class NormalModel { hertz, hooke };
enum class TangentialModel { none, history };
enum class RollingModel { none, cdt, epsd };
enum class CohesionModel { none, sjkr };
// The velocity the contact dashpots see (docs/models/contact-models.md, "Integration"):
// velocity Verlet's half-step velocity, or the end-of-step velocity predicted from it.
enum class DashpotVelocity { half_step, predicted };

struct ContactSettings {
  NormalModel normal = NormalModel::hertz;
  TangentialModel tangential = TangentialModel::history;
  RollingModel rolling = RollingModel::none;
  CohesionModel cohesion = CohesionModel::none;
  // Hooke: either a characteristic impact velocity (stiffness from Hertz theory at
  // that speed) or explicit stiffnesses. Exactly one form is set when normal == hooke.
  std::optional<double> hooke_characteristic_velocity;  // [m/s] > 0
  std::optional<double> hooke_kn;                       // [N/m] > 0
  std::optional<double> hooke_kt;                       // [N/m] > 0 (default: kt = kn)
  double epsd_damping_ratio = 0.3;                      // EPSD rolling viscous damping ratio in [0, 1]
  DashpotVelocity dashpot_velocity = DashpotVelocity::half_step;
};

struct Domain {
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Ones();
  std::array<bool, 3> periodic{false, false, false};
};

struct TimeSettings {
  std::optional<double> step;                     // dt [s] > 0, or
  std::optional<double> rayleigh_fraction;        // dt = fraction * Rayleigh time, (0, 1]
  double end = 0;                                 // simulated end time [s] > 0
  std::string end_source;                         // "file:line" of time.end, for messages
  std::string step_source;  // "file:line" of time.step or time.rayleigh_fraction, for messages
  double expected_max_speed = 1.0;                // for the Hertz contact-time check [m/s]
  double max_overlap = 0.25;  // overlap / smaller radius that stops the run, (0, 1]
  // Hertz contacts: t_c(v)/dt at a contact's own approach speed v below this stops the
  // run (the start-up refusal threshold of grain check); 0 turns the check off.
  double min_steps_per_contact = 5;
  // Largest distance a particle may move in one step, in its own radii; beyond it the run
  // stops (a particle that fast can pass a mesh wall or another particle unseen); 0: off.
  double max_step_travel = 1;
};

struct PlaneWall {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // unit; particles live on the side it points to
};

struct CylinderWall {
  Vec3 axis_point = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();   // unit
  double radius = 1;           // > 0
  bool inside = true;          // particles inside the cylinder (true) or outside (false)
  double angular_velocity = 0; // surface rotation about `axis` (right hand) [rad/s]
};

// A triangle mesh read from an STL file and placed by x' = R(axis, angle)(scale x) + translate.
struct MeshWall {
  std::string file;                      // resolved relative to the scene file's folder
  std::string file_source;               // "scene file:line" of the `file` key, for messages
  double scale = 1;                      // > 0
  Vec3 rotate_axis = Vec3::UnitZ();      // unit
  double rotate_angle = 0;               // [rad] (degrees in the scene file)
  Vec3 translate = Vec3::Zero();
  Vec3 surface_velocity = Vec3::Zero();  // conveyor: tangential surface speed [m/s]
  // Vertices closer than this times the bounding box's diagonal are one (stl_reader.hpp).
  double weld_tolerance = 1e-5;
};

// Prescribed rigid motion of a wall (dem/walls/wall_motion.hpp): a point x0 of the
// wall is at P + V t + R(axis, w t)(x0 - P) at time t.
struct WallMotion {
  Vec3 velocity = Vec3::Zero();    // V [m/s]
  double angular_velocity = 0;     // w [rad/s], right hand about `axis`
  Vec3 axis_point = Vec3::Zero();  // P
  Vec3 axis = Vec3::UnitZ();       // unit
};

// A wall's thermal condition (heat on; docs/models/heat-transfer.md): no heat through it, a
// fixed temperature across contacts, or a fixed heat flux density through the contact areas.
struct WallThermal {
  enum class Kind { adiabatic, temperature, flux } kind = Kind::adiabatic;
  double value = 0;  // temperature [K] or flux density into the particle [W/m^2]
};

struct Wall {
  enum class Kind { plane, cylinder, mesh } kind = Kind::plane;
  WallThermal thermal;
  std::string name;
  int material = 0;
  PlaneWall plane;
  CylinderWall cylinder;
  MeshWall mesh;
  WallMotion motion;
};

struct SizeDistribution {
  enum class Kind { constant, uniform, normal, discrete } kind = Kind::constant;
  double value = 0;              // constant radius
  double min = 0, max = 0;       // uniform bounds; normal truncation bounds
  double mean = 0, stddev = 0;   // normal
  std::vector<double> values;    // discrete radii
  std::vector<double> weights;   // discrete number fractions (normalised by the parser)
};

struct Region {
  enum class Kind { box, cylinder } kind = Kind::box;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // box
  Vec3 base = Vec3::Zero();                   // cylinder: centre of the base disc
  Vec3 axis = Vec3::UnitZ();                  // cylinder: unit axis
  double radius = 0, height = 0;              // cylinder
};

// The planar face a stream insertion feeds particles through.
// A fill region (a stream face) may be narrower than its particles' diameter by this share of
// it: round-off of the scene's decimals (0.0115 - 0.0085 < 0.003).
constexpr double kRegionFitTolerance = 1e-9;

struct InsertionFace {
  enum class Kind { rectangle, disc } kind = Kind::rectangle;
  Vec3 centre = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // unit
  Vec3 u = Vec3::UnitX();       // rectangle: unit direction of the side of length `length_u`
  double length_u = 0, length_v = 0;  // rectangle sides [m]
  double radius = 0;                  // disc [m]
};

struct Insertion {
  enum class Kind { fill, csv, stream, snapshot } kind = Kind::fill;
  // stream (dem/insert/stream_insertion.hpp): `radius`, `material`, `velocity`, `seed`
  // as for fill; exactly one of the two rates.
  InsertionFace face;
  std::optional<double> mass_rate;   // [kg/s]
  std::optional<double> count_rate;  // [1/s]
  double start = 0;                  // [s]
  std::optional<double> stop;        // [s]; default: the end of the run
  // snapshot: a grainflow HDF5 snapshot (dem/io/snapshot_reader.hpp)
  std::string snapshot_file;  // resolved relative to the scene file's folder
  bool keep_velocity = true;  // false: particles start at rest
  // A snapshot of parcels: the writing scene's parcel classes (its root attributes
  // material_coarse_grain and material_real, one entry per material index), and for each of
  // its material indices this scene's (the parser adds a class per (real material, k) the
  // snapshot holds). When the snapshot names its materials (root attribute material_names),
  // each listed material is this scene's material of that name, in whatever order this scene
  // lists them (-1: this scene has no material of that name; an error if a particle has it).
  // Empty: a snapshot of real particles without names, read with its material indices.
  std::vector<double> snapshot_class_k;
  std::vector<int> snapshot_class_real;
  std::vector<int> material_map;
  std::vector<std::string> snapshot_material_names;  // the writer's, by its material index
  // fill
  Region region;
  std::optional<long> count;              // number of particles, or
  std::optional<double> volume_fraction;  // solid volume fraction of the region, (0, 0.6]
  SizeDistribution radius;
  int material = 0;
  Vec3 velocity = Vec3::Zero();
  unsigned seed = 1;  // the parser's default: 1 + the entry's index in `insert`
  // csv: columns x,y,z,radius and optionally vx,vy,vz, wx,wy,wz, material (material by name)
  std::string csv_file;  // resolved relative to the scene file's folder
  // A csv file that does not exist: the error (file:line:column) its insertion reports. A
  // restart, which inserts nothing, runs without it (the parser cannot tell the two apart).
  std::string csv_missing;
  std::string source;    // "file:line" of this entry, for messages
  // fill, stream: coarse-graining factor k >= 1 (`coarse_grain`); with k != 1 the parser has
  // already set `material` to the parcel class (Material::coarse_grain) and multiplied
  // `radius` by k, so every particle inserted is a parcel. snapshot: the largest k of the
  // parcel classes the file holds (1: real particles only).
  double coarse_grain = 1;
  // Heat on: the particles' initial temperature [K] (fill, stream; csv rows without a `T`
  // column; snapshots without a temperature dataset). Absent when heat is off.
  std::optional<double> temperature;
};

struct OutputSettings {
  std::string directory = "output";       // relative to the working directory
  std::optional<double> snapshot_interval; // simulated seconds between HDF5 snapshots
  std::optional<double> log_interval;      // simulated seconds between CSV log rows
  bool progress = true;                    // terminal progress line with ETA
  std::optional<double> checkpoint_interval; // simulated seconds between checkpoints; none: off
  int checkpoint_keep = 2;                   // periodic checkpoints kept on disk (>= 1)
  // The keys the scene gives, with "file:line" of each (grainFoam
  // honours some and refuses the others, naming where they are).
  std::vector<std::pair<std::string, std::string>> given;
  // The snapshot datasets to write, a SnapshotFieldSet (dem/io/xdmf_index.hpp): bit k for
  // snapshot_fields[k]; id and position always. Default: the first eight fields.
  std::uint32_t fields = (std::uint32_t{1} << 8) - 1;
  // Snapshots only at times in [start, stop] (simulated seconds); start < stop.
  std::optional<double> start;
  std::optional<double> stop;
  // Each snapshot also holds the contact network (touching pairs and wall contacts with
  // their forces; dem/io/contact_network.hpp), indexed as lines in the XDMF.
  bool contacts = false;
  // Each wall's load: the mean force the particles exert on it since the previous log row,
  // as columns of log.csv (grain) or a line at each write time (grainFoam).
  bool wall_loads = false;
};

struct NeighbourSettings {
  std::optional<double> skin;  // [m] > 0; default 0.4 * the largest radius
};

// How the DEM is spread over MPI ranks (DESIGN.md §2).
struct ParallelSettings {
  std::array<int, 3> grid{0, 0, 0};  // ranks per axis; all 0: chosen for least cut area
  bool balance = false;              // move cut planes to balance particle counts
  // Sum every particle's contact forces in a canonical order (by partner key), so that the
  // trajectory does not depend on the rank count or grid (dem/engine/canonical_order.hpp).
  bool reproducible = false;
  // The keys the scene gives, with their "file:line" (grainFoam, whose decomposition is the
  // fluid mesh's, refuses grid and balance naming where they are).
  std::vector<std::pair<std::string, std::string>> given;
};

// Heat transfer (docs/models/heat-transfer.md): present when the scene switches it on
// (`heat:`); absent, no thermal code runs.
// The contact radius a of conduction (docs/models/heat-transfer.md, "Contact radius"):
// the overlap's geometric (Hertz) radius, or that radius corrected for a Young's modulus
// softer than the real one (Morris et al. 2016): for enduring contacts (the real contact
// radius under the same load) or for collisions (the real heat of a whole Hertz impact).
enum class ContactRadiusModel { geometric, morris_static, morris_collision };

struct HeatSettings {
  // Contact conduction law (Batchelor & O'Brien 1977, Q = 2 k* a dT) on or off.
  bool conduction = true;
  ContactRadiusModel contact_radius = ContactRadiusModel::geometric;
  std::string contact_radius_source;  // "file:line" of `contact_radius`, for messages
  std::string source;  // "file:line" of the block, for messages
};

struct Scene {
  std::string file;  // path it was read from
  // The scene's model as its file gives it: one line "path = value" per key of domain, gravity,
  // materials, interactions, interaction_defaults, contact, walls, heat and fluid (map keys in
  // sorted order, numbers in their shortest exact form). A checkpoint keeps it, and a restart
  // with another model is refused (check_model, dem/engine/model_record.hpp). model_sources:
  // each line's "file:line", in the same order.
  std::string model_record;
  std::vector<std::string> model_sources;
  Domain domain;
  Vec3 gravity = Vec3::Zero();
  TimeSettings time;
  std::vector<Material> materials;
  std::vector<MaterialPair> pairs;  // one entry per unordered pair (a <= b), complete
  ContactSettings contact;
  NeighbourSettings neighbour;
  std::vector<Wall> walls;
  std::vector<Insertion> insertions;
  OutputSettings output;
  ParallelSettings parallel;
  std::optional<FluidSettings> fluid;  // one-way fluid (docs/scene-reference.md, `fluid:`)
  std::optional<HeatSettings> heat;    // heat transfer on (docs/models/heat-transfer.md)
  // False when nothing in the scene can touch: no walls, and one particle (a fill entry of
  // count 1 or a CSV file of one row; no stream or snapshot). Then `contact`, `interactions`
  // and the materials' elastic constants may be left out.
  bool contacts_possible = true;
  // Settings the scene gives that have no effect in it (a pair's rolling_friction with
  // contact.rolling none, ...): one "<file>:<line>:<column>: note: ..." line each, printed at
  // start-up by grain check, grain run and grainFoam.
  std::vector<std::string> notes;

  int material_index(const std::string& name) const;  // -1 if absent
  // Every material's coarse-graining factor k (Material::coarse_grain), indexed by material;
  // empty when every particle is a real one (k = 1 for all).
  std::vector<double> coarse_grain_table() const;
  // Every material's listed material (its own index for a listed one, Material::real_material
  // for a parcel class), indexed by material; empty like coarse_grain_table().
  std::vector<int> real_material_table() const;
  // The materials' names in index order (parcel classes included).
  std::vector<std::string> material_names() const;
  const MaterialPair& pair(int a, int b) const;       // precondition: complete table
};

}  // namespace grainflow
