#include "dem/engine/time_step.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <vector>

#include "dem/contact/normal_hooke.hpp"
#include "dem/core/number_format.hpp"
#include "dem/heat/thermal_limits.hpp"
#include "dem/insert/insertion.hpp"
#include "dem/walls/wall_travel.hpp"

namespace grainflow {

double rayleigh_time(const Material& m, double radius) {
  const double g = m.youngs_modulus / (2 * (1 + m.poisson_ratio));
  return std::numbers::pi * radius * std::sqrt(m.density / g) /
         (0.1631 * m.poisson_ratio + 0.8766);
}

double hertz_contact_time(double y_star, double r_star, double m_star, double speed) {
  return 2.868 * std::pow(m_star * m_star / (r_star * y_star * y_star * speed), 0.2);
}

double pair_contact_time(const ContactSettings& cs, const PairCoefficients& pc,
                         const ContactConstants& cc, double r_star, double m_star, double v) {
  if (cs.normal == NormalModel::hertz) return hertz_contact_time(pc.y_star, r_star, m_star, v);
  const SpringDashpot s = HookeNormal::coefficients(pc, cc, r_star, m_star, 0);
  const double w2 = s.kn / m_star - std::pow(s.gn / (2 * m_star), 2);
  return w2 > 0 ? std::numbers::pi / std::sqrt(w2) : std::numeric_limits<double>::infinity();
}

namespace {

struct PairImpact {
  std::string pair;
  double contact_time, restitution;
  double r_star = 0, m_star = 0, r_small = 0;  // the pair's, and the radius max_overlap is of
  const PairCoefficients* coefficients = nullptr;
};

// The peak overlap of a head-on impact at `v` over the elastic one's, by RK4 of the
// dimensionless contact (overlap in units of the elastic peak, time of that peak / v):
//   Hertz: x'' = -(5/4) x^(3/2) - 2.5 b x^(1/4) x'  (b: the dashpot factor hertz_beta),
//   Hooke: x'' = -x - 2 z x'  (z = g_n / (2 sqrt(k_n m*)), time in sqrt(m*/k_n)),
// from x = 0, x' = 1 to the turn (x' = 0). 1 without damping; independent of v.
struct ApproachPath {
  std::vector<double> x, u;  // from (0, 1); the last point is the turn (u = 0)
};
ApproachPath approach_path(bool hertz, double damping) {
  const auto accel = [&](double x, double u) {
    const double xp = std::max(x, 0.0);
    return hertz ? -1.25 * xp * std::sqrt(xp) - 2.5 * damping * std::sqrt(std::sqrt(xp)) * u
                 : -xp - 2 * damping * u;
  };
  ApproachPath path{{0}, {1}};
  double x = 0, u = 1;
  const double h = 1e-3;
  for (int k = 0; k < 100000 && u > 0; ++k) {
    const double k1x = u, k1u = accel(x, u);
    const double k2x = u + 0.5 * h * k1u, k2u = accel(x + 0.5 * h * k1x, u + 0.5 * h * k1u);
    const double k3x = u + 0.5 * h * k2u, k3u = accel(x + 0.5 * h * k2x, u + 0.5 * h * k2u);
    const double k4x = u + h * k3u, k4u = accel(x + h * k3x, u + h * k3u);
    const double x1 = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    const double u1 = u + h / 6 * (k1u + 2 * k2u + 2 * k3u + k4u);
    if (u1 <= 0) {
      path.x.push_back(x + (x1 - x) * u / (u - u1));  // the turn, between the two steps
      path.u.push_back(0);
      break;
    }
    x = x1;
    u = u1;
    path.x.push_back(x);
    path.u.push_back(u);
  }
  return path;
}

double peak_overlap_ratio(bool hertz, double damping) {
  return approach_path(hertz, damping).x.back();
}

}  // namespace

double damped_impact_speed(const ContactSettings& cs, const PairCoefficients& pc,
                           const ContactConstants& cc, double r_star, double m_star, double overlap,
                           double speed) {
  // The overlap unit: the elastic peak of an impact at V, A V^p (Hertz: A = (15 m* /
  // (16 Y* sqrt(R*)))^(2/5), p = 4/5; Hooke: A = sqrt(m*/k_n), p = 1).
  const bool hertz = cs.normal == NormalModel::hertz;
  double damping = pc.hertz_beta, a = 0, p = 1;
  if (hertz) {
    a = std::pow(15 * m_star / (16 * pc.y_star * std::sqrt(r_star)), 0.4);
    p = 0.8;
  } else {
    const SpringDashpot s = HookeNormal::coefficients(pc, cc, r_star, m_star, 0);
    a = std::sqrt(m_star / s.kn);
    damping = s.gn / (2 * std::sqrt(s.kn * m_star));
  }
  if (!(overlap > 0) || !(a > 0)) return std::max(speed, 0.0);
  // The dimensionless approach, u against x, from (0, 1) to the turn.
  const ApproachPath path = approach_path(hertz, damping);
  const std::vector<double>&xs = path.x, &us = path.u;
  const double x_peak = xs.back();
  // u on the approach at x (x rises monotonically until the turn).
  const auto u_at = [&](double x) {
    if (x >= x_peak) return 0.0;
    const std::size_t k =
        static_cast<std::size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin());
    const double t = (x - xs[k - 1]) / (xs[k] - xs[k - 1]);
    return us[k - 1] + t * (us[k] - us[k - 1]);
  };
  // The state (overlap, speed) lies on the path of the impact at V: u(overlap / (A V^p)) =
  // speed / V, rising in V from the impact whose damped peak is the overlap now.
  const double v0 = std::max(speed, 0.0);
  const auto miss = [&](double v) { return u_at(overlap / (a * std::pow(v, p))) - v0 / v; };
  double lo = std::pow(overlap / (a * x_peak), 1 / p), hi = 2 * lo;
  if (!(miss(lo) < 0)) return lo;
  for (int k = 0; k < 200 && miss(hi) < 0; ++k) hi *= 2;
  for (int k = 0; k < 100; ++k) {
    const double mid = 0.5 * (lo + hi);
    (miss(mid) < 0 ? lo : hi) = mid;
  }
  return hi;
}

