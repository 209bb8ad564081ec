#include "dem/fluid/fluid_forces.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "dem/core/number_format.hpp"
#include "dem/fluid/beetstra.hpp"
#include "dem/fluid/di_felice.hpp"
#include "dem/fluid/drag_law.hpp"
#include "dem/fluid/ergun.hpp"
#include "dem/fluid/gidaspow.hpp"
#include "dem/fluid/koch_hill.hpp"
#include "dem/fluid/magnus_lift.hpp"
#include "dem/fluid/rong.hpp"
#include "dem/fluid/rotational_drag.hpp"
#include "dem/fluid/saffman_mei_lift.hpp"
#include "dem/fluid/schiller_naumann.hpp"
#include "dem/fluid/self_disturbance.hpp"
#include "dem/fluid/tenneti_garg_subramaniam.hpp"
#include "dem/fluid/void_fraction_grid.hpp"
#include "dem/fluid/volume_forces.hpp"
#include "dem/fluid/wen_yu.hpp"

namespace grainflow {
namespace {

std::string significant(double x) {
  std::ostringstream o;
  o.precision(4);
  o << x;
  return o.str();
}

struct Enabled {
  bool drag = false, pressure = false, viscous = false, buoyancy = false, virtual_mass = false,
       saffman = false, magnus = false, rotation = false;
};

template <DragFunction Law>
class FluidForcesWith final : public ForceTerm {
 public:
  FluidForcesWith(const FluidSettings& s, const Vec3& gravity, const Enabled& on,
                  const Domain& domain, MPI_Comm comm, std::shared_ptr<CoupledFluid> coupled)
      : s_(s), gravity_(gravity), on_(on), comm_(comm), coupled_(std::move(coupled)) {
    if (s.computed_void_fraction) grid_.emplace(domain, *s.computed_void_fraction);
    if (!s_.coarse_grain.empty()) coarse_ = s_.coarse_grain.data();
    const DragLaw& law = drag_law(s_.drag_law);
    fitted_reynolds_ = law.fitted_reynolds;
    reynolds_has_eps_ = !law.single_sphere_reynolds;
  }

  std::string name() const override { return "fluid forces (drag: " + s_.drag_law + ")"; }

  // Collective over comm_ (the beyond-range count is summed over the ranks).
  std::string report() const override {
    const std::string beyond = reynolds_report();
    std::string out = undisturbed_report();
    if (!beyond.empty()) out += (out.empty() ? "" : "\n") + beyond;
    return out;
  }

  // The drag law evaluated beyond the Reynolds number of its data (DragLaw::fitted_reynolds):
  // how often, how far, from when, and the laws whose data reach that far.
  std::string reynolds_report() const {
    double n[3] = {static_cast<double>(beyond_steps_), static_cast<double>(drag_steps_), 0};
    double largest = beyond_largest_, first = beyond_first_;
    if (comm_ != MPI_COMM_NULL) {
      MPI_Allreduce(MPI_IN_PLACE, n, 2, MPI_DOUBLE, MPI_SUM, comm_);
      MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_DOUBLE, MPI_MAX, comm_);
      MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_DOUBLE, MPI_MIN, comm_);
    }
    if (n[0] == 0) return {};
    const DragLaw& law = drag_law(s_.drag_law);
    std::string reaching;
    // Laws for beds (not the single sphere's) with a known bound that covers the largest Re.
    for (const DragLaw& other : drag_laws())
      if (other.fitted_reynolds >= largest && std::isfinite(other.fitted_reynolds) &&
          !other.single_sphere_reynolds && std::string_view(other.name) != law.name)
        reaching += (reaching.empty() ? "" : ", ") + std::string(other.name);
    std::ostringstream o;
    o << s_.source << ": warning: fluid.drag: " << law.name
      << " was evaluated beyond the Re = " << significant(law.fitted_reynolds) << " of its data ("
      << law.fitted_range << ") in " << static_cast<long long>(n[0]) << " of "
      << static_cast<long long>(n[1]) << " particle-steps, from t = " << significant(first)
      << " s, up to Re = " << significant(largest) << " (Re = rho_f "
      << (law.single_sphere_reynolds ? "" : "eps ") << "d |u_f - v| / mu, of the real particles)";
    if (!reaching.empty()) o << "; laws whose data reach that Re: " << reaching;
    o << " (docs/models/fluid-forces.md, \"Validity\")";
    return o.str();
  }

