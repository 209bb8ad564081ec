// Stream insertion through a planar face, and insertion from a grainflow snapshot.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "dem/engine/restored_state.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/insert/insertion.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/snapshot_writer.hpp"
#include "dem/scene/scene_parser.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kRho = 2500;

Scene falling_stream_scene() {
  Scene s = test::one_material_scene(5e6, 0.3, kRho, 0.3);
  s.domain.lo = Vec3(-0.03, -0.03, -0.6);
  s.domain.hi = Vec3(0.03, 0.03, 0.05);
  s.gravity = Vec3(0, 0, -9.81);
  s.time.step = 2e-5;
  return s;
}

Insertion stream(double mass_rate) {
  Insertion ins;
  ins.kind = Insertion::Kind::stream;
  ins.face.kind = InsertionFace::Kind::disc;
  ins.face.centre = Vec3(0, 0, 0.03);
  ins.face.normal = Vec3::UnitZ();
  ins.face.radius = 0.02;
  ins.mass_rate = mass_rate;
  ins.stop = 0.2;
  ins.radius.kind = SizeDistribution::Kind::uniform;
  ins.radius.min = 0.0008;
  ins.radius.max = 0.0012;
  ins.velocity = Vec3(0, 0, -0.5);
  ins.seed = 11;
  ins.source = "<test>";
  return ins;
}

// 0.05 kg/s for 0.2 s = 10 g, about 1400 particles, into a free fall (the particles
// leave through the bottom later). Reference: mass_rate * duration; the delivered mass
// may differ by half a particle (0.01 %) by construction, 1 % is the bound.
TEST(StreamInsertion, DeliversTheRequestedMass) {
  Scene s = falling_stream_scene();
  s.insertions.push_back(stream(0.05));
  Simulation sim(s);
  sim.advance_to(0.25);
  const double delivered = sim.streams().mass_inserted(0);
  double present = 0;
  for (double m : sim.particles().mass) present += m;
  std::printf("[ measured ] stream: delivered %.6f kg of 0.010000 kg (%+.3f %%) in %ld "
              "particles, lag %ld\n",
              delivered, 100 * (delivered / 0.01 - 1), sim.streams().count_inserted(0),
              sim.streams().lag(0));
  EXPECT_NEAR(delivered, 0.01, 0.01 * 0.01);
  EXPECT_NEAR(present, delivered, 1e-12);  // all still in the domain: none lost
  // No two particles overlap (they never touched: the stream is sparse and falling).
  const Particles& p = sim.particles();
  double worst = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      worst = std::max(worst, p.radius[i] + p.radius[j] - (p.x[i] - p.x[j]).norm());
  EXPECT_LE(worst, 0.0);
}

// A number rate: the count due at t is round(rate t).
TEST(StreamInsertion, NumberRateAndSizeDistribution) {
  Scene s = falling_stream_scene();
  Insertion ins = stream(1);
  ins.mass_rate.reset();
  ins.count_rate = 5000;
  s.insertions.push_back(ins);
  Simulation sim(s);
  sim.advance_to(0.1);
  const Particles& p = sim.particles();
  EXPECT_EQ(sim.streams().count_inserted(0), 500);
  EXPECT_EQ(static_cast<long>(p.size()), 500);
  double mean = 0;
  for (double r : p.radius) mean += r / static_cast<double>(p.size());
  // Uniform on [0.8, 1.2] mm: mean 1.0 mm, standard error 0.115/sqrt(500) mm = 0.005 mm.
  EXPECT_NEAR(mean, 0.001, 2e-5);
}

