#include "dem/engine/restored_state.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <utility>

#include "dem/engine/simulation.hpp"  // SetupError

namespace grainflow {
namespace {

// The shortest text that reads back as the same double (1e+300, 0.015).
std::string number(double v) {
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
  return std::string(buf, end);
}

std::string vec(const Vec3& v) {
  std::string out = "(";
  for (int a = 0; a < 3; ++a) out.append(number(v[a])).append(a < 2 ? ", " : ")");
  return out;
}

[[noreturn]] void fail(const StateSource& src, const std::string& dataset, std::size_t index,
                       const std::string& who, const std::string& rule) {
  throw StateError(src.file + ": error: dataset '" + src.group + dataset + "', index " +
                   std::to_string(index) + (who.empty() ? "" : " (" + who + ")") + ": " + rule +
                   "; " + src.advice);
}

std::string particle(GlobalId id) { return "particle id " + std::to_string(id); }

bool near(double value, double reference) {
  return std::abs(value - reference) <= kMassTolerance * std::abs(reference);
}

// The stored processor grid: what Decomposition::set_cuts accepts, for the scene's domain.
void check_grid(const CheckpointGrid& g, const Domain& dom, const StateSource& src) {
  if (g.ranks < 1)
    fail(src, "ranks", 0, "", "the rank count " + std::to_string(g.ranks) + " is not >= 1");
  long long product = 1;
  for (int a = 0; a < 3; ++a) {
    if (g.dims[a] < 1 || g.dims[a] > g.ranks)
      fail(src, "dims", static_cast<std::size_t>(a), "",
           std::string("the ranks along ") + "xyz"[a] + ", " + std::to_string(g.dims[a]) +
               ", are not in [1, " + std::to_string(g.ranks) + "] (dataset 'ranks')");
    product *= g.dims[a];
  }
  if (product != g.ranks)
    fail(src, "dims", 0, "",
         "the grid " + std::to_string(g.dims[0]) + " x " + std::to_string(g.dims[1]) + " x " +
             std::to_string(g.dims[2]) + " has " + std::to_string(product) +
             " boxes, but the file was written by " + std::to_string(g.ranks) +
             " ranks (dataset 'ranks')");
  for (int a = 0; a < 3; ++a) {
    const std::string name = std::string("cuts_") + "xyz"[a];
    const std::vector<double>& c = g.cuts[a];
    if (c.size() != static_cast<std::size_t>(g.dims[a]) + 1)
      fail(src, name, 0, "",
           std::to_string(c.size()) + " planes for " + std::to_string(g.dims[a]) +
               " rank(s) along " + "xyz"[a] + " (dataset 'dims'); there must be " +
               std::to_string(g.dims[a] + 1));
    if (c.front() != dom.lo[a] || c.back() != dom.hi[a])
      fail(src, name, c.front() != dom.lo[a] ? 0 : c.size() - 1, "",
           "the planes run from " + number(c.front()) + " to " + number(c.back()) +
               " m, not from the domain's lo " + number(dom.lo[a]) + " to its hi " +
               number(dom.hi[a]) + " m along " + "xyz"[a]);
    for (std::size_t k = 1; k < c.size(); ++k)
      if (!std::isfinite(c[k]) || !(c[k] > c[k - 1]))
        fail(src, name, k, "",
             "the plane " + number(c[k]) + " m is not a finite number above the one before, " +
                 number(c[k - 1]) + " m (the planes must increase strictly)");
  }
}

}  // namespace

void check_particle_records(const Particles& p, const Scene& scene, const StateSource& src,
                            bool inertia) {
  const int materials = static_cast<int>(scene.materials.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::string who = particle(p.id[i]);
    if (!p.x[i].allFinite())
      fail(src, "position", i, who, "the position " + vec(p.x[i]) + " is not finite");
    if (!std::isfinite(p.radius[i]) || !(p.radius[i] > 0))
      fail(src, "radius", i, who,
           "the radius " + number(p.radius[i]) + " m is not a finite number > 0");
    if (p.material[i] < 0 || p.material[i] >= materials)
      fail(src, "material", i, who,
           "the material index " + std::to_string(p.material[i]) + " is not one of the scene's " +
               std::to_string(materials) + " material(s) (allowed: 0 to " +
               std::to_string(materials - 1) + ", in the order of `materials`)");
    const Material& mat = scene.materials[static_cast<std::size_t>(p.material[i])];
    const double m = mat.density * sphere_volume(p.radius[i]);
    if (!near(p.mass[i], m))
      fail(src, "mass", i, who,
           "the mass " + number(p.mass[i]) + " kg is not rho (4/3) pi r^3 = " + number(m) +
               " kg of material '" + mat.name + "' (density " + number(mat.density) +
               " kg/m^3, radius " + number(p.radius[i]) + " m; relative tolerance " +
               number(kMassTolerance) + ")");
    if (inertia && !near(p.inertia[i], 0.4 * m * p.radius[i] * p.radius[i]))
      fail(src, "inertia", i, who,
           "the moment of inertia " + number(p.inertia[i]) +
               " kg m^2 is not 2/5 m r^2 = " + number(0.4 * m * p.radius[i] * p.radius[i]) +
               " kg m^2 (relative tolerance " + number(kMassTolerance) + ")");
    if (p.id[i] <= 0)
      fail(src, "id", i, "", "the particle id " + std::to_string(p.id[i]) + " is not > 0");
  }
  std::vector<std::pair<GlobalId, std::size_t>> ids(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) ids[i] = {p.id[i], i};
  std::sort(ids.begin(), ids.end());
  for (std::size_t k = 1; k < ids.size(); ++k)
    if (ids[k].first == ids[k - 1].first)
      fail(src, "id", ids[k].second, "",
           "the particle id " + std::to_string(ids[k].first) + " is also at index " +
               std::to_string(ids[k - 1].second) + "; ids must be unique");
}

void check_checkpoint(const CheckpointData& d, const Scene& scene, std::size_t wall_columns,
                      double stream_max_radius, const std::vector<long>& stream_counts) {
  const StateSource src{d.file, "/particles/",
                        "the checkpoint was changed or damaged after it was written, or belongs "
                        "to another scene: restart from an earlier checkpoint of this run (no "
                        "file was changed or deleted)"};
  auto attribute = [&](const std::string& name, const std::string& rule) {
    throw StateError(d.file + ": error: attribute '" + name + "' of the root group: " + rule +
                     "; " + src.advice);
  };
  if (!std::isfinite(d.time) || d.time < 0)
    attribute("time", "the time " + number(d.time) + " s is not a finite number >= 0");
  if (!std::isfinite(d.dt) || !(d.dt > 0))
    attribute("dt", "the time step " + number(d.dt) + " s is not a finite number > 0");
  if (d.step < 0) attribute("step", "the step " + std::to_string(d.step) + " is negative");

  if (d.grid) check_grid(*d.grid, scene.domain, {d.file, "/decomposition/", src.advice});

  // The parcel classes: a material index must mean the same k and listed material as when the
  // checkpoint was written (a changed coarse_grain would keep the parcels' radii and masses,
  // which pass every rule below, and give them another k).
  const std::size_t common = std::min(d.material_coarse_grain.size(), scene.materials.size());
  for (std::size_t m = 0; m < common; ++m) {
    const Material& mat = scene.materials[m];
    const int real = mat.real_material < 0 ? static_cast<int>(m) : mat.real_material;
    if (d.material_coarse_grain[m] == mat.coarse_grain && d.material_real[m] == real) continue;
    const auto what = [](double k, int listed, std::size_t index) {
      return k == 1 && listed == static_cast<int>(index)
                 ? std::string("a listed material (k = 1)")
                 : "parcels of k = " + number(k) + " of listed material " + std::to_string(listed);
    };
    throw StateError(d.file +
                     ": error: attributes 'material_coarse_grain', 'material_real' of "
                     "the root group: material index " +
                     std::to_string(m) + " was " +
                     what(d.material_coarse_grain[m], d.material_real[m], m) +
                     " when the checkpoint was written, but in " + scene.file + " it is '" +
                     mat.name + "', " + what(mat.coarse_grain, real, m) +
                     ": the scene's materials or coarse_grain changed since, so its particles "
                     "would continue as something else; restart with the scene the checkpoint "
                     "was written with, or start the changed scene afresh");
  }

  const Particles& p = d.particles;
  // A class the checkpoint's particles use but the scene no longer has (coarse_grain removed
  // or set to 1 before the restart; a checkpoint without the insertions' record).
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto m = static_cast<std::size_t>(p.material[i]);
    if (p.material[i] < 0 || m < scene.materials.size() || m >= d.material_coarse_grain.size())
      continue;
    throw StateError(d.file + ": error: dataset '/particles/material', index " + std::to_string(i) +
                     " (" + particle(p.id[i]) + "): material index " + std::to_string(m) +
                     " was parcels of k = " + number(d.material_coarse_grain[m]) +
                     " of listed material " + std::to_string(d.material_real[m]) +
                     " when the checkpoint was written (attribute 'material_coarse_grain'), but " +
                     scene.file + " has only " + std::to_string(scene.materials.size()) +
                     " material index(es): the scene's materials or coarse_grain changed since; "
                     "restart with the scene the checkpoint was written with, or start the "
                     "changed scene afresh");
  }
  // A density changed in the scene since the checkpoint: every particle of a material is off
  // by the same factor, which the rule below would blame on a damaged file.
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    double low = 0, high = 0;
    long count = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.material[i] != static_cast<int>(m)) continue;
      const double rho = p.mass[i] / sphere_volume(p.radius[i]);
      if (!std::isfinite(rho)) {
        count = 0;
        break;
      }
      low = count ? std::min(low, rho) : rho;
      high = count ? std::max(high, rho) : rho;
      ++count;
    }
    const Material& mat = scene.materials[m];
    if (count == 0 || !near(high, low) || near(low, mat.density)) continue;
    const std::string& listed =  // a parcel class has its listed material's density
        scene.materials[mat.real_material < 0 ? m : static_cast<std::size_t>(mat.real_material)]
            .name;
    throw StateError(scene.file + ": error: materials: '" + listed + "' has density " +
                     number(mat.density) + " kg/m^3, but each of its " + std::to_string(count) +
                     " particle(s) in checkpoint '" + d.file +
                     "' has mass / volume = " + number(low) +
                     " kg/m^3: the density changed since the checkpoint was written, and the "
                     "particles would continue with their old masses. Restart with density " +
                     number(low) +
                     " as the checkpoint's run had it, or start the changed scene "
                     "afresh");
  }
  check_particle_records(p, scene, src, true);

  // The range the run chose at its start: at least as large as every radius it holds.
  double r_max = stream_max_radius;
  for (double r : p.radius) r_max = std::max(r_max, r);
  if (d.largest_radius) {
    if (!std::isfinite(*d.largest_radius) || !(*d.largest_radius >= r_max) ||
        *d.largest_radius > std::max(r_max, 0.5 * (scene.domain.hi - scene.domain.lo).maxCoeff()))
      attribute("largest_radius",
                "the interaction range's radius " + number(*d.largest_radius) +
                    " m is not a finite number between the largest particle radius (" +
                    number(r_max) + " m) and half the domain's longest side");
    r_max = *d.largest_radius;
  }
  if (d.removed < 0)
    attribute("removed",
              "the count of removed particles " + std::to_string(d.removed) + " is negative");
  // The skin Simulation::initialise will choose, from the same radii, or the run's when larger:
  // its centres drifted by up to half of it (a restart with a smaller skin had refused them).
  if (d.skin && !(std::isfinite(*d.skin) && *d.skin > 0 &&
                  *d.skin <= (scene.domain.hi - scene.domain.lo).maxCoeff()))
    attribute("skin", "the neighbour skin " + number(*d.skin) +
                          " m is not a positive finite length within the domain's longest side");
  const double drift =
      0.5 * std::max(scene.neighbour.skin.value_or(0.4 * r_max), d.skin.value_or(0.0));
  const Domain& dom = scene.domain;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double slack = std::max(p.radius[i], drift);
    for (int a = 0; a < 3; ++a)
      if (p.x[i][a] < dom.lo[a] - slack || p.x[i][a] > dom.hi[a] + slack)
        fail(src, "position", i, particle(p.id[i]),
             std::string("the position ") + vec(p.x[i]) + " is outside the domain along " +
                 "xyz"[a] + " (" + (dom.periodic[a] ? "periodic" : "bounded") + ", [" +
                 number(dom.lo[a]) + ", " + number(dom.hi[a]) + "] m) by more than " +
                 number(slack) +
                 " m, the larger of the radius and half the neighbour skin that a centre can "
                 "drift between two neighbour-list rebuilds");
  }

  GlobalId largest = 0;
  for (GlobalId id : p.id) largest = std::max(largest, id);
  if (d.next_id <= largest)
    attribute("next_id", "next_id = " + std::to_string(d.next_id) +
                             " is not above the largest particle id " + std::to_string(largest) +
                             " (a new particle would get an id already taken)");
  for (std::size_t k = 0; k < stream_counts.size(); ++k)
    if (stream_counts[k] < 0 || stream_counts[k] >= d.next_id)
      throw StateError(d.file + ": error: dataset '/streams/state', stream " + std::to_string(k) +
                       ": " + std::to_string(stream_counts[k]) +
                       " particles delivered, but every delivered particle took an id and "
                       "next_id = " +
                       std::to_string(d.next_id) + " (the count must lie in [0, next_id - 1]); " +
                       src.advice);

  for (std::size_t i = 0; i < d.drag_coefficient.size(); ++i) {
    if (!std::isfinite(d.drag_coefficient[i]) || d.drag_coefficient[i] < 0)
      fail(src, "drag_coefficient", i, particle(p.id[i]),
           "the implicit drag coefficient " + number(d.drag_coefficient[i]) +
               " kg/s is not a finite number >= 0");
    if (!d.drag_fluid_velocity[i].allFinite())
      fail(src, "drag_fluid_velocity", i, particle(p.id[i]),
           "the fluid velocity " + vec(d.drag_fluid_velocity[i]) + " is not finite");
  }

  std::vector<GlobalId> ids = p.id;
  std::sort(ids.begin(), ids.end());
  const auto exists = [&](GlobalId id) { return std::binary_search(ids.begin(), ids.end(), id); };
  const StateSource springs{d.file, "/springs/", src.advice};
  for (std::size_t k = 0; k < d.springs.size(); ++k) {
    const CheckpointSpring& s = d.springs[k];
    if (!exists(s.particle))
      fail(springs, "particle", k, "",
           "the spring's particle id " + std::to_string(s.particle) +
               " is not a particle of the file");
    if (s.partner >= 0 && !exists(s.partner))
      fail(springs, "partner", k, particle(s.particle),
           "the spring's partner id " + std::to_string(s.partner) +
               " is not a particle of the file");
    if (s.partner < 0 && static_cast<std::size_t>(-1 - s.partner) >= wall_columns)
      fail(springs, "partner", k, particle(s.particle),
           "the spring's partner " + std::to_string(s.partner) + " names wall history column " +
               std::to_string(-1 - s.partner) + ", but the scene's walls have " +
               std::to_string(wall_columns) + " (partner = -1 - column)");
    if (!s.tangential.allFinite())
      fail(springs, "tangential", k, particle(s.particle),
           "the tangential spring " + vec(s.tangential) + " is not finite");
    if (!s.rolling.allFinite())
      fail(springs, "rolling", k, particle(s.particle),
           "the rolling spring " + vec(s.rolling) + " is not finite");
  }
}