  std::string undisturbed_report() const {
    if (undisturbed_calls_ > 0) {
      std::string out = "undisturbed velocity: the drag of " + std::to_string(undisturbed_calls_) +
                        " particle-steps raised by a mean factor of " +
                        significant(undisturbed_sum_ / undisturbed_calls_) + " (largest " +
                        significant(undisturbed_max_) + ")";
      if (undisturbed_limited_ > 0)
        out += "; " + std::to_string(undisturbed_limited_) +
               " particle-steps held at the largest factor 1/(1 - " + significant(max_km) +
               ") (the particle's own disturbance as large as its slip: cells too small for "
               "the particle, docs/models/undisturbed-velocity.md)";
      if (!grid_) return out;
      return out + "\n" + grid_report();
    }
    return grid_ ? grid_report() : std::string{};
  }

  std::string grid_report() const {
    return "void fraction: " + std::to_string(grid_->cells()[0]) + " x " +
           std::to_string(grid_->cells()[1]) + " x " + std::to_string(grid_->cells()[2]) +
           " cells; clamped to the minimum " + std::to_string(grid_->clamped_cells_total()) +
           " times (cell-steps), removing " + significant(grid_->clamped_volume_total()) +
           " m^3 of solid volume in total";
  }

  bool implicit_spin() const override { return on_.rotation; }
  const VoidFractionGrid* void_fraction_grid() const override {
    return grid_ ? &*grid_ : nullptr;
  }

  // The lift's step limit: the slip it turns in one step (explicit_lift_limit), and the
  // particle it carries across the shear G, whose fluid velocity there changes the slip by
  // G times the displacement: a spring of rate sqrt(G / tau_l) in the position, which the
  // velocity Verlet step holds for dt < 2 / that rate (a Magnus lift at G = 300/s, tau_l =
  // 0.022 s, blew up at 0.02 s and 0.04 s, which the first limit alone, 0.044 s, allowed).
  static double lift_step_limit(double tau_l, double tau_d, double shear_rate) {
    const double turn = explicit_lift_limit(tau_l, tau_d);
    if (!(shear_rate > 0)) return turn;
    return std::min(turn, 2 / std::sqrt(shear_rate / tau_l));
  }

