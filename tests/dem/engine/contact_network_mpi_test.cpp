// The contact network in the snapshots (output.contacts), on 2 ranks (CTest runs it with
// mpirun -np 2).
//
// References:
//  - Two spheres at rest pressed together at overlap delta, across the ranks' cut: one pair,
//    reported once, with the Hertz force F = (4/3) Y* sqrt(R*) delta^1.5 along the line of
//    centres (R* = r/2; 1/Y* = 2 (1 - nu^2)/Y for one material), no tangential force, the
//    contact point midway. A sphere spinning on a plane at overlap delta_w: normal force
//    (4/3) Y* sqrt(r) delta_w^1.5 (R* = r for a wall), tangential force at the Coulomb limit
//    mu F_n opposing the slip, acting on the plane at r - delta_w below the centre (Hertz
//    1881; Cundall & Strack 1979). Tolerance 1e-9 relative: the overlaps come from
//    coordinates of 1e-2 m, rounded at 2e-18 m, against overlaps of 1e-5 m.
//  - A frictional bed poured through a one-way air flow onto a floor plane, against a side
//    plane and a side mesh (periodic in y): Newton's second law as the snapshot states it, for
//    every particle, sum of its pair forces (+ on the lower id, - on the other) + its wall forces +
//    m g + fluid_force = force (the snapshot's total), to round-off; and 2 M + W = the sum of the
//    coordination field (an independent count of the touching contacts).
//  - A cohesive bed with the laws whose reports had been wrong (tangential none with the
//    half-step dashpot; the predicted dashpot): no tangential force along the normal, none at
//    all without a tangential spring.
//  - The same bed on 1 and 2 ranks (parallel.reproducible: the same state on both): the same
//    pairs by ids, none twice, and the same forces; a restart from the checkpoint continues
//    the contact output with the uninterrupted run's networks and an index that lists every
//    snapshot's network.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "dem/engine/run.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/io/contact_network.hpp"
#include "dem/io/snapshot_writer.hpp"
#include "dem/scene/scene_parser.hpp"
#include "dem/walls/stl_reader.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

// A fresh, empty directory per test, the same path on every rank.
fs::path test_directory() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir =
      fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "contact_network_mpi_test" / info->name();
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A dataset of `file` as doubles (ids exact at these sizes), flattened; empty if absent.
std::vector<double> read_doubles(hid_t file, const std::string& path) {
  std::vector<double> out;
  if (H5Lexists(file, path.c_str(), H5P_DEFAULT) <= 0) return out;
  const hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(d);
  out.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  H5Sclose(space);
  if (!out.empty()) {
    EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0) << path;
  }
  H5Dclose(d);
  return out;
}

std::string units_of(hid_t file, const std::string& path) {
  const hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  const hid_t a = H5Aopen(d, "units", H5P_DEFAULT);
  const hid_t type = H5Aget_type(a);
  std::string s(H5Tget_size(type), '\0');
  H5Aread(a, type, s.data());
  H5Tclose(type);
  H5Aclose(a);
  H5Dclose(d);
  return s.substr(0, s.find('\0'));
}

// One snapshot file read serially: the particle datasets and the two contact groups.
struct Snapshot {
  std::map<std::string, std::vector<double>> particles;  // by dataset name
  std::map<std::string, std::vector<double>> pairs;      // /contacts/<name>
  std::map<std::string, std::vector<double>> walls;      // /wall_contacts/<name>
  bool has_network = false;
  long pair_count_attribute = -1;
  std::size_t size() const { return particles.at("id").size(); }
  std::size_t pair_count() const { return pairs.at("overlap").size(); }
  std::size_t wall_count() const { return walls.at("overlap").size(); }
  std::map<std::int64_t, std::size_t> rows() const {
    std::map<std::int64_t, std::size_t> r;
    for (std::size_t i = 0; i < size(); ++i) r[std::llround(particles.at("id")[i])] = i;
    return r;
  }
};

