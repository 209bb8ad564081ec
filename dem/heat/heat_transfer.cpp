#include "dem/heat/heat_transfer.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "dem/heat/heat_laws.hpp"
#include "dem/walls/wall_contact.hpp"

namespace grainflow {

std::vector<double> contact_radius_factors(const Scene& scene) {
  const std::size_t n = scene.materials.size();
  std::vector<double> f(n * n, 1.0);
  if (!scene.heat || scene.heat->contact_radius == ContactRadiusModel::geometric) return f;
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      const Material& ma = scene.materials[a];
      const Material& mb = scene.materials[b];
      const double sim = hertz_effective_modulus(ma.youngs_modulus, ma.poisson_ratio,
                                                 mb.youngs_modulus, mb.poisson_ratio);
      const double real = hertz_effective_modulus(ma.real_youngs_modulus, ma.poisson_ratio,
                                                  mb.real_youngs_modulus, mb.poisson_ratio);
      f[a * n + b] = scene.heat->contact_radius == ContactRadiusModel::morris_static
                         ? morris_static_radius_factor(sim, real)
                         : morris_collision_radius_factor(sim, real);
    }
  return f;
}

HeatTransfer::HeatTransfer(const Scene& scene)
    : materials_(static_cast<int>(scene.materials.size())),
      conduction_(scene.heat && scene.heat->conduction),
      gravity_(scene.gravity) {
  for (const Material& m : scene.materials) {
    cp_.push_back(m.heat_capacity);
    source_.push_back(m.heat_source);
    k_.push_back(m.conductivity);
    coarse_grain_.push_back(m.coarse_grain);
  }
  radius_factor_ = contact_radius_factors(scene);
  k_star_.resize(static_cast<std::size_t>(materials_) * materials_);
  for (int a = 0; a < materials_; ++a)
    for (int b = 0; b < materials_; ++b)
      k_star_[a * materials_ + b] =
          effective_conductivity(k_[std::min(a, b)], k_[std::max(a, b)]) *
          radius_factor_[std::min(a, b) * materials_ + std::max(a, b)];
  for (const Wall& w : scene.walls) wall_thermal_.push_back(w.thermal);
  wall_heat_.assign(wall_thermal_.size(), 0.0);
  if (scene.fluid) {
    fluid_thermal_ = scene.fluid->thermal;
    field_ = scene.fluid->field;
    computed_void_fraction_ = scene.fluid->computed_void_fraction.has_value();
  }
}

double HeatTransfer::thermal_energy(const Particles& p) const {
  double e = 0;
  for (std::size_t i = 0; i < p.size(); ++i) e += p.mass[i] * cp_[p.material[i]] * p.temperature[i];
  return e;
}

void HeatTransfer::walls_pass(const Particles& p, const WallSet& walls, const WallNeighbours& wn) {
  for (std::size_t w = 0; w < walls.walls().size(); ++w) {
    const WallThermal& th = wall_thermal_[w];
    wall_heat_[w] = 0;
    if (th.kind == WallThermal::Kind::adiabatic) continue;
    const WallSet::Entry& wall = walls.walls()[w];
    // One touching contact of particle i with this wall, of overlap `overlap`.
    const auto conduct = [&](std::size_t i, double overlap) {
      const double a = contact_radius(p.radius[i], overlap);  // R* = r_i: a flat wall
      const std::size_t pair = static_cast<std::size_t>(p.material[i]) * materials_ + wall.material;
      // k_star_ holds the radius factor f; the flux wall's area is pi (f a)^2.
      const double q = th.kind == WallThermal::Kind::temperature
                           ? contact_conductance(k_star_[pair], a) * (th.value - p.temperature[i])
                           : th.value * std::numbers::pi * (radius_factor_[pair] * a) *
                                 (radius_factor_[pair] * a);
      q_[i] += q;
      wall_heat_[w] += q;
    };
    if (wall.kind == Wall::Kind::mesh) {
      const TriangleMesh& mesh = walls.mesh(wall);
      MeshTouch touch[TriangleMesh::kMaxTouches];
      for (std::size_t i = 0; i < p.size(); ++i) {
        const int n =
            mesh.touches(WallSet::mesh_query(wall, walls.in_period(p.x[i])), p.radius[i], touch);
        for (int k = 0; k < n; ++k) conduct(i, touch[k].overlap);
      }
      continue;
    }
    const WallNeighbours::List& list = wn.lists[w];
    const std::size_t n = list.all ? p.size() : list.i.size();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = list.all ? k : static_cast<std::size_t>(list.i[k]);
      WallTouch t;
      const bool touching = wall.kind == Wall::Kind::plane
                                ? touch_plane(wall.plane, p.x[i], p.radius[i], t)
                                : touch_cylinder(wall.cylinder, p.x[i], p.radius[i], t);
      if (touching) conduct(i, t.overlap);
    }
  }
}

