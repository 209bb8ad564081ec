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
struct ImplicitDrag {
  std::vector<double> coefficient;   // K_i >= 0 [kg/s]
  std::vector<Vec3> fluid_velocity;  // u_i [m/s]
};

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
};

}  // namespace grainflow