namespace {

// The head-on impact speed above which the pair's peak overlap exceeds time.max_overlap of
// the smaller radius (the overlap guard's stop), with the pair's damping.
double overlap_guard_speed(const Scene& scene, const ContactConstants& cc, const PairImpact& im) {
  const double limit = scene.time.max_overlap * im.r_small;
  const PairCoefficients& pc = *im.coefficients;
  if (scene.contact.normal == NormalModel::hertz) {
    // Elastic peak d0 = (15 m* v^2 / (16 Y* sqrt(R*)))^(2/5), the damped one rho d0.
    const double d0 = limit / peak_overlap_ratio(true, pc.hertz_beta);
    return std::sqrt(16 * pc.y_star * std::sqrt(im.r_star) * std::pow(d0, 2.5) / (15 * im.m_star));
  }
  const SpringDashpot s = HookeNormal::coefficients(pc, cc, im.r_star, im.m_star, 0);
  const double zeta = s.gn / (2 * std::sqrt(s.kn * im.m_star));
  return limit / peak_overlap_ratio(false, zeta) * std::sqrt(s.kn / im.m_star);
}

// Where dt sits on the measured curve (time_step_accuracy.hpp), for the pair whose
// restitution suffers most (fewest steps per impact, lowest e).
void accuracy_note(const Scene& scene, TimeStepReport& rep,
                   const std::vector<PairImpact>& impacts) {
  const PairImpact* worst = nullptr;
  ImpactAccuracy acc;
  for (const PairImpact& im : impacts) {
    if (!std::isfinite(im.contact_time)) continue;
    const ImpactAccuracy a =
        impact_accuracy(scene.contact.normal, im.restitution, im.contact_time / rep.dt,
                        scene.contact.dashpot_velocity);
    if (!worst || a.restitution_rms > acc.restitution_rms) {
      worst = &im;
      acc = a;
    }
  }
  if (!worst) return;
  rep.accuracy = acc;
  // The contact time's error may be worst for another pair (fewer steps, another e).
  const PairImpact* worst_time = worst;
  double time_rms = acc.contact_time_rms;
  for (const PairImpact& im : impacts) {
    if (!std::isfinite(im.contact_time)) continue;
    const double rms = impact_accuracy(scene.contact.normal, im.restitution,
                                       im.contact_time / rep.dt, scene.contact.dashpot_velocity)
                           .contact_time_rms;
    if (rms > time_rms) {
      time_rms = rms;
      worst_time = &im;
    }
  }
  auto percent = [](double x) {
    std::ostringstream p;
    p.precision(2);
    p << 100 * x;
    return p.str();
  };
  std::ostringstream o;
  o.precision(3);
  o << "dt = ";
  if (std::isfinite(rep.rayleigh_time)) o << rep.dt / rep.rayleigh_time << " t_R, ";
  const char* about = acc.coarser_than_measured || acc.below_restitution > 0 ? " > " : " ≈ ";
  o << worst->contact_time / rep.dt << " steps per impact: restitution error" << about
    << percent(acc.restitution_rms) << " % (worst" << about << percent(acc.restitution_max)
    << " %), contact-time error" << about << percent(time_rms) << " %";
  if (worst_time != worst)
    o << " (" << worst_time->pair << ", " << worst_time->contact_time / rep.dt
      << " steps, e = " << worst_time->restitution << ")";
  o << " (" << worst->pair << " at " << scene.time.expected_max_speed
    << " m/s, e = " << worst->restitution;
  const auto [lo, hi] = measured_steps_per_impact(scene.contact.normal);
  if (acc.coarser_than_measured)
    o << "; fewer steps per impact than the measured minimum of " << lo;
  if (acc.below_restitution > 0)
    o << "; e is below the lowest measured restitution, " << acc.below_restitution
      << ": these are its errors, and a lower e has larger ones";
  else if (acc.extrapolated && !acc.coarser_than_measured)
    o << "; extrapolated beyond the measured " << lo << "-" << hi << " steps per impact";
  o << "; measured, docs/accuracy-vs-cost.md)";
  rep.notes.push_back(o.str());
  // Damped contacts with the default dashpots: what the second-order ones would give.
  if (scene.contact.dashpot_velocity == DashpotVelocity::half_step && worst->restitution < 1 &&
      !acc.coarser_than_measured) {
    const ImpactAccuracy p =
        impact_accuracy(scene.contact.normal, worst->restitution,
                        worst->contact_time / rep.dt, DashpotVelocity::predicted);
    std::ostringstream q;
    q << "with `contact: {dashpot_velocity: predicted}` (second order for damped contacts, "
         "about 2x the cost per step) the restitution error at this dt would be" << about
      << percent(p.restitution_rms) << " % and the contact-time error" << about
      << percent(p.contact_time_rms) << " % (docs/accuracy-vs-cost.md)";
    rep.notes.push_back(q.str());
  }
}

}  // namespace