// Particles are not placed onto particles already at the face: a stream into a
// closed cup fills it and then waits (lag > 0) instead of overlapping.
TEST(StreamInsertion, NeverOverlapsExistingParticles) {
  Scene s = falling_stream_scene();
  s.walls.push_back(test::plane(Vec3(0, 0, 0.02), Vec3::UnitZ()));  // floor just below the face
  Insertion ins = stream(0.2);
  ins.velocity = Vec3::Zero();
  s.insertions.push_back(ins);
  Simulation sim(s);
  sim.advance_to(0.04);
  const Particles& p = sim.particles();
  double worst = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      worst = std::max(worst, (p.radius[i] + p.radius[j] - (p.x[i] - p.x[j]).norm()) /
                                  std::min(p.radius[i], p.radius[j]));
  std::printf("[ measured ] blocked stream: %zu particles placed, lag %ld, max overlap ratio "
              "%.3f\n",
              p.size(), sim.streams().lag(0), worst);
  EXPECT_GT(sim.streams().lag(0), 0);
  EXPECT_LT(worst, 0.05);  // only contact overlaps from settling, no insertion overlaps
}

// A backlog beyond one step's most (kMaxPerStep, 100 000): 1e9 particles/s for 1 ms through
// a 4 mm disc that holds a few. The summary's "behind" had stopped at 100 000 (the most
// counted per step). Reference: rate x elapsed - delivered, exactly for a count rate; for a
// mass rate the mass behind is rate x elapsed - delivered mass, and the count a lower bound.
TEST(StreamInsertion, ABacklogIsCountedBeyondOneStepsMost) {
  Scene s = falling_stream_scene();
  s.gravity = Vec3::Zero();
  s.time.step = 1e-5;
  Insertion ins = stream(1);
  ins.mass_rate.reset();
  ins.count_rate = 1e9;
  ins.face.radius = 0.002;
  ins.radius.min = ins.radius.max = 0.0005;
  ins.velocity = Vec3::Zero();
  s.insertions.push_back(ins);
  Insertion by_mass = ins;
  by_mass.count_rate.reset();
  by_mass.mass_rate = 1309.0;  // kg/s: 1e9 particles of 1.309e-6 kg per second
  by_mass.face.centre = Vec3(0, 0, -0.03);
  by_mass.seed = 12;
  s.insertions.push_back(by_mass);
  Simulation sim(s);
  sim.advance_to(1e-3);
  const StreamInsertion& st = sim.streams();
  const long due = 1000000;  // 1e9 /s x 1e-3 s
  std::printf(
      "[ measured ] count stream: %ld placed, %ld behind (due %ld); mass stream: %ld "
      "placed, %.6g kg behind, %s%ld particles\n",
      st.count_inserted(0), st.lag(0), due, st.count_inserted(1), st.lag_mass(1),
      st.lag_is_lower_bound(1) ? "at least " : "", st.lag(1));
  EXPECT_LT(st.count_inserted(0), 100);
  EXPECT_EQ(st.lag(0), due - st.count_inserted(0));
  EXPECT_FALSE(st.lag_is_lower_bound(0));
  const double mass_due = 1309.0 * 1e-3;
  EXPECT_NEAR(st.lag_mass(1), mass_due - st.mass_inserted(1), 1e-12 * mass_due);
  EXPECT_TRUE(st.lag_is_lower_bound(1));
  EXPECT_GE(st.lag(1), 100000 - st.count_inserted(1));
}

