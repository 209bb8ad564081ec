#include "dem/heat/thermal_limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "dem/core/number_format.hpp"
#include "dem/heat/heat_laws.hpp"
#include "dem/heat/heat_transfer.hpp"

namespace grainflow {

ThermalLimits check_thermal_limits(const Scene& scene, const Particles& p, TimeStepReport& rep) {
  ThermalLimits out;
  const double inf = std::numeric_limits<double>::infinity();
  out.conduction_time = out.convection_time = inf;
  const int nm = static_cast<int>(scene.materials.size());
  std::vector<double> r_min(nm, inf);
  for (std::size_t i = 0; i < p.size(); ++i)
    r_min[p.material[i]] = std::min(r_min[p.material[i]], p.radius[i]);
  for (const Insertion& ins : scene.insertions)
    if (ins.kind == Insertion::Kind::stream) {
      const SizeDistribution& s = ins.radius;
      const double r = s.kind == SizeDistribution::Kind::constant ? s.value
                       : s.kind == SizeDistribution::Kind::discrete
                           ? *std::min_element(s.values.begin(), s.values.end())
                           : s.min;
      r_min[ins.material] = std::min(r_min[ins.material], r);
    }
  const auto capacity = [&](int m) {
    return scene.materials[m].density * sphere_volume(r_min[m]) * scene.materials[m].heat_capacity;
  };
  const double overlap = scene.time.max_overlap;
  const std::vector<double> factor = contact_radius_factors(scene);  // a = f sqrt(R* delta)
  std::string where;
  bool wall_limited = false;  // the limit is a fixed-temperature wall's contact
  if (scene.heat->conduction && scene.contacts_possible)
    for (int a = 0; a < nm; ++a) {
      if (r_min[a] == inf) continue;
      const double ka = scene.materials[a].conductivity;
      for (int b = 0; b < nm; ++b) {
        if (r_min[b] == inf) continue;
        const double rs = r_min[a] * r_min[b] / (r_min[a] + r_min[b]);
        const double g = contact_conductance(
            effective_conductivity(ka, scene.materials[b].conductivity),
            factor[a * nm + b] * contact_radius(rs, overlap * std::min(r_min[a], r_min[b])));
        if (capacity(a) / g < out.conduction_time) {
          out.conduction_time = capacity(a) / g;
          where = "'" + scene.materials[a].name + "' on '" + scene.materials[b].name + "'";
        }
      }
      for (const Wall& w : scene.walls) {
        if (w.thermal.kind != WallThermal::Kind::temperature) continue;
        const double g = contact_conductance(
            effective_conductivity(ka, scene.materials[w.material].conductivity),
            factor[a * nm + w.material] * contact_radius(r_min[a], overlap * r_min[a]));
        if (capacity(a) / g < out.conduction_time) {
          out.conduction_time = capacity(a) / g;
          where = "'" + scene.materials[a].name + "' on wall '" + w.name + "'";
          wall_limited = true;
        }
      }
    }
  std::string smallest;
  if (scene.fluid && scene.fluid->thermal) {
    const Vec3 centre = 0.5 * (scene.domain.lo + scene.domain.hi);
    const double slip = scene.fluid->field.sample(centre, scene.gravity).velocity.norm();
    for (int a = 0; a < nm; ++a) {
      if (r_min[a] == inf) continue;
      // A parcel class: k^3 real particles of diameter 2 r / k (heat_laws.hpp).
      const double k = scene.materials[a].coarse_grain;
      const PrescribedFluid& f = scene.fluid->field;
      double h = parcel_convective_conductance(*scene.fluid->thermal, f.void_fraction, f.density,
                                               f.viscosity, 2 * r_min[a], k, slip);
      // eps computed from the particles: anywhere between its minimum and 1; the larger h.
      if (const auto& grid = scene.fluid->computed_void_fraction)
        for (const double eps : {grid->minimum, 1.0})
          h = std::max(h, parcel_convective_conductance(*scene.fluid->thermal, eps, f.density,
                                                        f.viscosity, 2 * r_min[a], k, slip));
      if (capacity(a) / h < out.convection_time) {
        out.convection_time = capacity(a) / h;
        smallest = scene.materials[a].name;
      }
    }
  }

  std::ostringstream o;
  o.precision(4);
  const double dt = rep.dt;
  const auto escalate = [&](TimeStepReport::Verdict v) {
    if (static_cast<int>(v) > static_cast<int>(rep.verdict)) rep.verdict = v;
  };
  if (out.conduction_time < inf) {
    const double limit = out.conduction_time / kThermalContacts;
    o << "heat conduction: time scale m c / (2 k* a) = " << out.conduction_time
      << " s through the stiffest contact (" << where << ", a at time.max_overlap = " << overlap
      << "); explicit, stable for dt <= tau / " << kThermalContacts << " = " << limit << " s";
    if (dt > 0) o << "; dt = " << dt / limit << " of that";
    rep.notes.push_back(o.str());
    o.str("");
    if (dt > limit) {
      rep.refuse_above(round_down_3(kWarnConductionFraction * limit));
      o << "error: dt = " << dt
        << " s is beyond the stability limit of heat conduction (dt <= " << limit
        << " s); use dt <= " << round_down_3(kWarnConductionFraction * limit) << " s";
      // A fixed-temperature wall needs conduction (the parser refuses it with `none`).
      if (wall_limited)
        o << " (the limit is the contact with that wall, whose fixed temperature reaches the "
             "particles by conduction; a wall with `heat_flux` instead has no such limit)";
      else
        o << ", or switch conduction off with `heat: {conduction: none}`";
      rep.notes.push_back(o.str());
      o.str("");
    } else if (dt > kWarnConductionFraction * limit) {
      escalate(TimeStepReport::Verdict::warn);
      o << "warning: dt is above " << kWarnConductionFraction
        << " of the stability limit of heat conduction; temperatures of densely packed "
           "particles will be inaccurate; dt <= "
        << round_down_3(kWarnConductionFraction * limit) << " s is recommended";
      rep.notes.push_back(o.str());
      o.str("");
    }
  } else if (!scene.heat->conduction) {
    rep.notes.push_back("heat conduction: off (heat.conduction: none)");
  }
  // Gunn (1978) fitted his Nusselt number for 0.35 <= eps <= 1: below, it is extrapolated.
  if (scene.fluid && scene.fluid->thermal && scene.fluid->thermal->nusselt == NusseltLaw::gunn) {
    const auto& grid = scene.fluid->computed_void_fraction;
    const double lowest = grid ? grid->minimum : scene.fluid->field.void_fraction;
    if (lowest < kGunnLowestVoidFraction) {
      escalate(TimeStepReport::Verdict::warn);
      o << "warning: Gunn's Nusselt number is fitted for " << kGunnLowestVoidFraction
        << " <= eps <= 1, and here eps "
        << (grid ? "computed from the particles may fall to its minimum " : "is ") << lowest
        << (grid ? " (fluid.void_fraction.minimum)" : " (fluid.void_fraction)") << ": below "
        << kGunnLowestVoidFraction << " the correlation is extrapolated"
        << (grid ? " (a random packing of spheres keeps eps above about 0.36)" : "");
      rep.notes.push_back(o.str());
      o.str("");
    }
  }
  if (out.convection_time < inf) {
    o << "heat convection: time scale m c / (h A) = " << out.convection_time
      << " s (smallest '" << smallest << "' particle at rest in the prescribed flow, "
      << (scene.fluid->thermal->nusselt == NusseltLaw::gunn ? "Gunn" : "Ranz-Marshall")
      << (scene.fluid->computed_void_fraction ? ", the larger h of eps = its minimum and 1" : "")
      << "); implicit, stable at any dt";
    if (dt > 0) o << "; dt / tau = " << dt / out.convection_time;
    rep.notes.push_back(o.str());
    o.str("");
    if (dt > kWarnConvectionFraction * out.convection_time) {
      escalate(TimeStepReport::Verdict::warn);
      o << "warning: dt is above " << kWarnConvectionFraction
        << " of the convection time scale: the implicit step lags the exponential by about "
        << 50 * dt / out.convection_time
        << " %; dt <= " << round_down_3(kWarnConvectionFraction * out.convection_time)
        << " s is recommended";
      rep.notes.push_back(o.str());
    }
  }
  return out;
}

}  // namespace grainflow