TimeStepReport check_time_step(const Scene& scene, const Particles& p, const PairTable& table,
                               const ContactConstants& constants,
                               std::optional<double> restart_step) {
  TimeStepReport rep;
  const int nm = static_cast<int>(scene.materials.size());
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> r_min(nm, inf);
  for (std::size_t i = 0; i < p.size(); ++i)
    r_min[p.material[i]] = std::min(r_min[p.material[i]], p.radius[i]);
  // The particles streams will insert count as present: the step must resolve their contacts
  // too (a stream of smaller or softer particles than the fill's ran unresolved before).
  std::vector<std::string> streamed(nm);  // the stream whose particles set r_min, if one does
  for (const Insertion& ins : scene.insertions)
    if (ins.kind == Insertion::Kind::stream && min_radius(ins.radius) < r_min[ins.material]) {
      r_min[ins.material] = min_radius(ins.radius);
      streamed[ins.material] = ins.source;
    }

  rep.rayleigh_time = inf;
  std::string rayleigh_material;
  // A scene in which nothing can touch has no contact to resolve (its materials' elastic
  // constants may be left out): neither time applies.
  for (int m = 0; m < nm && scene.contacts_possible; ++m)
    if (r_min[m] < inf) {
      const double t = rayleigh_time(scene.materials[m], r_min[m]);
      if (t < rep.rayleigh_time) {
        rep.rayleigh_time = t;
        rayleigh_material = "'" + scene.materials[m].name + "' particle" +
                            (streamed[m].empty() ? "" : ", of the stream at " + streamed[m]);
      }
    }

  const double v = scene.time.expected_max_speed;
  rep.contact_time = inf;
  std::string contact_pair;
  std::vector<PairImpact> impacts;  // every pair present, for the accuracy estimate
  auto mass = [&](int m) { return scene.materials[m].density * sphere_volume(r_min[m]); };
  for (int a = 0; a < nm && scene.contacts_possible; ++a) {
    if (r_min[a] == inf) continue;
    for (int b = a; b < nm; ++b) {
      if (r_min[b] == inf) continue;
      const double rs = r_min[a] * r_min[b] / (r_min[a] + r_min[b]);
      const double ms = mass(a) * mass(b) / (mass(a) + mass(b));
      const double t = pair_contact_time(scene.contact, table(a, b), constants, rs, ms, v);
      const std::string name = scene.materials[a].name + "-" + scene.materials[b].name;
      impacts.push_back(
          {name, t, table(a, b).restitution, rs, ms, std::min(r_min[a], r_min[b]), &table(a, b)});
      if (t < rep.contact_time) {
        rep.contact_time = t;
        contact_pair = name;
      }
    }
    for (const Wall& w : scene.walls) {
      const double t =
          pair_contact_time(scene.contact, table(a, w.material), constants, r_min[a], mass(a), v);
      const std::string name = scene.materials[a].name + "-wall '" + w.name + "'";
      impacts.push_back({name, t, table(a, w.material).restitution, r_min[a], mass(a), r_min[a],
                         &table(a, w.material)});
      if (t < rep.contact_time) {
        rep.contact_time = t;
        contact_pair = name;
      }
    }
  }

  if (scene.time.step)
    rep.dt = *scene.time.step;
  else if (rep.rayleigh_time < inf)
    rep.dt = *scene.time.rayleigh_fraction * rep.rayleigh_time;
  const double scene_step = rep.dt;  // what the scene gives for the particles present
  if (restart_step) rep.dt = *restart_step;

  std::ostringstream o;
  o.precision(4);
  if (rep.rayleigh_time < inf) {
    o << "Rayleigh time t_R = " << rep.rayleigh_time << " s (smallest " << rayleigh_material << ")";
    rep.notes.push_back(o.str());
    o.str("");
  } else if (!scene.contacts_possible && p.size() > 0) {
    rep.notes.push_back(
        "no contact can happen (no walls, one particle): Rayleigh and contact times do not "
        "apply");
  } else {
    rep.notes.push_back("no particles: Rayleigh and contact times do not apply");
  }
  if (rep.contact_time < inf) {
    o << "contact time t_c = " << rep.contact_time << " s (" << contact_pair << ", "
      << (scene.contact.normal == NormalModel::hertz ? "Hertz" : "Hooke") << ", impact at " << v
      << " m/s)";
    rep.notes.push_back(o.str());
    o.str("");
  }
  if (rep.dt > 0) {
    o << "dt = " << rep.dt << " s";
    if (rep.rayleigh_time < inf) o << " = " << rep.dt / rep.rayleigh_time << " t_R";
    if (rep.contact_time < inf)
      o << " = t_c / " << rep.contact_time / rep.dt << " (" << rep.contact_time / rep.dt
        << " steps per impact)";
    if (restart_step) {
      o << ", the checkpoint's step, which the restart keeps";
      if (scene_step > 0 && scene_step != rep.dt)
        o << " (" << (scene.time.step ? "time.step" : "time.rayleigh_fraction") << " gives "
          << scene_step << " s for the particles present)";
    }
    rep.notes.push_back(o.str());
    o.str("");
    accuracy_note(scene, rep, impacts);
    // The travel guard (Simulation::fastest_particle): speed x dt above max_step_travel of a
    // particle's radius stops the run; the smallest particles set the lowest such speed.
    double r_smallest = inf;
    for (int m = 0; m < nm; ++m) r_smallest = std::min(r_smallest, r_min[m]);
    const double travel = scene.time.max_step_travel;
    if (travel > 0 && r_smallest < inf && scene.contacts_possible) {
      const double v_stop = travel * r_smallest / rep.dt;
      o << "travel guard: a particle that moves more than " << travel
        << " x its radius in one step stops the run (key time.max_step_travel): above " << v_stop
        << " m/s for the smallest, r = " << r_smallest << " m";
      if (v >= v_stop) o << "; warning: that is below time.expected_max_speed = " << v << " m/s";
      rep.notes.push_back(o.str());
      o.str("");
      if (v >= v_stop && rep.verdict == TimeStepReport::Verdict::ok)
        rep.verdict = TimeStepReport::Verdict::warn;
    }
    // The overlap guard (time.max_overlap): the slowest head-on impact that stops the run.
    const PairImpact* first_stop = nullptr;
    double v_overlap = inf;
    for (const PairImpact& im : impacts) {
      if (im.coefficients == nullptr || !std::isfinite(im.contact_time)) continue;
      const double s = overlap_guard_speed(scene, constants, im);
      if (s < v_overlap) {
        v_overlap = s;
        first_stop = &im;
      }
    }
    if (first_stop != nullptr) {
      o << "overlap guard: a head-on impact faster than " << v_overlap << " m/s ("
        << first_stop->pair << ", e = " << first_stop->restitution
        << ") overlaps by more than time.max_overlap = " << scene.time.max_overlap
        << " of the smaller radius and stops the run";
      if (v >= v_overlap)
        o << "; warning: that is below time.expected_max_speed = " << v
          << " m/s: raise time.max_overlap, or use a stiffer material (docs/stability.md)";
      rep.notes.push_back(o.str());
      o.str("");
      if (v >= v_overlap && rep.verdict == TimeStepReport::Verdict::ok)
        rep.verdict = TimeStepReport::Verdict::warn;
    }
    const double fr = rep.dt / rep.rayleigh_time;
    const double steps = rep.contact_time / rep.dt;
    // Rounded down: the printed step, set as written, is within both limits (rounded to
    // nearest it could be a hair above and draw the same warning again).
    rep.recommended_step = round_down_3(std::min(kWarnRayleighFraction * rep.rayleigh_time,
                                                 rep.contact_time / kWarnStepsPerContact));
    if (fr > kRefuseRayleighFraction || steps < kRefuseStepsPerContact) {
      rep.refuse_above(rep.recommended_step);
      o << "error: dt is too large to resolve contacts (limits: dt <= " << kRefuseRayleighFraction
        << " t_R and >= " << kRefuseStepsPerContact << " steps per impact); use dt <= " << rep.recommended_step
        << " s";
      rep.notes.push_back(o.str());
    } else if (fr > kWarnRayleighFraction || steps < kWarnStepsPerContact) {
      rep.verdict = TimeStepReport::Verdict::warn;
      o << "warning: "
        << (fr > kWarnRayleighFraction ? "dt is above " + std::to_string(kWarnRayleighFraction).substr(0, 3) + " t_R"
                                       : "fewer than " + std::to_string(int(kWarnStepsPerContact)) + " steps per impact")
        << "; contacts will be poorly resolved; dt <= " << rep.recommended_step
        << " s is recommended";
      rep.notes.push_back(o.str());
    }
  }
  if (scene.heat) check_thermal_limits(scene, p, rep);
  return rep;
}

}  // namespace grainflow