  std::vector<TermLimit> limits(const Particles& p, double /*time*/) const override {
    constexpr double inf = std::numeric_limits<double>::infinity();
    std::vector<TermLimit> out;
    TermLimit drag{"drag", "m/K (Stokes: rho_p d^2/(18 mu f))",         inf, -1, true,
                   inf,    "implicit in the velocity: stable at any dt"};
    TermLimit spin{"rotational_drag",
                   "I/K_r (Stokes: rho_p d^2/(60 mu))",
                   inf,
                   -1,
                   true,
                   inf,
                   "implicit in the spin: stable at any dt"};
    TermLimit saffman{
        "saffman_mei", "m/K_L, K_L = 1.615 d^2 sqrt(rho_f mu |curl u|) f", inf, -1, false, inf, ""};
    TermLimit magnus{
        "magnus", "m/K_M, K_M = (pi/8) d^3 rho_f |Omega| (Re_p/Re_r) C_LR", inf, -1, false, inf,
        ""};
    // The drag time scale of the particle with each lift's shortest time scale.
    double saffman_drag = inf, magnus_drag = inf;
    CoupledFluid::View samples;
    if (coupled_) samples = coupled_->at_particles(p);
    for (std::size_t i = 0; i < p.size(); ++i) {
      FluidSample f = coupled_ ? coupled_->sample(samples, i) : s_.field.sample(p.x[i], gravity_);
      if (grid_) f.void_fraction = grid_->at(p.x[i]);
      const double d = 2 * p.radius[i];
      const Vec3 slip = f.velocity - p.v[i];
      const double u = slip.norm();
      const double cg = coarse_ ? coarse_[p.material[i]] : 1.0;
      const double k =
          cg * cg * cg * Law({d / cg, u, f.void_fraction, f.density, f.viscosity});
      const double tau_d = k > 0 ? p.mass[i] / k : inf;
      if (tau_d < drag.tau)
        drag = {drag.term, drag.time_scale, tau_d, p.id[i], true, inf, drag.rule};
      const Vec3 relative_rotation = 0.5 * f.vorticity - p.omega[i];
      if (on_.rotation) {
        const double kr =
            rotational_drag_coefficient(d, f.density, f.viscosity, relative_rotation.norm());
        const double tau = kr > 0 ? p.inertia[i] / kr : inf;
        if (tau < spin.tau) spin = {spin.term, spin.time_scale, tau, p.id[i], true, inf, spin.rule};
      }
      const double w = f.vorticity.norm();
      if (on_.saffman && w > 0) {
        const double re_p = f.density * d * u / f.viscosity;
        const double re_s = f.density * d * d * w / f.viscosity;
        const double kl = 1.615 * d * d * std::sqrt(f.density * f.viscosity * w) *
                          saffman_mei_correction(re_p, re_s);
        const double tau = p.mass[i] / kl;
        if (tau < saffman.tau) {
          saffman.tau = tau;
          saffman.particle = p.id[i];
          saffman_drag = tau_d;
        }
        saffman.dt_max = std::min(saffman.dt_max, lift_step_limit(tau, tau_d, w));
      }
      const double wr = relative_rotation.norm();
      if (on_.magnus && wr > 0) {
        const double re_p = f.density * d * u / f.viscosity;
        const double re_r = f.density * d * d * wr / f.viscosity;
        const double km =
            std::numbers::pi / 8 * d * d * d * f.density * wr * magnus_factor(re_p, re_r);
        const double tau = p.mass[i] / km;
        if (tau < magnus.tau) {
          magnus.tau = tau;
          magnus.particle = p.id[i];
          magnus_drag = tau_d;
        }
        magnus.dt_max = std::min(magnus.dt_max, lift_step_limit(tau, tau_d, w));
      }
    }
    if (on_.drag) out.push_back(drag);
    if (on_.rotation) out.push_back(spin);
    for (auto [lift, tau_d] :
         {std::pair{&saffman, saffman_drag}, std::pair{&magnus, magnus_drag}}) {
      if (lift == &saffman ? !on_.saffman : !on_.magnus) continue;
      // dt_max: the least over the particles, each with its own drag time scale.
      if (!(lift->tau < inf))
        lift->rule = "no shear or rotation at the particles now: no limit yet";
      else if (lift->dt_max == inf)
        lift->rule =
            "explicit; weaker than the implicit drag (tau_L >= tau_d = " + significant(tau_d) +
            " s): stable at any dt";
      else
        lift->rule = "explicit; stable while sqrt(1 + (dt/tau_L)^2) <= 1 + dt/tau_d, tau_d = " +
                     significant(tau_d) +
                     " s, and dt < 2 sqrt(tau_L/G) (it carries the particle across the shear "
                     "G = |curl u|)";
      out.push_back(*lift);
    }
    const auto no_limit = [&](bool on, const char* name, const char* why) {
      if (on) out.push_back({name, "none", inf, -1, true, inf, why});
    };
    no_limit(on_.pressure, "pressure_gradient", "independent of the particle's velocity: no limit");
    no_limit(on_.viscous, "viscous", "independent of the particle's velocity: no limit");
    no_limit(on_.buoyancy, "buoyancy", "constant: no limit");
    no_limit(on_.virtual_mass, "virtual_mass",
             "solved within the particle's equation (added mass): no limit");
    return out;
  }