// A face reaching across the periodic sides (a 0.06 m square centred on the corner x = y =
// -0.03 of a box periodic along x and y): the candidates are wrapped into the box and checked
// against the nearest images. Before, they were compared unwrapped, so that particles placed
// on either side of a periodic side overlapped by up to 142 % of a radius once wrapped.
// Reference: no two particles overlap by the minimum-image distance, every centre in the box.
TEST(StreamInsertion, AFaceAcrossPeriodicSidesPlacesNoOverlaps) {
  Scene s = falling_stream_scene();
  s.domain.periodic = {true, true, false};
  s.gravity = Vec3::Zero();
  Insertion ins = stream(1);
  ins.mass_rate.reset();
  ins.count_rate = 20000;
  ins.face.kind = InsertionFace::Kind::rectangle;
  ins.face.centre = Vec3(-0.03, -0.03, 0.03);
  ins.face.u = Vec3::UnitX();
  ins.face.length_u = 0.06;
  ins.face.length_v = 0.06;
  ins.velocity = Vec3(0, 0, -0.05);  // slow: the layers stay near the face
  s.insertions.push_back(ins);
  Simulation sim(s);
  sim.advance_to(0.02);
  const Particles& p = sim.particles();
  const Vec3 length = s.domain.hi - s.domain.lo;
  double worst = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int a = 0; a < 2; ++a) {
      EXPECT_GE(p.x[i][a], s.domain.lo[a]);
      EXPECT_LT(p.x[i][a], s.domain.hi[a]);
    }
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      Vec3 d = p.x[i] - p.x[j];
      for (int a = 0; a < 2; ++a) d[a] -= length[a] * std::round(d[a] / length[a]);
      worst = std::max(worst,
                       (p.radius[i] + p.radius[j] - d.norm()) / std::min(p.radius[i], p.radius[j]));
    }
  }
  std::printf(
      "[ measured ] face across the periodic sides: %zu particles, lag %ld, max overlap "
      "ratio %.4f\n",
      p.size(), sim.streams().lag(0), worst);
  EXPECT_GT(p.size(), 300u);
  EXPECT_LE(worst, 1e-9);
}

// Two planes 2 mm apart across a disc face: a particle of radius 1.2 mm fits nowhere
// between them. It waited for room for ever and the stream delivered nothing, with the run
// ending "done". Refused when the simulation is built, naming the wall at the face's centre;
// 3 mm apart (room for the largest particle) it runs, and so it does when one of the planes
// moves (it may make room later).
TEST(StreamInsertion, AFaceTheWallsLeaveNoRoomOnIsRefused) {
  const auto scene = [](double gap, bool moving) {
    Scene s = falling_stream_scene();
    s.insertions.push_back(stream(0.05));
    Wall a = test::plane(Vec3(-0.4 * gap, 0, 0), Vec3::UnitX());  // nearer the face's centre
    Wall b = test::plane(Vec3(0.6 * gap, 0, 0), -Vec3::UnitX());
    a.name = "left";
    b.name = "right";
    if (moving) b.motion.velocity = Vec3(0, 0, 0.1);
    s.walls = {a, b};
    return s;
  };
  try {
    Simulation sim(scene(0.002, false));
    ADD_FAILURE() << "a face with no room was accepted";
  } catch (const InsertionError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "<test>: error: insert: the walls leave no room on the stream's face for its "
                  "largest particles (radius 0.0012 m): at each of 4225 positions across the face "
                  "such a particle touches a wall (at the face's centre, wall 'left')"),
              std::string::npos)
        << e.what();
  }
  Simulation wide(scene(0.003, false));
  wide.advance_to(0.01);
  EXPECT_GT(wide.particles().size(), 0u);
  EXPECT_NO_THROW(Simulation(scene(0.002, true)));
}

// Saving and restoring the stream state continues the same sequence: a fresh
// inserter restored from the state draws the radii the running simulation draws next.
TEST(StreamInsertion, StateRoundTripContinuesTheSameSequence) {
  Scene s = falling_stream_scene();
  s.insertions.push_back(stream(0.05));
  Simulation a(s);
  a.advance_to(0.05);
  StreamInsertion copy(s);
  copy.restore_state(a.streams().save_state());
  EXPECT_EQ(copy.save_state(), a.streams().save_state());
  const GlobalId first_new = a.next_id();
  // The running simulation goes on to t = 0.05 + 10 dt; the copy inserts up to the
  // same time into an empty set (the stream is sparse: nothing blocks either).
  a.advance_to(0.05 + 10 * 2e-5);
  Particles pb;
  const WallSet walls(s);
  const Decomposition d(MPI_COMM_SELF, s.domain, {1, 1, 1});
  GlobalId ib = first_new;
  copy.insert(a.time(), pb, walls, d, ib, MPI_COMM_SELF);
  std::vector<double> ra;
  const Particles& p = a.particles();
  for (GlobalId id = first_new; id < a.next_id(); ++id)
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.id[i] == id) ra.push_back(p.radius[i]);
  ASSERT_GT(ra.size(), 0u);
  ASSERT_EQ(ra.size(), pb.size());
  for (std::size_t k = 0; k < ra.size(); ++k) EXPECT_EQ(ra[k], pb.radius[k]);
  EXPECT_EQ(copy.count_inserted(0), a.streams().count_inserted(0));
  EXPECT_THROW(copy.restore_state("2\n"), std::invalid_argument);
}