Vec3 row3(const std::vector<double>& a, std::size_t k) {
  return {a[3 * k], a[3 * k + 1], a[3 * k + 2]};
}

Snapshot read_snapshot(const fs::path& path) {
  Snapshot s;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(file, 0) << path;
  if (file < 0) return s;
  for (const SnapshotField& f : snapshot_fields)
    if (H5Lexists(file, f.name, H5P_DEFAULT) > 0)
      s.particles[f.name] = read_doubles(file, std::string("/") + f.name);
  s.has_network = H5Lexists(file, pair_contact_group, H5P_DEFAULT) > 0;
  if (s.has_network) {
    for (const ContactField& c : pair_contact_fields) {
      const std::string p = std::string("/") + pair_contact_group + "/" + c.field.name;
      s.pairs[c.field.name] = read_doubles(file, p);
      EXPECT_EQ(units_of(file, p), c.field.units) << p;
    }
    for (const ContactField& c : wall_contact_fields) {
      const std::string p = std::string("/") + wall_contact_group + "/" + c.field.name;
      s.walls[c.field.name] = read_doubles(file, p);
      EXPECT_EQ(units_of(file, p), c.field.units) << p;
    }
    std::int64_t n = -1;
    const hid_t a = H5Aopen_by_name(file, pair_contact_group, "count", H5P_DEFAULT, H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_INT64, &n);
    H5Aclose(a);
    s.pair_count_attribute = static_cast<long>(n);
  }
  H5Fclose(file);
  return s;
}

std::vector<fs::path> snapshots_in(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("particles_", 0) == 0 && e.path().extension() == ".h5") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

void expect_vec_near(const Vec3& got, const Vec3& want, double tol, const std::string& what) {
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want[a], tol) << what << " component " << a;
}

// --- closed forms of Hertz contacts ---------------------------------------------------------

constexpr double kY = 5e6, kNu = 0.3, kMu = 0.5;
constexpr double kR = 1e-3;       // m
constexpr double kDelta = 2e-5;   // pair overlap [m]
constexpr double kDeltaW = 1e-5;  // wall overlap [m]