  void add(Particles& p, double time, ImplicitDrag& drag) override {
    if (grid_) grid_->update(p, comm_);
    CoupledFluid::View samples;
    if (coupled_) {
      samples = coupled_->at_particles(p);
      coupled_->exchange_force.assign(p.size(), Vec3::Zero());
    }
    const bool b = s_.model == VansModel::B;
    for (std::size_t i = 0; i < p.size(); ++i) {
      FluidSample f =
          coupled_ ? coupled_->sample(samples, i) : s_.field.sample(p.x[i], gravity_);
      if (grid_) f.void_fraction = grid_->at(p.x[i]);
      double d = 2 * p.radius[i];
      const double volume = sphere_volume(p.radius[i]);
      const Vec3 slip = f.velocity - p.v[i];
      Vec3 force = Vec3::Zero(), carried = Vec3::Zero();
      if (on_.drag) {
        // A parcel (coarse graining): the real particle's drag, times the k^3 it stands for.
        double parcel = 1;
        if (coarse_) {
          const double cg = coarse_[p.material[i]];
          d /= cg;
          parcel = cg * cg * cg;
        }
        const double u = slip.norm();
        double k = Law({d, u, f.void_fraction, f.density, f.viscosity});
        if (coarse_) k *= parcel;
        // Beyond the law's data? (Re > bound, written without a division; never for ergun.)
        ++drag_steps_;
        if (f.density * d * u * (reynolds_has_eps_ ? f.void_fraction : 1) >
            fitted_reynolds_ * f.viscosity)
          note_beyond_fit(
              f.density * d * u * (reynolds_has_eps_ ? f.void_fraction : 1) / f.viscosity, time);
        if (samples.disturbance && samples.disturbance[i].cell > 0)
          k *= undisturbed(samples.disturbance[i], d, slip, f);
        const double k_sum = drag.coefficient[i] + k;
        if (k_sum > 0)
          drag.fluid_velocity[i] =
              (drag.coefficient[i] * drag.fluid_velocity[i] + k * f.velocity) / k_sum;
        drag.coefficient[i] = k_sum;
      }
      if (on_.pressure) force += pressure_gradient_force(volume, f.pressure_gradient);
      if (on_.viscous) force += viscous_force(volume, f.viscous_stress_divergence);
      // Model B returns the pressure and viscous forces to the fluid. Buoyancy is not
      // returned: the coupled solver's pressure excludes hydrostatics, and in model B its
      // momentum equation would then carry -(1-eps) rho_f g, which the returned
      // buoyancy cancels exactly; both are left out (foam_solver/grainFoam/grainFoam.C).
      if (b) carried = force;
      if (on_.buoyancy) force += archimedes_buoyancy(f.density, volume, gravity_);
      if (on_.saffman) {
        const Vec3 lift = saffman_mei_lift(d, f.density, f.viscosity, slip, f.vorticity);
        force += lift;
        carried += lift;
      }
      if (on_.magnus || on_.rotation) {
        const Vec3 relative_rotation = 0.5 * f.vorticity - p.omega[i];
        if (on_.magnus) {
          const Vec3 lift = magnus_lift(d, f.density, f.viscosity, slip, relative_rotation);
          force += lift;
          carried += lift;
        }
        if (on_.rotation) {
          // Implicit in the spin (ImplicitDrag): K_r at this step's relative rotation.
          const double kr =
              rotational_drag_coefficient(d, f.density, f.viscosity, relative_rotation.norm());
          const double kr_sum = drag.spin_coefficient[i] + kr;
          if (kr_sum > 0)
            drag.fluid_spin[i] =
                (drag.spin_coefficient[i] * drag.fluid_spin[i] + kr * 0.5 * f.vorticity) / kr_sum;
          drag.spin_coefficient[i] = kr_sum;
        }
      }
      p.force[i] += force;
      if (coupled_) coupled_->exchange_force[i] = carried;
      if (on_.virtual_mass) {
        double scale = 1;
        p.force[i] += virtual_mass_closure(s_.virtual_mass_coefficient * f.density * volume,
                                           p.mass[i], p.force[i], f.material_derivative, scale);
        drag.coefficient[i] *= scale;
      }
      // sampling cellPoint: the fluid's implicit exchange takes K (v - U_fp) at the
      // footprint's cells; the drag's remainder K (u_f - U_fp) goes back explicitly.
      if (samples.cell_velocity && drag.coefficient[i] > 0)
        coupled_->exchange_force[i] +=
            drag.coefficient[i] * (drag.fluid_velocity[i] - samples.cell_velocity[i]);
    }
  }