// A snapshot written by SnapshotWriter comes back as the same particles.
TEST(SnapshotInsertion, ContinuesABedFromASnapshot) {
  const std::filesystem::path dir =
      std::filesystem::path(GRAINFLOW_BINARY_DIR) / "test_output" / "snapshot_insertion";
  std::filesystem::remove_all(dir);
  prepare_output_directory(dir.string());
  Scene s = test::one_material_scene(5e6, 0.3, kRho, 0.3);
  Particles p;
  p.add(10, Vec3(0.1, 0.2, 0.3), Vec3(1, 2, 3), Vec3(4, 5, 6), 0.01, 0, kRho);
  p.add(11, Vec3(-0.1, 0.2, 0.3), Vec3(0, 0, 0), Vec3(0, 0, 0), 0.02, 0, kRho);
  SnapshotWriter w(MPI_COMM_WORLD, dir.string());
  const std::string file = w.write(p, 0.5, 10);
  Insertion ins;
  ins.kind = Insertion::Kind::snapshot;
  ins.snapshot_file = file;
  ins.source = "<test>";
  s.insertions.push_back(ins);
  Particles q;
  GlobalId next = 1;
  insert_particles(s, q, next);
  ASSERT_EQ(q.size(), 2u);
  EXPECT_EQ(next, 3);
  EXPECT_EQ(q.x[1], p.x[1]);
  EXPECT_EQ(q.v[0], p.v[0]);
  EXPECT_EQ(q.omega[0], p.omega[0]);
  EXPECT_EQ(q.radius[1], p.radius[1]);
  EXPECT_DOUBLE_EQ(q.mass[1], p.mass[1]);
  s.insertions[0].keep_velocity = false;
  Particles r;
  next = 1;
  insert_particles(s, r, next);
  EXPECT_EQ(r.v[0], Vec3::Zero());
  s.insertions[0].snapshot_file = (dir / "particles.xdmf").string();
  EXPECT_THROW(insert_particles(s, r, next), InsertionError);
}

