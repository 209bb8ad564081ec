// Snapshot fields on request (output.fields), the snapshot window (output.start / stop) and
// the CSV spin columns, on 2 ranks (CTest runs it with mpirun -np 2).
//
// References:
//  - Two spheres pressed together at a known overlap delta by a Hooke spring of given k_n, at
//    rest: force = k_n delta along the line of centres, coordination 1, overlap_max = delta/r
//    (closed form). A sphere on a plane at overlap delta_w spinning fast: normal force
//    k_n delta_w, tangential force at the Coulomb limit mu k_n delta_w opposing the slip,
//    torque (r - delta_w) mu k_n delta_w (the wall contact's lever arm is the centre's
//    distance to the plane). Tolerance 1e-9 relative: the overlaps come from coordinates of
//    1e-2 m, rounded at 2e-18 m, against overlaps of 1e-5 m.
//  - One sphere in a uniform one-way upward flow under gravity: fluid_force = Schiller-Naumann
//    drag 3 pi mu d (u - v)(1 + 0.15 Re^0.687), Re = rho d |u - v| / mu, at the snapshot's v,
//    plus the hydrostatic pressure gradient's force -V grad p = -rho_f V g (Archimedes) and
//    the viscous force V div(tau) = 0 of a uniform flow;
//    force = fluid_force + m g.
//  - The same scene on 1 and 2 ranks with parallel.reproducible, and a restart from its
//    checkpoint: every field equal bit for bit (docs/parallel.md, "Reproducible results").
//  - The window: snapshots exactly at steps start/dt ... stop/dt, counted and timed.
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
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "dem/engine/run.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/snapshot_writer.hpp"
#include "dem/scene/scene_parser.hpp"

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
      fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "output_fields_mpi_test" / info->name();
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

SnapshotFieldSet all_fields() { return (SnapshotFieldSet{1} << snapshot_fields.size()) - 1; }

const char* kAllFields =
    "[velocity, angular_velocity, radius, diameter, mass, material, force, torque, "
    "coordination, fluid_force, overlap_max]";

// One snapshot file read serially: attributes and every dataset it holds, each as doubles
// (ids and counts are exact in a double at these sizes), rows in file order.
struct SnapshotFile {
  double time = 0;
  long step = 0;
  std::map<std::string, std::vector<double>> data;        // flattened (N x components)
  std::map<std::string, std::vector<std::int64_t>> ints;  // id, material, coordination
  std::size_t size() const { return ints.at("id").size(); }
  std::size_t row_of(std::int64_t id) const {
    const auto& ids = ints.at("id");
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (ids[i] == id) return i;
    ADD_FAILURE() << "no particle " << id;
    return 0;
  }
  Vec3 vec(const std::string& name, std::int64_t id) const {
    const std::size_t i = row_of(id);
    const auto& a = data.at(name);
    return {a[3 * i], a[3 * i + 1], a[3 * i + 2]};
  }
  double scalar(const std::string& name, std::int64_t id) const {
    return data.at(name)[row_of(id)];
  }
  std::int64_t integer(const std::string& name, std::int64_t id) const {
    return ints.at(name)[row_of(id)];
  }
  // The rows of `name` sorted by id, as bytes: for exact comparisons across files.
  std::vector<double> by_id(const std::string& name, int components) const {
    std::map<std::int64_t, std::size_t> order;
    for (std::size_t i = 0; i < size(); ++i) order[ints.at("id")[i]] = i;
    std::vector<double> out;
    for (const auto& [id, i] : order)
      for (int c = 0; c < components; ++c)
        out.push_back(ints.count(name) ? static_cast<double>(ints.at(name)[i])
                                       : data.at(name)[components * i + c]);
    return out;
  }
};

