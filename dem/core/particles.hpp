#pragma once
// Particle state as a structure of arrays: every per-particle quantity lives in its
// own contiguous array, indexed by the local particle index. Arrays are permuted
// together (spatial re-sorting at neighbour rebuilds) and shrunk together (removal).
#include <cstddef>
#include <numbers>
#include <vector>

#include "dem/core/types.hpp"

namespace grainflow {

struct Particles {
  std::vector<GlobalId> id;      // global id, stable for the particle's life
  std::vector<Vec3> x;           // position [m]
  std::vector<Vec3> v;           // velocity [m/s]
  std::vector<Vec3> omega;       // angular velocity [rad/s]
  // With contact.dashpot_velocity: predicted, the velocities the contact dashpots see: during a
  // step's force evaluation v and omega are those of the half step, and these the end-of-step
  // values predicted from them, set by the step's first half kick (Simulation::kick_and_drift;
  // docs/models/contact-models.md, "Integration"); before the first step, the initial v and
  // omega. Unused (not updated) with the default half_step.
  std::vector<Vec3> v_pred;      // [m/s]
  std::vector<Vec3> omega_pred;  // [rad/s]
  std::vector<Vec3> force;       // total force of the current step [N]
  std::vector<Vec3> torque;      // total torque of the current step [N m]
  std::vector<double> radius;    // [m]
  std::vector<double> mass;      // [kg]
  std::vector<double> inertia;   // moment of inertia of a solid sphere, 2/5 m r^2 [kg m^2]
  std::vector<int> material;     // index into the scene's material table
  // [K]; integrated only when the scene switches heat transfer on (0 otherwise). Touched
  // at rebuilds (re-sort, migration), never by the force loop or the kicks.
  std::vector<double> temperature;

  std::size_t size() const { return id.size(); }

  void reserve(std::size_t n);

  // Appends a solid sphere of the given density; returns its local index.
  std::size_t add(GlobalId gid, const Vec3& position, const Vec3& velocity, const Vec3& spin,
                  double r, int mat, double density);

  // Appends a particle whose mass and inertia are known (e.g. received from a rank).
  std::size_t add_raw(GlobalId gid, const Vec3& position, const Vec3& velocity, const Vec3& spin,
                      double r, double m, double moment, int mat);

  // Reorders every array so that new index k holds old index perm[k].
  void permute(const std::vector<std::size_t>& perm);

  // Keeps only the particles whose flag is false, preserving order.
  void remove_if(const std::vector<char>& remove);
};

inline double sphere_volume(double r) { return 4.0 / 3.0 * std::numbers::pi * r * r * r; }

}  // namespace grainflow
