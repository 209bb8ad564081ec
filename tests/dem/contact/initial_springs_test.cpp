// Contacts present when a run starts: their springs start from zero displacement, and the
// evaluation of the initial state (Simulation::initialise) does not advance them. After N
// steps a sticking tangential spring holds exactly the tangential displacement of those N
// steps, N dt v_t, and an EPSD rolling spring the torque -k_r N dt w_r (Ai et al. 2011) — not
// (N + 1) dt, which an initial evaluation that advanced the springs would give.
//
// The motion is prescribed by inertia: the spheres are so dense (1e12 kg/m^3) that over the
// N = 10 steps the contact forces change their spins by ~1e-11 relatively and their
// positions by ~1e-17 m, so v_t and w_r stay those of the start. Hooke with given k_n, k_t and
// e = 1 (no dashpots) and EPSD damping ratio 0 leave the springs alone in the forces. Three
// contacts, far apart:
// - pair a-b: a spins about z, b at rest; contact point velocity v_t = arm w (arm = r - d/2);
// - sphere c on the plane z = -0.5, spinning about x: v_t = arm w (arm = r - d);
// - pair d-e spinning in opposite senses about z: no sliding (v_t = 0 exactly), w_r = 2 w.
// Reference: F_t = -k_t N dt v_t and M_r = -k_r N dt w_r, k_r = 2.25 k_n mu_r^2 R*^2. The
// tolerance 1e-9 relative covers the prescribed motion's drift (~1e-11).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kR = 1e-3, kOverlap = 1e-5, kSpin = 10, kDt = 1e-6;
constexpr double kKn = 1e3, kKt = 8e2, kRollingFriction = 0.1;
constexpr int kSteps = 10;

struct Springs {
  double pair_force = 0;      // y force on a [N]
  double wall_force = 0;      // y force on c [N]
  double rolling_torque = 0;  // z torque on d [N m]
};

class InitialSprings : public ::testing::TestWithParam<DashpotVelocity> {
 protected:
  void SetUp() override {
    Scene s = test::one_material_scene(1e7, 0.3, 1e12, 1.0, 0.5, kRollingFriction);
    s.gravity = Vec3::Zero();
    s.contact.normal = NormalModel::hooke;
    s.contact.hooke_kn = kKn;
    s.contact.hooke_kt = kKt;
    s.contact.tangential = TangentialModel::history;
    s.contact.rolling = RollingModel::epsd;
    s.contact.epsd_damping_ratio = 0;
    s.contact.dashpot_velocity = GetParam();
    s.walls.push_back(test::plane(Vec3(0, 0, -0.5), Vec3::UnitZ()));
    sim_ = std::make_unique<Simulation>(s, false);
    Particles& p = sim_->particles();
    const double half = kR - 0.5 * kOverlap;
    p.add(1, Vec3(-half, 0, 0.5), Vec3::Zero(), Vec3(0, 0, kSpin), kR, 0, 1e12);  // a
    p.add(2, Vec3(half, 0, 0.5), Vec3::Zero(), Vec3::Zero(), kR, 0, 1e12);        // b
    p.add(3, Vec3(0, -0.5, -0.5 + kR - kOverlap), Vec3::Zero(), Vec3(kSpin, 0, 0), kR, 0,
          1e12);                                                                    // c
    p.add(4, Vec3(-half, 0.5, 0.5), Vec3::Zero(), Vec3(0, 0, kSpin), kR, 0, 1e12);  // d
    p.add(5, Vec3(half, 0.5, 0.5), Vec3::Zero(), Vec3(0, 0, -kSpin), kR, 0, 1e12);  // e
    sim_->set_dt(kDt);
    sim_->initialise();
  }
  Springs read() const {
    const Particles& p = sim_->particles();
    Springs out;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.id[i] == 1) out.pair_force = p.force[i].y();
      if (p.id[i] == 3) out.wall_force = p.force[i].y();
      if (p.id[i] == 4) out.rolling_torque = p.torque[i].z();
    }
    return out;
  }
  std::unique_ptr<Simulation> sim_;
};

TEST_P(InitialSprings, StartFromZeroAndHoldTheStepsDisplacement) {
  // The initial state: every spring at zero displacement, so no tangential force or torque
  // (the rolling torque of d is then the tangential spring's only, zero too).
  const Springs start = read();
  EXPECT_EQ(start.pair_force, 0.0);
  EXPECT_EQ(start.wall_force, 0.0);
  EXPECT_EQ(start.rolling_torque, 0.0);

  for (int k = 0; k < kSteps; ++k) sim_->step();
  const Springs end = read();
  const double travel = kSteps * kDt;  // N dt
  const double pair_vt = (kR - 0.5 * kOverlap) * kSpin;
  const double wall_vt = (kR - kOverlap) * kSpin;
  const double r_star = 0.5 * kR;
  const double kr = 2.25 * kKn * kRollingFriction * kRollingFriction * r_star * r_star;
  const double pair_ref = -kKt * travel * pair_vt;
  const double wall_ref = -kKt * travel * wall_vt;
  const double rolling_ref = -kr * travel * 2 * kSpin;
  EXPECT_NEAR(end.pair_force, pair_ref, 1e-9 * std::abs(pair_ref));
  EXPECT_NEAR(end.wall_force, wall_ref, 1e-9 * std::abs(wall_ref));
  EXPECT_NEAR(end.rolling_torque, rolling_ref, 1e-9 * std::abs(rolling_ref));
  // Sticking: the springs are below their Coulomb and rolling limits.
  ASSERT_LT(std::abs(pair_ref), 0.5 * kKn * kOverlap);
  ASSERT_LT(std::abs(rolling_ref), kRollingFriction * r_star * kKn * kOverlap);
}

INSTANTIATE_TEST_SUITE_P(DashpotVelocities, InitialSprings,
                         ::testing::Values(DashpotVelocity::half_step, DashpotVelocity::predicted),
                         [](const ::testing::TestParamInfo<DashpotVelocity>& p) {
                           return p.param == DashpotVelocity::half_step ? "half_step" : "predicted";
                         });

}  // namespace
}  // namespace grainflow