 private:
  // The particle's own disturbance of the sampled velocity (self_disturbance.hpp): the factor
  // 1/(1 - k m) by which the drag on the seen slip grows, so that the force is the drag law's
  // at the undisturbed slip, with m the mobility of the particle's disturbance on its cells'
  // lattice. The momentum equation of the disturbance has the viscosity c mu (c = eps in
  // model A, 1 in model B) and the advecting density eps rho.
  // The disturbance's transverse factor is that of the particle's own weights on the two mesh
  // axes across the motion, the motion's axis being the one most aligned with the slip.
  double undisturbed(const SelfDisturbance& sd, double d, const Vec3& slip, const FluidSample& f) {
    const double w_seen = slip.norm();
    const std::array<double, 3>*ax = nullptr, *ay = nullptr;
    int along = 2;
    if (sd.placed) {
      const Vec3 a = slip.cwiseAbs();
      along = a[0] >= a[1] ? (a[0] >= a[2] ? 0 : 2) : (a[1] >= a[2] ? 1 : 2);
      ax = &sd.transverse[(along + 1) % 3];
      ay = &sd.transverse[(along + 2) % 3];
    }
    const double mu_e = (s_.model == VansModel::A ? f.void_fraction : 1.0) * f.viscosity;
    const double rho_e = f.void_fraction * f.density;
    const double eps = f.void_fraction;
    const auto k = [&](double w) { return Law({d, w, eps, f.density, f.viscosity}); };
    const auto m = [&](double w) {
      if (ax && sd.cell_point && sd.cell_point_reads_set)
        return lattice_self_mobility_cellpoint(sd.cell, sd.spread, w, rho_e, mu_e, sd.screening,
                                               sd.cell_point_reads[along], sd.smoothing);
      if (ax && sd.cell_point) {
        const int ta = (along + 1) % 3, tb = (along + 2) % 3;
        return lattice_self_mobility_cellpoint(sd.cell, sd.spread, w, rho_e, mu_e, sd.screening,
                                               sd.place[ta], sd.place[tb], sd.marginals[ta],
                                               sd.marginals[tb], sd.smoothing);
      }
      return lattice_self_mobility(sd.cell, sd.spread, w, rho_e, mu_e, sd.screening, ax, ay,
                                   sd.smoothing);
    };
    bool limited = false;
    const double k0 = k(w_seen);
    const double factor = undisturbed_factor(w_seen, k, m, max_km, limited);
    // The law at the undisturbed slip, relative to the law at the seen slip (the caller's k).
    const double w = w_seen * factor;
    const double ratio = k0 > 0 ? k(w) * factor / k0 : factor;
    ++undisturbed_calls_;
    undisturbed_sum_ += ratio;
    undisturbed_max_ = std::max(undisturbed_max_, ratio);
    if (limited) ++undisturbed_limited_;
    return ratio;
  }
  // Beyond k m = 0.8 the particle's own disturbance would be four times its seen slip: the
  // estimate is then an extrapolation of the model far outside where it was checked.
  static constexpr double max_km = 0.8;
  long undisturbed_calls_ = 0, undisturbed_limited_ = 0;
  double undisturbed_sum_ = 0, undisturbed_max_ = 0;

