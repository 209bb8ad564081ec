#pragma once
// Extension point for non-contact forces (fluid forces, later coupling): a term is
// called once per step, after the contact sweep, and loops over the particles itself.
// The virtual call is per sweep, never per particle.
#include <string>
#include <vector>

#include "dem/core/particles.hpp"

namespace grainflow {

// Drag that the integrator treats implicitly in the particle velocity:
// F_drag,i = K_i (u_i - v_i). With K_i = 0 a particle has no implicit drag.
// Implicit treatment keeps a particle whose response time m/K is far shorter than
// dt stable and free of overshoot (each half kick solves for the new velocity).
// The same for the spin when a term sets `spin_coefficient` (ForceTerm::implicit_spin):
// T_i = K_r,i (Omega_i - w_i), Omega_i = (1/2) curl u_f, response time I/K_r.
struct ImplicitDrag {
  std::vector<double> coefficient;   // K_i >= 0 [kg/s]
  std::vector<Vec3> fluid_velocity;  // u_i [m/s]
  std::vector<double> spin_coefficient;  // K_r,i >= 0 [N m s]; empty: no implicit torque
  std::vector<Vec3> fluid_spin;          // Omega_i [rad/s]
};

// A force term's stability limit on the time step (DESIGN.md §9), the smallest over the
// particles at the time it is evaluated. An implicit term has a time scale but no limit.
struct TermLimit {
  std::string term;        // the scene's name of the force (fluid.forces)
  std::string time_scale;  // what the time scale is, e.g. "m/K = rho_p d^2/(18 mu f)"
  double tau = 0;          // the smallest time scale [s] (infinity: none, e.g. no shear)
  GlobalId particle = -1;  // the particle that sets it
  bool implicit = false;   // integrated implicitly: stable at any dt
  double dt_max = 0;       // the largest stable dt [s] (infinity when any dt is stable)
  std::string rule;        // where dt_max comes from, or why there is none
};

class VoidFractionGrid;

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  virtual std::string name() const = 0;
  // Adds explicit forces/torques to p.force / p.torque (which hold gravity and
  // contacts) and may set each particle's implicit drag. `drag` arrays are sized to
  // p.size() and zeroed before the first term of the step.
  virtual void add(Particles& p, double time, ImplicitDrag& drag) = 0;
  // Anything the run's closing summary must say (counted clamps, ...); may be empty.
  virtual std::string report() const { return {}; }
  // Whether add() sets the implicit spin drag (ImplicitDrag::spin_coefficient).
  virtual bool implicit_spin() const { return false; }
  // The void fraction the term computes from the particles in add() (fluid.void_fraction:
  // {cell_size, ...}), for convection to use the same eps; nullptr when it computes none.
  virtual const VoidFractionGrid* void_fraction_grid() const { return nullptr; }
  // The stability limit of each force of the term at the particles' present state.
  virtual std::vector<TermLimit> limits(const Particles& /*p*/, double /*time*/) const {
    return {};
  }
};

}  // namespace grainflow
