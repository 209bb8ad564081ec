#include "dem/core/particles.hpp"

namespace grainflow {

void Particles::reserve(std::size_t n) {
  id.reserve(n);
  x.reserve(n);
  v.reserve(n);
  omega.reserve(n);
  v_pred.reserve(n);
  omega_pred.reserve(n);
  force.reserve(n);
  torque.reserve(n);
  radius.reserve(n);
  mass.reserve(n);
  inertia.reserve(n);
  material.reserve(n);
  temperature.reserve(n);
}

std::size_t Particles::add(GlobalId gid, const Vec3& position, const Vec3& velocity,
                           const Vec3& spin, double r, int mat, double density) {
  const double m = density * sphere_volume(r);
  return add_raw(gid, position, velocity, spin, r, m, 0.4 * m * r * r, mat);
}

std::size_t Particles::add_raw(GlobalId gid, const Vec3& position, const Vec3& velocity,
                               const Vec3& spin, double r, double m, double moment, int mat) {
  id.push_back(gid);
  x.push_back(position);
  v.push_back(velocity);
  omega.push_back(spin);
  v_pred.push_back(velocity);
  omega_pred.push_back(spin);
  force.push_back(Vec3::Zero());
  torque.push_back(Vec3::Zero());
  radius.push_back(r);
  mass.push_back(m);
  inertia.push_back(moment);
  material.push_back(mat);
  temperature.push_back(0.0);
  return id.size() - 1;
}

namespace {
template <class T>
void apply_permutation(std::vector<T>& a, const std::vector<std::size_t>& perm) {
  std::vector<T> out;
  out.reserve(a.size());
  for (std::size_t k : perm) out.push_back(a[k]);
  a.swap(out);
}

template <class T>
void compact(std::vector<T>& a, const std::vector<char>& remove) {
  std::size_t w = 0;
  for (std::size_t r = 0; r < a.size(); ++r)
    if (!remove[r]) a[w++] = a[r];
  a.resize(w);
}
}  // namespace

void Particles::permute(const std::vector<std::size_t>& perm) {
  apply_permutation(id, perm);
  apply_permutation(x, perm);
  apply_permutation(v, perm);
  apply_permutation(omega, perm);
  apply_permutation(v_pred, perm);
  apply_permutation(omega_pred, perm);
  apply_permutation(force, perm);
  apply_permutation(torque, perm);
  apply_permutation(radius, perm);
  apply_permutation(mass, perm);
  apply_permutation(inertia, perm);
  apply_permutation(material, perm);
  apply_permutation(temperature, perm);
}

void Particles::remove_if(const std::vector<char>& remove) {
  compact(id, remove);
  compact(x, remove);
  compact(v, remove);
  compact(omega, remove);
  compact(v_pred, remove);
  compact(omega_pred, remove);
  compact(force, remove);
  compact(torque, remove);
  compact(radius, remove);
  compact(mass, remove);
  compact(inertia, remove);
  compact(material, remove);
  compact(temperature, remove);
}

}  // namespace grainflow