  void note_beyond_fit(double re, double time) {
    if (beyond_steps_++ == 0) beyond_first_ = time;
    beyond_largest_ = std::max(beyond_largest_, re);
  }
  double fitted_reynolds_ = std::numeric_limits<double>::infinity();
  bool reynolds_has_eps_ = true;
  long long drag_steps_ = 0, beyond_steps_ = 0;
  double beyond_largest_ = 0, beyond_first_ = std::numeric_limits<double>::infinity();

  FluidSettings s_;
  // Each material's coarse-graining factor (FluidSettings::coarse_grain); null: all k = 1.
  const double* coarse_ = nullptr;
  Vec3 gravity_;
  Enabled on_;
  MPI_Comm comm_;
  std::optional<VoidFractionGrid> grid_;
  std::shared_ptr<CoupledFluid> coupled_;  // two-way mode
};

// One compiled particle loop per law: the registry's function pointer picks the
// instantiation whose template argument is that same function.
template <DragFunction... Laws>
std::unique_ptr<ForceTerm> instantiate(DragFunction chosen, const FluidSettings& s, const Vec3& g,
                                       const Enabled& on, const Domain& domain, MPI_Comm comm,
                                       const std::shared_ptr<CoupledFluid>& coupled) {
  std::unique_ptr<ForceTerm> out;
  ((out == nullptr && chosen == Laws
        ? (out = std::make_unique<FluidForcesWith<Laws>>(s, g, on, domain, comm, coupled), 0)
        : 0),
   ...);
  return out;
}

std::unique_ptr<ForceTerm> make_term(const FluidSettings& s, const Vec3& gravity,
                                     const Domain& domain, MPI_Comm comm,
                                     const std::shared_ptr<CoupledFluid>& coupled) {
  check_force_list(s.forces, {s.model, s.field.hydrostatic_pressure, gravity.norm() > 0});
  Enabled on;
  for (FluidForce f : s.forces) {
    switch (f) {
      case FluidForce::drag: on.drag = true; break;
      case FluidForce::pressure_gradient: on.pressure = true; break;
      case FluidForce::viscous: on.viscous = true; break;
      case FluidForce::buoyancy: on.buoyancy = true; break;
      case FluidForce::virtual_mass: on.virtual_mass = true; break;
      case FluidForce::saffman_mei: on.saffman = true; break;
      case FluidForce::magnus: on.magnus = true; break;
      case FluidForce::rotational_drag: on.rotation = true; break;
    }
  }
  const DragLaw& law = drag_law(s.drag_law);
  std::unique_ptr<ForceTerm> term =
      instantiate<schiller_naumann, di_felice, rong, wen_yu, ergun, gidaspow, koch_hill, beetstra,
                  tenneti_garg_subramaniam>(law.function, s, gravity, on, domain, comm, coupled);
  if (term == nullptr)
    throw std::logic_error(std::string("drag law '") + law.name +
                           "' is registered but not instantiated in fluid_forces.cpp");
  return term;
}

}  // namespace

std::unique_ptr<ForceTerm> make_fluid_forces(const FluidSettings& s, const Vec3& gravity,
                                             const Domain& domain, MPI_Comm comm) {
  return make_term(s, gravity, domain, comm, nullptr);
}

std::unique_ptr<ForceTerm> make_coupled_fluid_forces(const FluidSettings& settings,
                                                     const Vec3& gravity,
                                                     std::shared_ptr<CoupledFluid> coupled,
                                                     MPI_Comm comm) {
  if (coupled == nullptr) throw std::invalid_argument("make_coupled_fluid_forces: no CoupledFluid");
  for (FluidForce f : settings.forces)
    if (f == FluidForce::virtual_mass)
      throw std::invalid_argument(
          "virtual_mass is not available in coupled runs yet (the coupling does not sample the "
          "fluid's material derivative Du/Dt); remove it from fluid.forces");
  FluidSettings s = settings;
  s.computed_void_fraction.reset();        // the coupling computes eps on the mesh
  s.field.hydrostatic_pressure = false;    // the solver's p excludes rho_f g.x
  return make_term(s, gravity, Domain{}, comm, coupled);
}

}  // namespace grainflow