SnapshotFile read_file(const fs::path& path) {
  SnapshotFile s;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(file, 0) << path;
  if (file < 0) return s;
  const auto attribute = [&](const char* name, hid_t type, void* out) {
    const hid_t a = H5Aopen(file, name, H5P_DEFAULT);
    EXPECT_GE(H5Aread(a, type, out), 0) << name;
    H5Aclose(a);
  };
  std::int64_t step = 0;
  attribute("time", H5T_NATIVE_DOUBLE, &s.time);
  attribute("step", H5T_NATIVE_INT64, &step);
  s.step = static_cast<long>(step);
  for (const SnapshotField& f : snapshot_fields) {
    if (H5Lexists(file, f.name, H5P_DEFAULT) <= 0) continue;
    const hid_t d = H5Dopen2(file, f.name, H5P_DEFAULT);
    const hid_t space = H5Dget_space(d);
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    H5Sclose(space);
    if (f.type == SnapshotField::Type::Float64) {
      std::vector<double>& out = s.data[f.name];
      out.resize(static_cast<std::size_t>(n));
      if (n > 0) {
        EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0);
      }
    } else {
      std::vector<std::int64_t>& out = s.ints[f.name];
      out.resize(static_cast<std::size_t>(n));
      if (n > 0) {
        EXPECT_GE(H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0);
      }
    }
    H5Dclose(d);
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

void expect_vec_near(const Vec3& got, const Vec3& want, double tol, const std::string& what) {
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want[a], tol) << what << " component " << a;
}

// --- closed forms of a Hooke contact ------------------------------------------------------

constexpr double kKn = 1000;      // N/m, contact.hooke.stiffness.normal
constexpr double kMu = 0.5;       // friction
constexpr double kR = 1e-3;       // m
constexpr double kDelta = 2e-5;   // pair overlap [m]
constexpr double kDeltaW = 1e-5;  // wall overlap [m]

const std::string kHookeScene =
    "domain: {min: [-0.02, -0.005, -0.005], max: [0.02, 0.005, 0.005]}\n"
    "time: {step: 1e-5, end: 1e-3}\n"
    "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
    "interactions: [{materials: [glass, glass], restitution: 0.5, friction: 0.5}]\n"
    "contact: {normal: hooke, tangential: history, hooke: {stiffness: {normal: 1000}}}\n"
    "walls: [{type: plane, name: floor, point: [0, 0, -0.005], normal: [0, 0, 1], "
    "material: glass}]\n"
    "output: {progress: false}\n";