void check_restart_step(const Scene& scene, const CheckpointData& d) {
  // A step set by time.rayleigh_fraction is the checkpoint's too (the particles present may
  // give another one): the run's own fraction continues it; another one, or a fraction where
  // the run gave time.step, would be kept silently, so it is refused.
  // Only values their checksum vouches for (dt, rayleigh_fraction): a damaged one is named as
  // damage by Simulation::restore, not offered as the value to set.
  if (d.attributes_checksum_stored && d.attributes_checksum_stored != d.attributes_checksum_read)
    return;
  if (scene.time.rayleigh_fraction && d.rayleigh_fraction &&
      *scene.time.rayleigh_fraction != *d.rayleigh_fraction) {
    const std::string run = *d.rayleigh_fraction > 0
                                ? "time.rayleigh_fraction = " + number(*d.rayleigh_fraction)
                                : "time.step = " + number(d.dt) + " s";
    throw SetupError(
        scene.time.step_source + ": error: time.rayleigh_fraction = " +
        number(*scene.time.rayleigh_fraction) + ", but checkpoint '" + d.file +
        "' was written by a run with " + run + " (a step of " + number(d.dt) +
        " s), which a restart keeps (the snapshot, log and checkpoint series count its steps): "
        "set " +
        (*d.rayleigh_fraction > 0 ? "time.rayleigh_fraction to " + number(*d.rayleigh_fraction)
                                  : "time.step to " + number(d.dt)) +
        " to restart; for another step from this state on, start a new run from its last "
        "snapshot (insert `type: snapshot`, docs/scene-reference.md; contact springs start "
        "afresh)");
  }
  if (!scene.time.step || *scene.time.step == d.dt) return;
  throw SetupError(scene.time.step_source + ": error: time.step = " + number(*scene.time.step) +
                   " s, but checkpoint '" + d.file + "' was written with a step of " +
                   number(d.dt) +
                   " s, which a restart keeps (the snapshot, log and checkpoint series count its "
                   "steps): set time.step to " +
                   number(d.dt) +
                   " to restart; for another step from this state on, start a new run from its "
                   "last snapshot (insert `type: snapshot`, docs/scene-reference.md; contact "
                   "springs start afresh)");
}

}  // namespace grainflow