// A snapshot names its scene's materials (root attribute material_names), and a scene that
// lists them in another order keeps each particle's material: the glass bead stays glass, the
// rubber one rubber (by index they had been swapped, silently when the densities agree). A
// scene without one of the names is refused, naming it.
TEST(SnapshotInsertion, MaterialsAreMatchedByNameNotByIndex) {
  const std::filesystem::path dir =
      std::filesystem::path(GRAINFLOW_BINARY_DIR) / "test_output" / "snapshot_material_names";
  std::filesystem::remove_all(dir);
  prepare_output_directory(dir.string());
  Particles p;
  p.add(10, Vec3(0.002, 0.002, 0.002), Vec3::Zero(), Vec3::Zero(), 5e-4, 0, kRho);  // glass
  p.add(11, Vec3(0.006, 0.006, 0.006), Vec3::Zero(), Vec3::Zero(), 5e-4, 1, kRho);  // rubber
  SnapshotWriter w(MPI_COMM_WORLD, dir.string());
  w.set_material_names({"glass", "rubber"});
  const std::string file = w.write(p, 0.5, 10);
  const auto scene = [&](const std::string& materials) {
    return parse_scene(
        "domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.01]}\n"
        "time: {step: 1e-6, end: 1e-5}\n"
        "materials:\n" +
            materials +
            "interaction_defaults: {restitution: 0.5}\n"
            "contact: {normal: hertz}\n"
            "insert:\n  - {type: snapshot, file: '" +
            file + "'}\n",
        "<test>");
  };
  const Scene s = scene(
      "  - {name: rubber, youngs_modulus: 1e6, poisson_ratio: 0.45, density: 2500}\n"
      "  - {name: glass, youngs_modulus: 5e7, poisson_ratio: 0.3, density: 2500}\n");
  Particles q;
  GlobalId next = 1;
  insert_particles(s, q, next);
  ASSERT_EQ(q.size(), 2u);
  EXPECT_EQ(s.materials[static_cast<std::size_t>(q.material[0])].name, "glass");
  EXPECT_EQ(s.materials[static_cast<std::size_t>(q.material[1])].name, "rubber");

  const Scene missing = scene(
      "  - {name: glass, youngs_modulus: 5e7, poisson_ratio: 0.3, density: 2500}\n"
      "  - {name: gum, youngs_modulus: 1e6, poisson_ratio: 0.45, density: 2500}\n");
  Particles r;
  next = 1;
  try {
    insert_particles(missing, r, next);
    ADD_FAILURE() << "a snapshot of rubber beads was taken into a scene without rubber";
  } catch (const InsertionError& e) {
    EXPECT_NE(std::string(e.what()).find("material 'rubber'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("it lists glass, gum"), std::string::npos) << e.what();
  }
}

// A periodic run moves centres back into [lo, hi) only at neighbour-list rebuilds, so its
// snapshots may hold centres just past a periodic side: they are the same spheres as their
// images one period away, and come back there. A centre farther out is an error naming it.
TEST(SnapshotInsertion, CentresJustPastAPeriodicSideComeBackAsTheirImages) {
  const std::filesystem::path dir =
      std::filesystem::path(GRAINFLOW_BINARY_DIR) / "test_output" / "snapshot_insertion_periodic";
  std::filesystem::remove_all(dir);
  prepare_output_directory(dir.string());
  Scene s = test::one_material_scene(5e6, 0.3, kRho, 0.3);  // domain [-1, 1]^3
  s.domain.periodic = {true, true, false};
  const double r = 0.01;
  Particles p;
  p.add(1, Vec3(-1 - 0.3 * r, 0, 0), Vec3::Zero(), Vec3::Zero(), r, 0, kRho);
  p.add(2, Vec3(0, 1 + 0.1 * r, 0), Vec3::Zero(), Vec3::Zero(), r, 0, kRho);
  p.add(3, Vec3(0.5, 0.5, 0.5), Vec3::Zero(), Vec3::Zero(), r, 0, kRho);
  SnapshotWriter w(MPI_COMM_WORLD, dir.string());
  Insertion ins;
  ins.kind = Insertion::Kind::snapshot;
  ins.snapshot_file = w.write(p, 0.5, 10);
  ins.source = "scene.yaml:9";
  s.insertions.push_back(ins);
  Particles q;
  GlobalId next = 1;
  insert_particles(s, q, next);
  ASSERT_EQ(q.size(), 3u);
  EXPECT_DOUBLE_EQ(q.x[0][0], 1 - 0.3 * r);  // one period (2 m) further
  EXPECT_EQ(q.x[0][1], 0.0);
  EXPECT_DOUBLE_EQ(q.x[1][1], -1 + 0.1 * r);
  EXPECT_EQ(q.x[2], p.x[2]);

  // Two radii past the side (default skin 0.4 r): not a periodic run's drift.
  p.x[0][0] = -1 - 2 * r;
  s.insertions[0].snapshot_file = w.write(p, 0.6, 11);
  Particles bad;
  next = 1;
  try {
    insert_particles(s, bad, next);
    FAIL() << "expected StateError";
  } catch (const StateError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "error: dataset '/position', index 0 (particle id 1): the particle lies outside"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("(insertion at scene.yaml:9)"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("its centre x = -1.02 is outside the periodic range [-1, 1)"),
              std::string::npos) << e.what();
  }
  // A scene skin of 6 r lets a run drift 3 r between rebuilds: accepted then.
  s.neighbour.skin = 6 * r;
  Particles ok;
  next = 1;
  insert_particles(s, ok, next);
  EXPECT_DOUBLE_EQ(ok.x[0][0], 1 - 2 * r);
}

}  // namespace
}  // namespace grainflow