TEST(OutputFields, HookeContactsGiveClosedFormForceTorqueCoordinationOverlap) {
  const fs::path dir = test_directory();
  const Scene scene = parse_scene(kHookeScene, "hooke.yaml");
  // The domain is 4x longer in x: 2 ranks cut it at x = 0, between the pair's two spheres
  // (a contact through a ghost on each side).
  Simulation sim(scene, /*insert=*/false, MPI_COMM_WORLD);
  Particles& p = sim.particles();
  const double rho = 2500;
  const double half = kR - 0.5 * kDelta;
  p.add(1, Vec3(-half, 0, 0.002), Vec3::Zero(), Vec3::Zero(), kR, 0, rho);
  p.add(2, Vec3(half, 0, 0.002), Vec3::Zero(), Vec3::Zero(), kR, 0, rho);
  const double z3 = -0.005 + kR - kDeltaW;  // on the floor, spinning about +y at 1000 rad/s
  p.add(3, Vec3(0.01, 0, z3), Vec3::Zero(), Vec3(0, 1000, 0), kR, 0, rho);
  p.add(4, Vec3(-0.01, 0, 0), Vec3::Zero(), Vec3::Zero(), kR, 0, rho);  // touches nothing
  sim.next_id() = 5;
  sim.initialise();
  SnapshotWriter writer(MPI_COMM_WORLD, dir.string(), "particles", all_fields());
  writer.write(sim.particles(), sim.time(), 0, sim.snapshot_extras(writer.fields()));
  if (world_rank() == 0) {
    const SnapshotFile s = read_file(dir / "particles_000000.h5");
    ASSERT_EQ(s.size(), 4u);
    // The overlaps as the coordinates give them (within 1e-18 m of kDelta, kDeltaW).
    const double delta = (kR + kR) - (half - (-half));
    const double delta_w = kR - (z3 - (-0.005));
    const double f = kKn * delta, tol = 1e-9 * f;
    // Sphere 1 is pushed to -x, sphere 2 to +x; no tangential force at rest.
    expect_vec_near(s.vec("force", 1), Vec3(-f, 0, 0), tol, "force on 1");
    expect_vec_near(s.vec("force", 2), Vec3(f, 0, 0), tol, "force on 2");
    expect_vec_near(s.vec("torque", 1), Vec3::Zero(), 1e-15, "torque on 1");
    EXPECT_EQ(s.integer("coordination", 1), 1);
    EXPECT_EQ(s.integer("coordination", 2), 1);
    EXPECT_NEAR(s.scalar("overlap_max", 1), delta / kR, 1e-9 * delta / kR);
    EXPECT_NEAR(s.scalar("overlap_max", 2), delta / kR, 1e-9 * delta / kR);
    // The floor sphere slides: the contact point moves at w x (-(r - delta_w) z) = -x, so
    // friction pushes +x with mu F_n, and its torque (-(r - delta_w) z) x F_t is along -y.
    const double fn = kKn * delta_w, ft = kMu * fn, arm = kR - delta_w;
    expect_vec_near(s.vec("force", 3), Vec3(ft, 0, fn), 1e-9 * fn, "force on 3");
    expect_vec_near(s.vec("torque", 3), Vec3(0, -arm * ft, 0), 1e-9 * arm * ft, "torque on 3");
    EXPECT_EQ(s.integer("coordination", 3), 1);
    EXPECT_NEAR(s.scalar("overlap_max", 3), delta_w / kR, 1e-9 * delta_w / kR);
    // Nothing touches sphere 4 and there is no gravity; no fluid anywhere.
    EXPECT_EQ(s.vec("force", 4), Vec3::Zero());
    EXPECT_EQ(s.integer("coordination", 4), 0);
    EXPECT_EQ(s.scalar("overlap_max", 4), 0.0);
    for (std::int64_t id = 1; id <= 4; ++id) EXPECT_EQ(s.vec("fluid_force", id), Vec3::Zero());
    // Every field is an Attribute of the XDMF index, with its units in the file.
    const std::string xml = slurp(dir / "particles.xdmf");
    for (const char* name :
         {"force", "torque", "coordination", "fluid_force", "overlap_max", "velocity", "material"})
      EXPECT_EQ(count(xml, std::string("<Attribute Name=\"") + name + "\""), 1u) << name;
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// --- drag in a uniform one-way flow, spin from the CSV file --------------------------------

TEST(OutputFields, FluidForceIsSchillerNaumannDragAndCsvSpinReachesTheSnapshot) {
  const fs::path dir = test_directory();
  const fs::path csv = dir / "bead.csv";
  if (world_rank() == 0)
    std::ofstream(csv) << "x,y,z,radius,wx,wy,wz\n0.005,0.005,0.005,5e-4,1.5,-2.25,3\n";
  MPI_Barrier(MPI_COMM_WORLD);
  const double mu = 1e-3, rho_f = 1000, d = 1e-3, rho_p = 2500;
  const Vec3 u(0, 0, 0.01), g(0, 0, -9.81);
  const double volume = std::numbers::pi * d * d * d / 6;
  const Scene scene = parse_scene(
      "domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.01]}\n"
      "gravity: [0, 0, -9.81]\n"
      "time: {step: 1e-5, end: 2e-4}\n"
      "materials: [{name: glass, youngs_modulus: 5e4, poisson_ratio: 0.3, density: 2500}]\n"
      "interactions: [{materials: [glass, glass], restitution: 0.5, friction: 0.5}]\n"
      "contact: {normal: hertz}\n"
      "insert: [{type: csv, file: " +
          csv.string() +
          ", material: glass}]\n"
          "fluid: {density: 1000, viscosity: 1e-3, velocity: [0, 0, 0.01], void_fraction: 1,\n"
          "        drag: schiller_naumann, model: B, forces: [drag, pressure_gradient, viscous]}\n"
          "output: {progress: false, snapshot_interval: 1e-5, fields: " +
          kAllFields + "}\n",
      (dir / "drag.yaml").string());
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  options.output_directory = (dir / "out").string();
  std::ostringstream log;
  run_scene(scene, options, MPI_COMM_WORLD, log);
  if (world_rank() == 0) {
    const auto files = snapshots_in(dir / "out");
    ASSERT_EQ(files.size(), 21u);  // steps 0 ... 20
    for (std::size_t k = 0; k < files.size(); ++k) {
      SCOPED_TRACE(files[k].filename().string());
      const SnapshotFile s = read_file(files[k]);
      ASSERT_EQ(s.size(), 1u);
      const Vec3 v = s.vec("velocity", 1);
      const Vec3 slip = u - v;
      const double re = rho_f * d * slip.norm() / mu;
      const Vec3 drag = 3 * std::numbers::pi * mu * d * (1 + 0.15 * std::pow(re, 0.687)) * slip;
      const Vec3 buoyancy = -rho_f * volume * g;
      // Step 0: the drag coefficient is of this very velocity (rest): round-off only. Later
      // the half kick's coefficient is of the velocity half a step earlier, which differs by
      // h |a| = 5e-6 s x 5.9 m/s^2 = 3e-5 m/s, 3e-3 of the slip: with dK/K = 0.4 dU/U for
      // Schiller-Naumann at Re = 10, 1.2e-3 of the drag; 2.5e-3 leaves a margin.
      const double tol = (k == 0 ? 1e-12 : 2.5e-3) * drag.norm() + 1e-12 * buoyancy.norm();
      expect_vec_near(s.vec("fluid_force", 1), drag + buoyancy, tol, "fluid_force");
      // No contact: the total force is the fluid's and the weight.
      const double m = rho_p * volume;
      expect_vec_near(s.vec("force", 1), s.vec("fluid_force", 1) + m * g, 1e-12 * m * g.norm(),
                      "force");
      EXPECT_EQ(s.integer("coordination", 1), 0);
      // The CSV spin, untouched: no torque acts (no contact, no rotational drag).
      EXPECT_EQ(s.vec("angular_velocity", 1), Vec3(1.5, -2.25, 3));
      EXPECT_EQ(s.vec("torque", 1), Vec3::Zero());
    }
    EXPECT_EQ(read_file(files[0]).vec("velocity", 1), Vec3::Zero());
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// --- a spinning sphere set down on a frictional plane --------------------------------------

// A solid sphere spinning at w0 with no velocity, on a plane with Coulomb friction: the
// friction keeps the angular momentum about the contact point, so it ends rolling at
// v = I w0 r / (I + m r^2) = (2/7) r w0 (I = 2/5 m r^2). Resting then, its net force is zero
// and its overlap the Hertz static one, delta = (3 m g / (4 Y* sqrt(r)))^(2/3) with
// 1/Y* = 2 (1 - nu^2) / Y (sphere and plane of one material). Tolerances: 1 % on the speeds
// (the lever arm is r - delta, delta/r = 1e-3, and the tangential spring still rings a little),
// 2 % on the overlap (the normal oscillation of the set-down has decayed to well below that),
// net force below 1 % of the weight.
TEST(OutputFields, SpinningSphereOnAFrictionalPlaneEndsRollingAtTwoSevenths) {
  const fs::path dir = test_directory();
  const fs::path csv = dir / "bead.csv";
  const double r = 1e-3, w0 = 100, rho = 2500, y = 5e6, nu = 0.3, g = 9.81;
  if (world_rank() == 0)
    std::ofstream(csv) << "x,y,z,radius,wx,wy,wz\n0.005,0.005,0.001,1e-3,0,100,0\n";
  MPI_Barrier(MPI_COMM_WORLD);
  const Scene scene = parse_scene(
      "domain: {min: [0, 0, 0], max: [0.02, 0.01, 0.01]}\n"
      "gravity: [0, 0, -9.81]\n"
      "time: {rayleigh_fraction: 0.15, end: 0.03}\n"
      "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
      "interactions: [{materials: [glass, glass], restitution: 0.5, friction: 0.5}]\n"
      "contact: {normal: hertz, tangential: history}\n"
      "walls: [{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], "
      "material: glass}]\n"
      "insert: [{type: csv, file: " +
          csv.string() +
          ", material: glass}]\n"
          "output: {progress: false, fields: [velocity, angular_velocity, force, coordination, "
          "overlap_max]}\n",
      (dir / "rolling.yaml").string());
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  options.output_directory = (dir / "out").string();
  std::ostringstream log;
  run_scene(scene, options, MPI_COMM_WORLD, log);
  if (world_rank() == 0) {
    const auto files = snapshots_in(dir / "out");
    ASSERT_FALSE(files.empty());
    EXPECT_EQ(read_file(files.front()).vec("angular_velocity", 1), Vec3(0, w0, 0));
    const SnapshotFile end = read_file(files.back());
    const double v_roll = 2.0 / 7.0 * r * w0;
    const Vec3 v = end.vec("velocity", 1), w = end.vec("angular_velocity", 1);
    EXPECT_NEAR(v[0], v_roll, 0.01 * v_roll);
    EXPECT_NEAR(w[1] * r, v_roll, 0.01 * v_roll);
    const double m = rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
    EXPECT_LT(end.vec("force", 1).norm(), 0.01 * m * g);
    EXPECT_EQ(end.integer("coordination", 1), 1);
    const double y_star = y / (2 * (1 - nu * nu));
    const double delta = std::pow(3 * m * g / (4 * y_star * std::sqrt(r)), 2.0 / 3.0);
    EXPECT_NEAR(end.scalar("overlap_max", 1), delta / r, 0.02 * delta / r);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// --- 1 rank, 2 ranks, restart ---------------------------------------------------------------

const std::string kBedScene =
    "domain: {min: [0, 0, 0], max: [0.012, 0.012, 0.03], periodic: [true, true, false]}\n"
    "gravity: [0, 0, -9.81]\n"
    "time: {rayleigh_fraction: 0.15, end: 0.03}\n"
    "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
    "interactions: [{materials: [glass, glass], restitution: 0.5, friction: 0.5}]\n"
    "contact: {normal: hertz, tangential: history}\n"
    "walls: [{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}]\n"
    "insert:\n"
    "  - type: fill\n"
    "    region: {box: {min: [0, 0, 0.0006], max: [0.012, 0.012, 0.004]}}\n"
    "    count: 150\n"
    "    material: glass\n"
    "    radius: {distribution: uniform, min: 4e-4, max: 6e-4}\n"
    "fluid: {density: 1000, viscosity: 1e-3, velocity: [0, 0, 0.02], void_fraction: 1,\n"
    "        drag: schiller_naumann, model: B, forces: [drag, pressure_gradient, viscous]}\n"
    "output: {progress: false, snapshot_interval: 0.0075, checkpoint_interval: 0.015,\n"
    "         fields: " +
    std::string(kAllFields) +
    "}\n"
    "parallel: {reproducible: true}\n";

void expect_same_fields(const fs::path& a, const fs::path& b) {
  SCOPED_TRACE(a.string() + " vs " + b.string());
  const SnapshotFile sa = read_file(a), sb = read_file(b);
  EXPECT_EQ(sa.step, sb.step);
  EXPECT_EQ(sa.time, sb.time);
  ASSERT_EQ(sa.size(), sb.size());
  for (const SnapshotField& f : snapshot_fields) {
    // Both files hold the same datasets; a field the scene does not write (temperature
    // without heat) is in neither.
    const bool in_a = sa.data.count(f.name) + sa.ints.count(f.name) > 0;
    EXPECT_EQ(in_a, sb.data.count(f.name) + sb.ints.count(f.name) > 0) << f.name;
    if (!in_a) continue;
    const auto va = sa.by_id(f.name, f.components), vb = sb.by_id(f.name, f.components);
    EXPECT_TRUE(va == vb) << f.name << " differs";
  }
}

TEST(OutputFields, SameOnOneAndTwoRanksAndAfterARestart) {
  const fs::path dir = test_directory();
  const Scene scene = parse_scene(kBedScene, (dir / "bed.yaml").string());
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  std::ostringstream log;
  // One rank (rank 0 alone), then both.
  if (world_rank() == 0) {
    options.output_directory = (dir / "np1").string();
    run_scene(scene, options, MPI_COMM_SELF, log);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  options.output_directory = (dir / "np2").string();
  const RunSummary whole = run_scene(scene, options, MPI_COMM_WORLD, log);
  // The restart continues a copy of the 2-rank output from its checkpoint at t = 0.015 s.
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
  const RunSummary restarted = run_scene(scene, options, MPI_COMM_WORLD, log);
  EXPECT_EQ(restarted.steps, whole.steps);
  if (world_rank() == 0) {
    const auto np1 = snapshots_in(dir / "np1"), np2 = snapshots_in(dir / "np2");
    const auto again = snapshots_in(dir / "restart");
    ASSERT_EQ(np1.size(), 5u);  // t = 0, 0.0075, ..., 0.03
    ASSERT_EQ(np2.size(), np1.size());
    ASSERT_EQ(again.size(), np1.size());
    for (std::size_t k = 0; k < np1.size(); ++k) expect_same_fields(np1[k], np2[k]);
    // The snapshots the restart wrote (after the checkpoint) equal the uninterrupted run's.
    for (std::size_t k = 3; k < np1.size(); ++k) expect_same_fields(np2[k], again[k]);
    // The fields compared are not trivial: by the end the lower beads lie on the floor and on
    // each other, and buoyancy and the upward flow push the beads up.
    const SnapshotFile last = read_file(np2.back());
    long touching = 0;
    double largest = 0, lift = 0;
    for (std::size_t i = 0; i < last.size(); ++i) {
      touching += last.ints.at("coordination")[i];
      largest = std::max(largest, last.data.at("overlap_max")[i]);
      lift += last.data.at("fluid_force")[3 * i + 2];
    }
    EXPECT_GT(touching, 10);
    EXPECT_GT(largest, 0.0);
    EXPECT_GT(lift, 0.0);
    // The restart's index lists the new fields for the earlier snapshots too (read back
    // from their files) and for its own.
    const std::string xml = slurp(dir / "restart" / "particles.xdmf");
    EXPECT_EQ(count(xml, "<Attribute Name=\"fluid_force\""), np1.size());
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// --- the snapshot window --------------------------------------------------------------------

TEST(OutputFields, WindowWritesEveryStepBetweenStartAndStopOnly) {
  const fs::path dir = test_directory();
  const fs::path csv = dir / "bead.csv";
  if (world_rank() == 0) std::ofstream(csv) << "x,y,z,radius\n0.005,0.005,0.008,1e-3\n";
  MPI_Barrier(MPI_COMM_WORLD);
  const Scene scene = parse_scene(
      "domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.01]}\n"
      "gravity: [0, 0, -9.81]\n"
      "time: {step: 1e-4, end: 0.01}\n"
      "materials: [{name: glass, youngs_modulus: 5e4, poisson_ratio: 0.3, density: 2500}]\n"
      "interactions: [{materials: [glass, glass], restitution: 0.5, friction: 0.5}]\n"
      "contact: {normal: hertz}\n"
      "insert: [{type: csv, file: " +
          csv.string() +
          ", material: glass}]\n"
          "output: {progress: false, snapshot_interval: 1e-4, start: 0.0035, stop: 0.0045}\n",
      (dir / "window.yaml").string());
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  options.output_directory = (dir / "out").string();
  std::ostringstream log;
  const RunSummary sum = run_scene(scene, options, MPI_COMM_WORLD, log);
  if (world_rank() == 0) {
    const auto files = snapshots_in(dir / "out");
    ASSERT_EQ(files.size(), 11u);  // steps 35 ... 45, both ends included
    // The summary counts what is on disk: the files and their bytes.
    EXPECT_EQ(sum.snapshot_files, 11);
    double bytes = 0;
    for (const auto& f : files) bytes += static_cast<double>(fs::file_size(f));
    EXPECT_EQ(sum.snapshot_bytes, bytes);
    EXPECT_GT(sum.snapshot_seconds, 0);
    EXPECT_GT(sum.startup_seconds, 0);
    EXPECT_NE(log.str().find("; 11 snapshot(s), "), std::string::npos) << log.str();
    // No snapshot before the window: the start-up has none to include.
    EXPECT_EQ(log.str().find("first snapshot"), std::string::npos) << log.str();
    for (std::size_t k = 0; k < files.size(); ++k) {
      const SnapshotFile s = read_file(files[k]);
      EXPECT_EQ(s.step, 35 + static_cast<long>(k));
      EXPECT_NEAR(s.time, (35 + static_cast<double>(k)) * 1e-4, 1e-15);
      // The default fields only.
      EXPECT_EQ(s.data.count("force"), 0u);
      EXPECT_EQ(s.data.count("velocity"), 1u);
    }
    EXPECT_EQ(count(slurp(dir / "out" / "particles.xdmf"), "<Time Value="), 11u);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

}  // namespace
}  // namespace grainflow