TEST(ContactNetwork, HertzPairAndWallContactGiveClosedFormForces) {
  const fs::path dir = test_directory();
  const Scene scene = parse_scene(
      "domain: {min: [-0.02, -0.005, -0.005], max: [0.02, 0.005, 0.005]}\n"
      "time: {step: 1e-6, end: 1e-3}\n"
      "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
      "interactions: [{materials: [glass, glass], restitution: 0.5, friction: 0.5}]\n"
      "contact: {normal: hertz, tangential: history}\n"
      "walls: [{type: plane, name: floor, point: [0, 0, -0.005], normal: [0, 0, 1], "
      "material: glass}]\n"
      "output: {progress: false, contacts: true}\n",
      "hertz.yaml");
  ASSERT_TRUE(scene.output.contacts);
  // The domain is 4x longer in x: 2 ranks cut it at x = 0, between the pair's spheres (a
  // contact through a ghost on each side, which only the owner of id 1 reports).
  Simulation sim(scene, /*insert=*/false, MPI_COMM_WORLD);
  Particles& p = sim.particles();
  const double rho = 2500, half = kR - 0.5 * kDelta;
  p.add(1, Vec3(-half, 0, 0.002), Vec3::Zero(), Vec3::Zero(), kR, 0, rho);
  p.add(2, Vec3(half, 0, 0.002), Vec3::Zero(), Vec3::Zero(), kR, 0, rho);
  const double z3 = -0.005 + kR - kDeltaW;  // on the floor, spinning about +y at 1000 rad/s
  p.add(3, Vec3(0.01, 0, z3), Vec3::Zero(), Vec3(0, 1000, 0), kR, 0, rho);
  p.add(4, Vec3(-0.01, 0, 0), Vec3::Zero(), Vec3::Zero(), kR, 0, rho);  // touches nothing
  sim.next_id() = 5;
  sim.record_contacts(true);
  sim.initialise();
  SnapshotWriter writer(MPI_COMM_WORLD, dir.string(), "particles");
  writer.write(sim.particles(), sim.time(), 0, sim.snapshot_extras(writer.fields()),
               &sim.contact_network());
  if (world_rank() == 0) {
    const Snapshot s = read_snapshot(dir / "particles_000000.h5");
    ASSERT_TRUE(s.has_network);
    ASSERT_EQ(s.pair_count(), 1u);
    EXPECT_EQ(s.pair_count_attribute, 1);
    ASSERT_EQ(s.wall_count(), 1u);
    const double y_star = kY / (2 * (1 - kNu * kNu));
    // The overlaps as the coordinates give them (within 1e-18 m of kDelta, kDeltaW).
    const double delta = (kR + kR) - (half - (-half));
    const double delta_w = kR - (z3 - (-0.005));
    const double f = 4.0 / 3.0 * y_star * std::sqrt(kR / 2) * std::pow(delta, 1.5);
    EXPECT_EQ(s.pairs.at("id"), (std::vector<double>{1, 2}));
    // On sphere 1 (the lower id) by sphere 2: pushed to -x; nothing tangential at rest.
    expect_vec_near(row3(s.pairs.at("normal_force"), 0), Vec3(-f, 0, 0), 1e-9 * f, "F_n");
    expect_vec_near(row3(s.pairs.at("tangential_force"), 0), Vec3::Zero(), 1e-15 * f, "F_t");
    EXPECT_NEAR(s.pairs.at("normal_force_magnitude")[0], f, 1e-9 * f);
    EXPECT_NEAR(s.pairs.at("overlap")[0], delta, 1e-9 * delta);
    expect_vec_near(row3(s.pairs.at("point"), 0), Vec3(0, 0, 0.002), 1e-15, "point");
    expect_vec_near(row3(s.pairs.at("ends"), 0), Vec3(-half, 0, 0.002), 0, "end a");
    expect_vec_near(row3(s.pairs.at("ends"), 1), Vec3(half, 0, 0.002), 0, "end b");
    // The floor sphere slides: friction pushes +x with mu F_n, at the plane below it.
    const double fw = 4.0 / 3.0 * y_star * std::sqrt(kR) * std::pow(delta_w, 1.5);
    EXPECT_EQ(s.walls.at("id")[0], 3);
    EXPECT_EQ(s.walls.at("wall")[0], 0);
    expect_vec_near(row3(s.walls.at("normal_force"), 0), Vec3(0, 0, fw), 1e-9 * fw, "wall F_n");
    expect_vec_near(row3(s.walls.at("tangential_force"), 0), Vec3(kMu * fw, 0, 0), 1e-9 * fw,
                    "wall F_t");
    EXPECT_NEAR(s.walls.at("normal_force_magnitude")[0], fw, 1e-9 * fw);
    EXPECT_NEAR(s.walls.at("overlap")[0], delta_w, 1e-9 * delta_w);
    expect_vec_near(row3(s.walls.at("point"), 0), Vec3(0.01, 0, -0.005), 1e-15, "wall point");
    expect_vec_near(row3(s.walls.at("ends"), 0), Vec3(0.01, 0, z3), 0, "wall end 0");
    expect_vec_near(row3(s.walls.at("ends"), 1), Vec3(0.01, 0, -0.005), 1e-15, "wall end 1");
    // The index shows the network as lines coloured by cell attributes.
    const std::string xml = slurp(dir / "particles.xdmf");
    EXPECT_EQ(count(xml, "CollectionType=\"Spatial\""), 1u);
    EXPECT_EQ(count(xml, "TopologyType=\"Polyline\" NumberOfElements=\"1\" NodesPerElement=\"2\""),
              2u);
    EXPECT_EQ(count(xml,
                    "<Attribute Name=\"normal_force_magnitude\" AttributeType=\"Scalar\" "
                    "Center=\"Cell\">"),
              2u);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// The split of each contact force into normal_force and tangential_force follows the law's
// own force: without a tangential spring the tangential part is zero, and with the predicted
// dashpot the normal part carries the whole normal force. Checked on a cohesive bed poured into
// a box on 2 ranks, for the laws whose report had read a velocity the sweep does not set
// (tangential none, half-step dashpot: the split changed from run to run) or the half-step
// dashpot where the predicted one acts (a part of the normal force reported as tangential).
TEST(ContactNetwork, SplitFollowsTheLawWithoutSpringAndWithPredictedDashpot) {
  const fs::path dir = test_directory();
  const std::string base =
      "domain: {min: [0, 0, 0], max: [0.008, 0.008, 0.02]}\n"
      "gravity: [0, 0, -98.1]\n"
      "time: {step: 7e-6, end: 0.012}\n"
      "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
      "interactions: [{materials: [glass, glass], restitution: 0.3, friction: 0.4, "
      "cohesion_energy_density: 5e4}]\n"
      "contact: {normal: hertz, cohesion: sjkr, CONTACT}\n"
      "walls:\n"
      "  - {type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}\n"
      "  - {type: plane, name: left, point: [0, 0, 0], normal: [1, 0, 0], material: glass}\n"
      "  - {type: plane, name: right, point: [0.008, 0, 0], normal: [-1, 0, 0], "
      "material: glass}\n"
      "insert: [{type: fill, region: {box: {min: [0, 0, 0.0005], max: [0.008, 0.008, 0.015]}}, "
      "count: 150, material: glass, radius: {distribution: uniform, min: 4e-4, max: 6e-4}}]\n"
      "output: {progress: false, contacts: true, snapshot_interval: 0.004}\n";
  for (const std::string contact :
       {"tangential: none", "tangential: none, dashpot_velocity: predicted",
        "tangential: history, dashpot_velocity: predicted"}) {
    SCOPED_TRACE(contact);
    std::string text = base;
    text.replace(text.find("CONTACT"), 7, contact);
    const Scene scene = parse_scene(text, (dir / "split.yaml").string());
    RunOptions options;
    options.progress = false;
    options.handle_stop_signals = false;
    std::ostringstream log;
    const std::string name = std::to_string(contact.size());
    options.output_directory = (dir / name).string();
    run_scene(scene, options, MPI_COMM_WORLD, log);
    if (world_rank() != 0) continue;
    const bool no_spring = contact.find("none") != std::string::npos;
    long contacts_seen = 0;
    for (const fs::path& file : snapshots_in(dir / name)) {
      SCOPED_TRACE(file.string());
      const Snapshot s = read_snapshot(file);
      ASSERT_TRUE(s.has_network);
      for (const auto* group : {&s.pairs, &s.walls}) {
        const std::size_t n = group->at("overlap").size();
        for (std::size_t k = 0; k < n; ++k) {
          const Vec3 fn = row3(group->at("normal_force"), k);
          const Vec3 ft = row3(group->at("tangential_force"), k);
          const double scale = fn.norm() + ft.norm();
          ASSERT_GT(scale, 0);
          // Along the normal: the reported normal force is the law's whole normal force.
          EXPECT_LE(std::abs(ft.dot(fn.normalized())), 1e-12 * scale) << "contact " << k;
          EXPECT_NEAR(group->at("normal_force_magnitude")[k], fn.norm(), 1e-12 * scale);
          if (no_spring) {
            EXPECT_LE(ft.norm(), 1e-12 * scale) << "contact " << k;
          }
          ++contacts_seen;
        }
      }
    }
    EXPECT_GT(contacts_seen, 80);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(ContactNetwork, NetworkAskedWithoutRecordingIsALogicError) {
  const Scene scene = parse_scene(
      "domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.01]}\n"
      "time: {step: 1e-6, end: 1e-3}\n"
      "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
      "interactions: [{materials: [glass, glass], restitution: 0.5, friction: 0.5}]\n"
      "contact: {normal: hertz}\n"
      "output: {progress: false}\n",
      "off.yaml");
  EXPECT_FALSE(scene.output.contacts);  // the default
  Simulation sim(scene, /*insert=*/false, MPI_COMM_WORLD);
  sim.particles().add(1, Vec3(0.005, 0.005, 0.005), Vec3::Zero(), Vec3::Zero(), kR, 0, 2500);
  sim.next_id() = 2;
  sim.initialise();
  EXPECT_FALSE(sim.contact_network_recorded());
  EXPECT_THROW((void)sim.contact_network(), std::logic_error);
  sim.record_contacts(true);
  sim.step();
  EXPECT_TRUE(sim.contact_network_recorded());
  sim.record_contacts(false);
  sim.step();
  EXPECT_FALSE(sim.contact_network_recorded());
}

// --- a bed against planes and a mesh, on 1 and 2 ranks, restarted ---------------------------

// A vertical square mesh at x = 0.006 facing the bed, 2 x 2 squares of two triangles each
// (shared edges and vertices), beyond the periodic y range.
std::string write_side_mesh(const fs::path& dir) {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 2; ++i) v.emplace_back(0.006, -0.002 + 0.005 * i, 0.015 * j);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = 3 * j + i, b = a + 1, c = a + 4, d = a + 3;
      t.push_back({a, b, c});
      t.push_back({a, c, d});
    }
  const std::string path = (dir / "side.stl").string();
  if (world_rank() == 0) write_ascii_stl(path, v, t);
  MPI_Barrier(MPI_COMM_WORLD);
  return path;
}

std::string bed_scene(const std::string& mesh) {
  return "domain: {min: [0, 0, 0], max: [0.006, 0.006, 0.03], periodic: [false, true, false]}\n"
         "gravity: [0, 0, -9.81]\n"
         "time: {rayleigh_fraction: 0.15, end: 0.04}\n"
         "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
         "interactions: [{materials: [glass, glass], restitution: 0.5, friction: 0.5}]\n"
         "contact: {normal: hertz, tangential: history}\n"
         "walls:\n"
         "  - {type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}\n"
         "  - {type: plane, name: left, point: [0, 0, 0], normal: [1, 0, 0], material: glass}\n"
         "  - {type: mesh, name: right, file: " +
         mesh +
         ", material: glass}\n"
         "insert:\n"
         "  - type: fill\n"
         "    region: {box: {min: [0.0006, 0, 0.0006], max: [0.0054, 0.006, 0.008]}}\n"
         "    count: 150\n"
         "    material: glass\n"
         "    radius: {distribution: uniform, min: 4e-4, max: 6e-4}\n"
         "fluid: {density: 1.2, viscosity: 1.8e-5, velocity: [0.2, 0.1, 0.5], void_fraction: 1,\n"
         "        drag: schiller_naumann, model: B, forces: [drag, pressure_gradient, viscous]}\n"
         "output: {progress: false, snapshot_interval: 0.01, checkpoint_interval: 0.02,\n"
         "         fields: [mass, force, fluid_force, coordination], contacts: true}\n"
         "parallel: {reproducible: true}\n";
}

// Every particle's force from the network: the sum over its pairs and walls, and the largest
// contact force seen (the scale of the round-off).
struct NetworkForces {
  std::map<std::int64_t, Vec3> on;
  double largest = 0;
};

NetworkForces network_forces(const Snapshot& s) {
  NetworkForces out;
  const auto add = [&](std::int64_t id, const Vec3& f) {
    out.on.try_emplace(id, Vec3::Zero()).first->second += f;
  };
  const auto& id = s.pairs.at("id");
  for (std::size_t k = 0; k < s.pair_count(); ++k) {
    const Vec3 f = row3(s.pairs.at("normal_force"), k) + row3(s.pairs.at("tangential_force"), k);
    add(std::llround(id[2 * k]), f);
    add(std::llround(id[2 * k + 1]), -f);
    out.largest = std::max(out.largest, f.norm());
  }
  for (std::size_t k = 0; k < s.wall_count(); ++k) {
    const Vec3 f = row3(s.walls.at("normal_force"), k) + row3(s.walls.at("tangential_force"), k);
    add(std::llround(s.walls.at("id")[k]), f);
    out.largest = std::max(out.largest, f.norm());
  }
  return out;
}

// The pairs (a, b) and the wall contacts (id, wall, overlap) of a snapshot, sorted, with each
// one's force, for comparisons across runs.
using PairKey = std::pair<std::int64_t, std::int64_t>;
std::map<PairKey, Vec3> pair_forces(const Snapshot& s) {
  std::map<PairKey, Vec3> out;
  for (std::size_t k = 0; k < s.pair_count(); ++k) {
    const PairKey key{std::llround(s.pairs.at("id")[2 * k]),
                      std::llround(s.pairs.at("id")[2 * k + 1])};
    EXPECT_LT(key.first, key.second) << "the lower id first";
    EXPECT_TRUE(out.emplace(key, row3(s.pairs.at("normal_force"), k) +
                                     row3(s.pairs.at("tangential_force"), k))
                    .second)
        << "pair " << key.first << "-" << key.second << " written twice";
  }
  return out;
}
std::multiset<std::tuple<std::int64_t, int, double>> wall_keys(const Snapshot& s) {
  std::multiset<std::tuple<std::int64_t, int, double>> out;
  for (std::size_t k = 0; k < s.wall_count(); ++k)
    out.emplace(std::llround(s.walls.at("id")[k]), static_cast<int>(s.walls.at("wall")[k]),
                s.walls.at("overlap")[k]);
  return out;
}

void expect_same_networks(const fs::path& a, const fs::path& b, double rel) {
  SCOPED_TRACE(a.string() + " vs " + b.string());
  const Snapshot sa = read_snapshot(a), sb = read_snapshot(b);
  const auto pa = pair_forces(sa), pb = pair_forces(sb);
  ASSERT_EQ(pa.size(), pb.size());
  double largest = 0;
  for (const auto& [key, f] : pa) largest = std::max(largest, f.norm());
  for (const auto& [key, f] : pa) {
    const auto it = pb.find(key);
    ASSERT_NE(it, pb.end()) << "pair " << key.first << "-" << key.second << " missing";
    expect_vec_near(it->second, f, rel * largest, "pair force");
  }
  EXPECT_EQ(wall_keys(sa), wall_keys(sb));
}

TEST(ContactNetwork, BedBalancesForcesIsTheSameOnOneAndTwoRanksAndContinuesAfterRestart) {
  const fs::path dir = test_directory();
  const Scene scene = parse_scene(bed_scene(write_side_mesh(dir)), (dir / "bed.yaml").string());
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  std::ostringstream log;
  if (world_rank() == 0) {
    options.output_directory = (dir / "np1").string();
    run_scene(scene, options, MPI_COMM_SELF, log);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  options.output_directory = (dir / "np2").string();
  run_scene(scene, options, MPI_COMM_WORLD, log);
  fs::path checkpoint;
  for (const auto& e : fs::directory_iterator(dir / "np2"))
    if (e.path().filename().string().rfind("checkpoint_", 0) == 0)
      checkpoint = dir / "restart" / e.path().filename();
  ASSERT_FALSE(checkpoint.empty()) << "no checkpoint in np2";
  MPI_Barrier(MPI_COMM_WORLD);
  if (world_rank() == 0) fs::copy(dir / "np2", dir / "restart", fs::copy_options::recursive);
  MPI_Barrier(MPI_COMM_WORLD);
  options.output_directory = (dir / "restart").string();
  options.restart = checkpoint.string();
  run_scene(scene, options, MPI_COMM_WORLD, log);
  if (world_rank() != 0) return;

  const auto np1 = snapshots_in(dir / "np1"), np2 = snapshots_in(dir / "np2");
  const auto again = snapshots_in(dir / "restart");
  ASSERT_EQ(np1.size(), 5u);  // t = 0, 0.01, ..., 0.04
  ASSERT_EQ(np2.size(), np1.size());
  ASSERT_EQ(again.size(), np1.size());
  const Vec3 g(0, 0, -9.81);
  long pairs_seen = 0, mesh_seen = 0, plane_seen = 0;
  for (const fs::path& file : np2) {
    SCOPED_TRACE(file.string());
    const Snapshot s = read_snapshot(file);
    ASSERT_TRUE(s.has_network);
    const NetworkForces net = network_forces(s);
    (void)pair_forces(s);  // no pair twice, the lower id first
    // Newton's second law as written: contacts + weight + fluid = the particle's force.
    const auto& mass = s.particles.at("mass");
    const auto& force = s.particles.at("force");
    const auto& fluid = s.particles.at("fluid_force");
    double coordination = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const std::int64_t id = std::llround(s.particles.at("id")[i]);
      const auto it = net.on.find(id);
      const Vec3 contacts = it == net.on.end() ? Vec3::Zero() : it->second;
      // Round-off: ~10 contact forces summed in two orders, each split into parts within
      // an ulp: 1e-12 of the largest contact force is hundreds of ulps; the weight and the
      // fluid force add their own ulps.
      const double tol =
          1e-12 * net.largest + 1e-13 * mass[i] * g.norm() + 1e-13 * row3(fluid, i).norm();
      expect_vec_near(row3(force, i), contacts + mass[i] * g + row3(fluid, i), tol,
                      "balance of particle " + std::to_string(id));
      coordination += s.particles.at("coordination")[i];
    }
    EXPECT_EQ(coordination, 2.0 * s.pair_count() + s.wall_count());
    pairs_seen += static_cast<long>(s.pair_count());
    for (std::size_t k = 0; k < s.wall_count(); ++k)
      (s.walls.at("wall")[k] == 2 ? mesh_seen : plane_seen) += 1;
  }
  // The networks checked are not trivial: the bed has settled on the floor against both
  // sides.
  EXPECT_GT(pairs_seen, 50);
  EXPECT_GT(plane_seen, 20);
  EXPECT_GT(mesh_seen, 0);
  // 1 and 2 ranks: the same state (parallel.reproducible), so the same contacts and forces.
  for (std::size_t k = 0; k < np1.size(); ++k) expect_same_networks(np1[k], np2[k], 1e-13);
  // The restart (from t = 0.02 s) writes the uninterrupted run's networks, bit for bit.
  for (std::size_t k = 3; k < np1.size(); ++k) expect_same_networks(np2[k], again[k], 0);
  // Its index lists the network of every snapshot, the earlier ones read back from their
  // files, each with its own count of lines (a group without contacts has no grid).
  const std::string xml = slurp(dir / "restart" / "particles.xdmf");
  EXPECT_EQ(count(xml, "CollectionType=\"Spatial\""), np1.size());
  std::vector<long> lines, expected;
  const std::string polyline = "TopologyType=\"Polyline\" NumberOfElements=\"";
  for (std::size_t at = xml.find(polyline); at != std::string::npos;
       at = xml.find(polyline, at + 1))
    lines.push_back(std::stol(xml.substr(at + polyline.size())));
  for (const fs::path& file : again) {
    const Snapshot s = read_snapshot(file);
    for (const std::size_t n : {s.pair_count(), s.wall_count()})
      if (n > 0) expected.push_back(static_cast<long>(n));
  }
  EXPECT_EQ(lines, expected);
}

}  // namespace
}  // namespace grainflow
