#include "dem/engine/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "dem/insert/insertion.hpp"

namespace grainflow {
namespace {
// Contact springs are saved across rebuilds under the pair's global ids.
struct PairKey {
  GlobalId lo, hi;
  PairKey(GlobalId a, GlobalId b) : lo(std::min(a, b)), hi(std::max(a, b)) {}
  bool operator==(const PairKey&) const = default;
};
struct PairKeyHash {
  std::size_t operator()(const PairKey& k) const {
    return std::hash<GlobalId>()(k.lo) * 0x9E3779B97F4A7C15ull ^ std::hash<GlobalId>()(k.hi);
  }
};
}  // namespace

Simulation::Simulation(const Scene& scene, bool insert)
    : scene_(scene), table_(scene), box_(scene.domain) {
  constants_.hooke_characteristic_velocity =
      scene.contact.hooke_characteristic_velocity.value_or(0.0);
  constants_.hooke_kn = scene.contact.hooke_kn.value_or(0.0);
  constants_.hooke_kt = scene.contact.hooke_kt.value_or(constants_.hooke_kn);
  constants_.epsd_damping_ratio = scene.contact.epsd_damping_ratio;
  sweep_ = select_sweep(scene.contact, box_.any_periodic);
  if (insert) insert_particles(scene_, p_, next_id_);
}

void Simulation::initialise() {
  double r_max = 0;
  for (double r : p_.radius) r_max = std::max(r_max, r);
  if (r_max == 0) r_max = (box_.length.minCoeff()) / 100;  // empty scene: any grid works
  skin_ = scene_.neighbour.skin.value_or(0.4 * r_max);
  try {
    grid_ = std::make_unique<BinGrid>(box_, 2 * r_max + skin_);
  } catch (const std::invalid_argument& e) {  // a periodic axis too short for the particles
    throw SetupError(scene_.file + ": error: " + e.what());
  }

  report_ = check_time_step(scene_, p_, table_, constants_);
  if (dt_ <= 0) dt_ = report_.dt;
  if (dt_ <= 0)
    throw SetupError(scene_.file +
                     ": error: time.rayleigh_fraction needs particles to size the time step; "
                     "give time.step instead");
  wall_history_.assign(scene_.walls.size(), std::vector<ContactHistory>(p_.size()));
  for (std::size_t i = 0; i < p_.size(); ++i) {
    p_.force[i].setZero();
    p_.torque[i].setZero();
  }
  apply_boundaries();
  rebuild();
  compute_forces();
  initialised_ = true;
}

void Simulation::apply_boundaries() {
  leaving_.assign(p_.size(), 0);
  bool any = false;
  for (std::size_t i = 0; i < p_.size(); ++i) {
    Vec3& x = p_.x[i];
    for (int a = 0; a < 3; ++a) {
      if (box_.periodic[a]) {
        if (x[a] < box_.lo[a]) x[a] += box_.length[a];
        else if (x[a] >= box_.hi[a]) x[a] -= box_.length[a];
      } else if (x[a] < box_.lo[a] || x[a] > box_.hi[a]) {
        leaving_[i] = 1;
        any = true;
      }
    }
  }
  if (!any) leaving_.clear();
}

bool Simulation::needs_rebuild() const {
  if (!leaving_.empty()) return true;
  const double limit2 = 0.25 * skin_ * skin_;
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (box_.min_image(p_.x[i] - x_at_build_[i]).squaredNorm() > limit2) return true;
  return false;
}

void Simulation::rebuild() {
  // Save the springs of touching pairs by global ids; indices change below.
  std::unordered_map<PairKey, ContactHistory, PairKeyHash> saved;
  if (sweep_.has_history) {
    for (std::size_t i = 0; i + 1 < list_.offsets.size(); ++i)
      for (int k = list_.offsets[i]; k < list_.offsets[i + 1]; ++k) {
        const ContactHistory& h = pair_history_[k];
        if (!h.tangential.isZero(0) || !h.rolling.isZero(0))
          saved.emplace(PairKey(p_.id[i], p_.id[list_.j[k]]), h);
      }
  }
  if (!leaving_.empty()) {
    const long before = static_cast<long>(p_.size());
    p_.remove_if(leaving_);
    for (auto& wh : wall_history_) {
      std::size_t w = 0;
      for (std::size_t r = 0; r < wh.size(); ++r)
        if (!leaving_[r]) wh[w++] = wh[r];
      wh.resize(w);
    }
    counters_.removed += before - static_cast<long>(p_.size());
    leaving_.clear();
  }
  const std::vector<std::size_t> perm = grid_->sort_permutation(p_);
  p_.permute(perm);
  for (auto& wh : wall_history_) {
    std::vector<ContactHistory> sorted(perm.size());
    for (std::size_t k = 0; k < perm.size(); ++k) sorted[k] = wh[perm[k]];
    wh.swap(sorted);
  }
  grid_->build(p_, skin_, list_);
  pair_history_.assign(list_.pairs(), ContactHistory{});
  if (!saved.empty())
    for (std::size_t i = 0; i < p_.size(); ++i)
      for (int k = list_.offsets[i]; k < list_.offsets[i + 1]; ++k) {
        auto it = saved.find(PairKey(p_.id[i], p_.id[list_.j[k]]));
        if (it != saved.end()) pair_history_[k] = it->second;
      }
  x_at_build_ = p_.x;
  ++counters_.rebuilds;
}

void Simulation::compute_forces() {
  const Vec3 g = scene_.gravity;
  for (std::size_t i = 0; i < p_.size(); ++i) {
    p_.force[i] = p_.mass[i] * g;
    p_.torque[i].setZero();
  }
  ContactSweep s{p_, list_, pair_history_, scene_.walls, wall_history_, table_, constants_, box_,
                 dt_};
  sweep_.run(s);
  counters_.contacts = s.contacts;
  counters_.max_overlap_ratio = s.max_overlap_ratio;
  if (!terms_.empty()) {
    drag_.coefficient.assign(p_.size(), 0.0);
    drag_.fluid_velocity.assign(p_.size(), Vec3::Zero());
    for (auto& term : terms_) term->add(p_, time_, drag_);
  }
}

void Simulation::half_kick() {
  const double h = 0.5 * dt_;
  const std::size_t n = p_.size();
  if (drag_.coefficient.empty()) {
    for (std::size_t i = 0; i < n; ++i) p_.v[i] += (h / p_.mass[i]) * p_.force[i];
  } else {
    // v' = v + h/m (F + K (u - v'))  =>  v' = (v + h/m (F + K u)) / (1 + h K / m)
    for (std::size_t i = 0; i < n; ++i) {
      const double a = h / p_.mass[i], k = drag_.coefficient[i];
      p_.v[i] = (p_.v[i] + a * (p_.force[i] + k * drag_.fluid_velocity[i])) / (1 + a * k);
    }
  }
  if (sweep_.needs_spin)
    for (std::size_t i = 0; i < n; ++i) p_.omega[i] += (h / p_.inertia[i]) * p_.torque[i];
}

void Simulation::step() {
  if (!initialised_) initialise();
  // Velocity Verlet: half kick, drift, new forces, half kick.
  half_kick();
  for (std::size_t i = 0; i < p_.size(); ++i) p_.x[i] += dt_ * p_.v[i];
  apply_boundaries();
  if (needs_rebuild()) rebuild();
  time_ += dt_;
  compute_forces();
  half_kick();
  ++counters_.steps;
}

void Simulation::advance_to(double t_end) {
  while (time_ < t_end - 0.5 * dt_) step();
}

double Simulation::kinetic_energy_translational() const {
  double e = 0;
  for (std::size_t i = 0; i < p_.size(); ++i) e += 0.5 * p_.mass[i] * p_.v[i].squaredNorm();
  return e;
}

double Simulation::kinetic_energy_rotational() const {
  double e = 0;
  for (std::size_t i = 0; i < p_.size(); ++i) e += 0.5 * p_.inertia[i] * p_.omega[i].squaredNorm();
  return e;
}

}  // namespace grainflow