void HeatTransfer::step(Particles& p, const Ghosts& g, const std::vector<double>& ghost_temperature,
                        const NeighbourList& local, const NeighbourList& ghost,
                        const WallSet& walls, const WallNeighbours& wall_neighbours, double dt,
                        const CanonicalOrder* canonical) {
  const std::size_t n = p.size();
  q_.assign(n, 0.0);
  const double* T = p.temperature.data();
  if (conduction_) {
    // A local pair (list entry e), once: +q to i, -q to j.
    const auto local_pair = [&](std::size_t e) {
      const std::size_t i = local.owner[e], j = local.j[e];
      const double sum = p.radius[i] + p.radius[j];
      const double d2 = (p.x[i] - p.x[j]).squaredNorm();
      if (d2 >= sum * sum) return;
      const double overlap = sum - std::sqrt(d2);
      const double r_star = p.radius[i] * p.radius[j] / sum;
      const double q = contact_conductance(k_star_[p.material[i] * materials_ + p.material[j]],
                                           contact_radius(r_star, overlap)) *
                       (T[j] - T[i]);
      q_[i] += q;
      q_[j] -= q;
    };
    // A local-ghost pair: the ghost's owner computes the same pair from its side. The
    // operands are the same bits in the other order, and each operation gives the same
    // result in either order (a - b = -(b - a), squares, sums and products commute), so
    // the two ranks' q are exact opposites, and equal to the q of the same pair held by one
    // rank as a local pair.
    const auto ghost_pair = [&](std::size_t e) {
      const std::size_t i = ghost.owner[e], k = ghost.j[e];
      const double sum = p.radius[i] + g.radius[k];
      const double d2 = ((p.x[i] - g.x[k]) - g.shift[k]).squaredNorm();
      if (d2 >= sum * sum) return;
      const double overlap = sum - std::sqrt(d2);
      const double r_star = p.radius[i] * g.radius[k] / sum;
      q_[i] += contact_conductance(k_star_[p.material[i] * materials_ + g.material[k]],
                                   contact_radius(r_star, overlap)) *
               (ghost_temperature[k] - T[i]);
    };
    if (canonical != nullptr) {
      // parallel.reproducible: the contact sweep's order, so that each particle adds its
      // pairs' heat by ascending partner key on every decomposition (canonical_order.hpp).
      std::size_t e = 0, t = 0;
      for (const CanonicalOrder::Run& run : canonical->runs) {
        for (; e < static_cast<std::size_t>(run.local_end); ++e) local_pair(e);
        for (; t < static_cast<std::size_t>(run.ghost_end); ++t)
          ghost_pair(static_cast<std::size_t>(canonical->ghost_entries[t]));
      }
    } else {
      for (std::size_t e = 0; e < local.j.size(); ++e) local_pair(e);
      for (std::size_t e = 0; e < ghost.j.size(); ++e) ghost_pair(e);
    }
  }
  walls_pass(p, walls, wall_neighbours);
  fluid_heat_ = 0;
  source_heat_ = 0;
  double* Tw = p.temperature.data();
  const bool convection = fluid_thermal_.has_value();
  if (convection && coupled_) {
    coupled_step(p, dt);
    return;
  }
  if (convection && computed_void_fraction_ && !void_fraction_)
    throw std::logic_error("HeatTransfer: the scene computes the void fraction from the "
                           "particles, but no fluid force term lent its grid");
  for (std::size_t i = 0; i < n; ++i) {
    const double c = p.mass[i] * cp_[p.material[i]];
    const double s = p.mass[i] * source_[p.material[i]];
    source_heat_ += s;
    if (!convection) {
      Tw[i] += dt * (q_[i] + s) / c;
      continue;
    }
    const Vec3 u = field_.sample(p.x[i], gravity_).velocity;
    const double eps = void_fraction_ ? void_fraction_->at(p.x[i]) : field_.void_fraction;
    const double h = parcel_convective_conductance(
        *fluid_thermal_, eps, field_.density, field_.viscosity, 2 * p.radius[i],
        coarse_grain_[p.material[i]], (u - p.v[i]).norm());
    const double t_f = fluid_thermal_->temperature;
    Tw[i] = (Tw[i] + dt * (q_[i] + s + h * t_f) / c) / (1 + dt * h / c);
    fluid_heat_ += h * (t_f - Tw[i]);
  }
}

void HeatTransfer::coupled_step(Particles& p, double dt) {
  const CoupledFluid::View view = coupled_->at_particles(p);
  if (!view.temperature)
    throw std::logic_error("HeatTransfer: the coupled fluid samples carry no temperatures");
  double* T = p.temperature.data();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double c = p.mass[i] * cp_[p.material[i]];
    const double s = p.mass[i] * source_[p.material[i]];
    source_heat_ += s;
    const CoupledSample& f = view.samples[i];
    const double h = parcel_convective_conductance(
        *fluid_thermal_, f.void_fraction, field_.density, field_.viscosity, 2 * p.radius[i],
        coarse_grain_[p.material[i]], (f.velocity - p.v[i]).norm());
    const double t_f = view.temperature[i];
    T[i] = (T[i] + dt * (q_[i] + s + h * t_f) / c) / (1 + dt * h / c);
    const double q = h * (t_f - T[i]);
    fluid_heat_ += q;
    coupled_->add_heat(view.entry ? view.entry[i] : i, dt * q, p.x[i], h);
  }
}

}  // namespace grainflow
