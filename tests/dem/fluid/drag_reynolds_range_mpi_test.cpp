// The drag law evaluated beyond the Reynolds number of its data is counted and reported,
// summed over the ranks (docs/models/fluid-forces.md, "Validity"). Runs on 2 ranks.
// Reference: Re = rho_f eps d |u_f - v| / mu by hand (rho_f = 1.2, mu = 1.8e-5, d = 2 mm):
// - koch_hill (bound 200) at eps = 0.5, u_f = 12 m/s: a bead at rest has Re = 800, one moving
//   at 9 m/s Re = 200 (not beyond: the bound is inclusive);
// - schiller_naumann is a single sphere's law: its Re has no eps, so at eps = 0.5 a bead at
//   rest in 1800 m/s has Re = 2.4e5, beyond its 2e5, although eps Re = 1.2e5 is not;
// - ergun has no bound: never reported.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mpi.h>

#include <memory>
#include <string>

#include "dem/engine/force_term.hpp"
#include "dem/fluid/fluid_forces.hpp"

namespace grainflow {
namespace {

using ::testing::HasSubstr;

FluidSettings air(const std::string& law, double speed) {
  FluidSettings s;
  s.field.density = 1.2;
  s.field.viscosity = 1.8e-5;
  s.field.velocity = Vec3(0, 0, speed);
  s.field.void_fraction = 0.5;
  s.drag_law = law;
  s.forces = {FluidForce::drag, FluidForce::pressure_gradient, FluidForce::viscous};
  s.source = "scene.yaml:9";
  return s;
}

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

// One bead per rank at velocity (0, 0, vz[rank]), the term applied at t = 0.1 and 0.2 s.
std::string report_after_two_steps(const FluidSettings& s, const double (&vz)[2]) {
  const auto term = make_fluid_forces(s, Vec3::Zero(), Domain{}, MPI_COMM_WORLD);
  Particles p;
  p.add(rank() + 1, Vec3::Zero(), Vec3(0, 0, vz[rank()]), Vec3::Zero(), 1e-3, 0, 2500);
  for (double t : {0.1, 0.2}) {
    ImplicitDrag drag;
    drag.coefficient.assign(p.size(), 0.0);
    drag.fluid_velocity.assign(p.size(), Vec3::Zero());
    term->add(p, t, drag);
  }
  return term->report();  // collective
}

TEST(DragReynoldsRange, BeyondTheDataIsCountedOverTheRanks) {
  int size = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  ASSERT_EQ(size, 2);
  // Rank 0's bead within the bound, rank 1's beyond: rank 0 reports rank 1's steps.
  const std::string koch = report_after_two_steps(air("koch_hill", 12), {9, 0});
  EXPECT_THAT(koch, HasSubstr("scene.yaml:9: warning: fluid.drag: koch_hill was evaluated beyond "
                              "the Re = 200 of its data"));
  EXPECT_THAT(koch, HasSubstr("in 2 of 4 particle-steps, from t = 0.1 s, up to Re = 800 (Re = "
                              "rho_f eps d |u_f - v| / mu"));
  // The laws for beds whose data reach Re = 800 (not ergun: no bound known; not the single
  // sphere's law).
  EXPECT_THAT(koch, HasSubstr("laws whose data reach that Re: di_felice, rong, wen_yu, gidaspow, "
                              "beetstra ("));

  EXPECT_EQ(report_after_two_steps(air("koch_hill", 12), {9, 9}), "");
  EXPECT_EQ(report_after_two_steps(air("ergun", 1800), {0, 0}), "");

  const std::string single = report_after_two_steps(air("schiller_naumann", 1800), {0, 0});
  EXPECT_THAT(single, HasSubstr("schiller_naumann was evaluated beyond the Re = 2e+05 of its "
                                "data"));
  EXPECT_THAT(single, HasSubstr("in 4 of 4 particle-steps, from t = 0.1 s, up to Re = 2.4e+05 "
                                "(Re = rho_f d |u_f - v| / mu"));
  EXPECT_THAT(single, ::testing::Not(HasSubstr("laws whose data reach")));
  EXPECT_EQ(report_after_two_steps(air("wen_yu", 1800), {0, 0}), "");  // eps Re = 1.2e5
}

}  // namespace
}  // namespace grainflow
