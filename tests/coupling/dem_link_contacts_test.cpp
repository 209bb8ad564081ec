// grainFoam's particle snapshots (DemLink::write_snapshot) honour the scene's output.contacts
// as `grain` does: the contact network of the last DEM sub-step, whose forces are those in
// the snapshot's force field. Without OpenFOAM: the fluid samples are set by hand.
//
// Reference: Newton's second law as the snapshot states it, for every particle: the sum of
// its pair forces (+ on the lower id, - on the other) and wall forces, its weight and the
// coupling's fluid_force equal its force field, to round-off, in the middle of three impacts
// (damped, with friction); and the network holds exactly the contacts set up.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "coupling/dem_link.hpp"
#include "dem/core/types.hpp"
#include "dem/io/output_directory.hpp"

namespace grainflow::coupling {
namespace {

namespace fs = std::filesystem;

std::vector<double> read(hid_t file, const std::string& path) {
  std::vector<double> out;
  if (H5Lexists(file, path.substr(0, path.find('/', 1)).c_str(), H5P_DEFAULT) <= 0) return out;
  const hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(d);
  out.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  H5Sclose(space);
  if (!out.empty()) H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
  H5Dclose(d);
  return out;
}

Vec3 row(const std::vector<double>& a, std::size_t k) {
  return {a[3 * k], a[3 * k + 1], a[3 * k + 2]};
}

TEST(DemLinkContacts, SnapshotsHoldTheNetworkOfTheLastSubStep) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "dem_link_contacts";
  fs::remove_all(dir);
  prepare_output_directory(dir.string());
  // Beads 1 and 2 about to collide (an oblique impact), bead 3 about to hit the floor and
  // bead 4 about to hit bead 3: all touch within 10 sub-steps.
  const double r = 5e-4, gap = 1e-6;
  std::ofstream csv(dir / "beads.csv");
  csv.precision(17);
  csv << "x,y,z,radius,vx,vy,vz\n"
      << 0.01 - r - gap / 2 << ",0.01,0.02," << r << ",0.05,0.01,0\n"
      << 0.01 + r + gap / 2 << ",0.01,0.02," << r << ",-0.05,0,0\n"
      << "0.005,0.005," << r + gap << "," << r << ",0,0,-0.05\n"
      << "0.005,0.005," << 3 * r + 2 * gap << "," << r << ",0.01,0,-0.1\n";
  csv.close();
  const std::string scene = (dir / "scene.yaml").string();
  std::ofstream(scene) << "domain: {min: [0, 0, 0], max: [0.02, 0.02, 0.04]}\n"
                          "gravity: [0, 0, -9.81]\n"
                          "time: {step: 1.0e-6, end: 1.0}\n"
                          "materials: [{name: glass, youngs_modulus: 1.0e7, poisson_ratio: 0.3, "
                          "density: 2500}]\n"
                          "interaction_defaults: {restitution: 0.5, friction: 0.3}\n"
                          "contact: {normal: hertz, tangential: history}\n"
                          "walls: [{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], "
                          "material: glass}]\n"
                          "insert: [{type: csv, file: beads.csv, material: glass}]\n"
                          "fluid: {density: 1.2, viscosity: 1.8e-5, drag: di_felice, model: A, "
                          "pressure: {hydrostatic: false}, forces: [drag, pressure_gradient, "
                          "viscous, buoyancy]}\n"
                          "output: {fields: [mass, force, fluid_force], contacts: true}\n";
  DemLink dem(scene, 1.2, 1.8e-5, MPI_COMM_WORLD);
  dem.initialise();
  const std::string out = (dir / "particles").string();
  dem.write_snapshot(out, 0);
  const auto late = [](const std::array<double, 3>&) { return FluidAtParticle{}; };
  dem.begin_fluid();
  for (std::size_t i = 0; i < dem.particles(false).local; ++i) {
    FluidAtParticle f;
    f.velocity = {0.1, 0, 0.5};
    f.void_fraction = 0.6;
    f.pressure_gradient = {0, 0, -5};
    dem.add_fluid(f);
  }
  dem.end_fluid(late);
  dem.advance(60, (dir / "diagnostics").string());  // mid-impact for all three contacts
  dem.write_snapshot(out, 1);

  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) return;
  for (const char* name : {"particles_000000.h5", "particles_000001.h5"}) {
    SCOPED_TRACE(name);
    const hid_t file = H5Fopen((fs::path(out) / name).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    const auto id = read(file, "/id"), mass = read(file, "/mass"), force = read(file, "/force"),
               fluid = read(file, "/fluid_force");
    const auto pair_id = read(file, "/contacts/id"), fn = read(file, "/contacts/normal_force"),
               ft = read(file, "/contacts/tangential_force");
    const auto wall_id = read(file, "/wall_contacts/id"),
               wn = read(file, "/wall_contacts/normal_force"),
               wt = read(file, "/wall_contacts/tangential_force");
    H5Fclose(file);
    ASSERT_EQ(id.size(), 4u);
    if (std::string(name) == "particles_000001.h5") {
      ASSERT_EQ(pair_id.size(), 4u);  // two pairs, in the neighbour list's order
      EXPECT_EQ(std::min(pair_id[0], pair_id[2]), 1);
      EXPECT_EQ(std::max(pair_id[0], pair_id[2]), 3);
      EXPECT_EQ(pair_id[1] - pair_id[0], 1);  // 1-2 and 3-4
      EXPECT_EQ(pair_id[3] - pair_id[2], 1);
      ASSERT_EQ(wall_id, (std::vector<double>{3}));
    }
    std::map<long, Vec3> net;
    double largest = 0;
    for (std::size_t k = 0; 2 * k < pair_id.size(); ++k) {
      const Vec3 f = row(fn, k) + row(ft, k);
      net.try_emplace(std::lround(pair_id[2 * k]), Vec3::Zero()).first->second += f;
      net.try_emplace(std::lround(pair_id[2 * k + 1]), Vec3::Zero()).first->second -= f;
      largest = std::max(largest, f.norm());
    }
    for (std::size_t k = 0; k < wall_id.size(); ++k) {
      const Vec3 f = row(wn, k) + row(wt, k);
      net.try_emplace(std::lround(wall_id[k]), Vec3::Zero()).first->second += f;
      largest = std::max(largest, f.norm());
    }
    const Vec3 g(0, 0, -9.81);
    for (std::size_t i = 0; i < id.size(); ++i) {
      const auto it = net.find(std::lround(id[i]));
      const Vec3 contacts = it == net.end() ? Vec3::Zero() : it->second;
      const Vec3 want = contacts + mass[i] * g + row(fluid, i);
      // Round-off of a few contact forces summed in two orders, and of the weight.
      const double tol = 1e-12 * largest + 1e-13 * mass[i] * g.norm();
      for (int a = 0; a < 3; ++a)
        EXPECT_NEAR(row(force, i)[a], want[a], tol) << "particle " << id[i] << " component " << a;
    }
  }
}

}  // namespace
}  // namespace grainflow::coupling
