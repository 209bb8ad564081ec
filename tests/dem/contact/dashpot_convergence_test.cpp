// The order in dt of the tangential and EPSD rolling dashpots and of pair impacts, with
// `contact.dashpot_velocity: predicted` and with the default (half_step).
// (damped_impact_convergence_test.cpp covers the normal dashpot in sphere-wall impacts.)
//
// References, all independent of the DEM code:
// - Tangential dashpot in a lasting contact: a sphere resting on a plane (gravity, Hooke
//   normal at its equilibrium overlap d0 = m g / k_n, so the lever arm a = R - d0 is
//   constant) with an initial sliding speed v0 and a friction coefficient so large that it
//   sticks. The contact point's tangential velocity v_t = v_x - a w_y and the spring xi obey
//   m_eff xi'' + gamma_t xi' + k_t xi = 0, xi(0) = 0, xi'(0) = v0, with
//   1/m_eff = 1/m + a^2/I (m_eff ~ (2/7) m): a damped linear oscillator in closed form.
// - EPSD rolling dashpot: a frictionless sphere resting on the plane, spinning about a
//   horizontal axis at w0: the rolling spring M_k' = -k_r w and M = M_k - C_r w give
//   I theta'' + C_r theta' + k_r theta = 0, w = theta', with k_r, C_r of rolling.hpp
//   (Ai et al. 2011, model C); the spring stays below M_max = mu_r R m g.
// - Oblique impacts that stick (Hooke and Hertz, sphere-wall and pair): a friction
//   coefficient so large that the Coulomb limit acts only where F_n <= 0 (the attractive end
//   of a damped contact: there F_t = 0 from then on). The normal and tangential motion
//   (spring xi' = v_t, F_t = -k_t xi - gamma_t v_t, the lever arms R - d or R - d/2) are
//   integrated here with RK4 (40000 steps per contact time, the cut located by bisection); for
//   the pair in the plane of the motion, since the line of centres turns. The rebound's v_t is
//   compared (oblique_reference, oblique_pair_reference).
// - Pair impacts: two equal spheres head-on, Hooke and Hertz, the references of
//   damped_impact_convergence_test.cpp with m* = m/2 and R* = R/2.
//
// The damping of each case is set so that the oscillator the dashpot acts in has the
// "restitution" e_t = exp(-zeta pi / sqrt(1 - zeta^2)) = 0.9, 0.5 and 0.1.
// Steps per impact N: the half period pi / omega_d of that oscillator over dt. Lasting
// contacts are sampled at four times (N/2 ... 2N steps); impacts take the rms over 32 impacts
// (8 first-touch offsets x 4 contact lengths), as damped_impact_convergence_test.cpp.
// The slope is log2 of the error at N = 20 over that at N = 40. With GRAINFLOW_DASHPOT_SWEEP=1
// each test also prints both schemes' errors from N = 5 to 80 (for the docs).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "dem/engine/simulation.hpp"
#include "dem/contact/restitution_mapping.hpp"
#include "dem/engine/time_step.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kR = 1e-3, kRho = 2500, kY = 5e7, kNu = 0.25, kG = 9.81;
const double kMass = kRho * sphere_volume(kR);
const double kInertia = 0.4 * kMass * kR * kR;

// zeta of a damped linear oscillator of restitution e, and the inverse.
double zeta_of(double e) { return 1.0 / std::sqrt(1 + std::pow(kPi / std::log(e), 2)); }
double restitution_of(double zeta) { return std::exp(-zeta * kPi / std::sqrt(1 - zeta * zeta)); }

// xi(t) and xi'(t) of m xi'' + c xi' + k xi = 0, xi(0) = 0, xi'(0) = v0 (underdamped).
struct Oscillator {
  double alpha, omega_d, v0;
  Oscillator(double m, double c, double k, double v) : alpha(c / (2 * m)), v0(v) {
    omega_d = std::sqrt(k / m - alpha * alpha);
  }
  double position(double t) const {
    return v0 / omega_d * std::exp(-alpha * t) * std::sin(omega_d * t);
  }
  double velocity(double t) const {
    return v0 * std::exp(-alpha * t) *
           (std::cos(omega_d * t) - alpha / omega_d * std::sin(omega_d * t));
  }
  double half_period() const { return kPi / omega_d; }
};

bool sweep_requested() { return std::getenv("GRAINFLOW_DASHPOT_SWEEP") != nullptr; }

const char* scheme_name(DashpotVelocity d) {
  return d == DashpotVelocity::predicted ? "predicted" : "half_step";
}

// Prints err(N) for both schemes from 5 to 80 steps per impact, with the local slopes.
void print_sweep(const char* what, const std::function<double(DashpotVelocity, double)>& err) {
  if (!sweep_requested()) return;
  for (DashpotVelocity d : {DashpotVelocity::half_step, DashpotVelocity::predicted}) {
    std::printf("sweep %s %s:", what, scheme_name(d));
    double prev = 0;
    for (double n : {5.0, 10.0, 20.0, 40.0, 80.0}) {
      const double e = err(d, n);
      if (prev > 0)
        std::printf(" N=%g %.2e (slope %.2f)", n, e, std::log2(prev / e));
      else
        std::printf(" N=%g %.2e", n, e);
      prev = e;
    }
    std::printf("\n");
  }
}

Scene resting_scene(DashpotVelocity d, double restitution, double friction, double mu_r) {
  Scene s = test::one_material_scene(kY, kNu, kRho, restitution, friction, mu_r);
  s.contact.normal = NormalModel::hooke;
  s.contact.hooke_kn = 1e3;
  s.contact.hooke_kt = 1e3;
  s.contact.dashpot_velocity = d;
  s.gravity = Vec3(0, 0, -kG);
  s.domain.lo = Vec3(-0.01, -0.01, -0.01);
  s.domain.hi = Vec3(0.01, 0.01, 0.01);
  s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitZ()));
  return s;
}

// ---------------------------------------------------------------------------------------
// Tangential dashpot, lasting contact.
struct LastingCase {
  double e;  // restitution of the oscillator the dashpot acts in
};

// The rms over the four sample times of |v_t - reference| / v0.
double tangential_lasting_error(DashpotVelocity d, double e_t, double steps) {
  const double kn = 1e3, kt = 1e3, d0 = kMass * kG / kn, a = kR - d0;
  const double m_eff = 1.0 / (1.0 / kMass + a * a / kInertia);
  // gamma_t = sqrt(4 m k_t) * beta with beta = 1/sqrt(1 + (pi/ln e)^2) of the pair's e
  // (normal_hooke.hpp): choose e so that zeta_t = gamma_t / (2 sqrt(m_eff k_t)) = zeta(e_t).
  const double beta = zeta_of(e_t) * std::sqrt(m_eff / kMass);
  const double gt = std::sqrt(4 * kMass * kt) * beta;
  const double v0 = 1e-6;
  const Oscillator ref(m_eff, gt, kt, v0);
  Scene s = resting_scene(d, restitution_of(beta), 1e3, 0);
  s.contact.tangential = TangentialModel::history;
  Simulation sim(s, false);
  sim.particles().add(1, Vec3(0, 0, kR - d0), Vec3::Zero(), Vec3::Zero(), kR, 0, kRho);
  const double dt = ref.half_period() / steps;
  sim.set_dt(dt);
  // initialise() evaluates the contact forces of t = 0, which advances a spring by
  // v(0) dt as if a step had been made: at rest it stays zero. Then the initial velocity and
  // its force and torque at t = 0 (xi = 0: the dashpot alone, F_t = -gamma_t v0, torque
  // -a n x F_t), so that the integration starts from the reference's initial state.
  sim.initialise();
  Particles& p = sim.particles();
  p.v[0] = Vec3(v0, 0, 0);
  p.force[0][0] = -gt * v0;
  p.torque[0] = Vec3(0, -a * (-gt * v0), 0);
  const long n = std::lround(steps);
  double se = 0;
  long done = 0;
  for (int k = 1; k <= 4; ++k) {
    const long target = k * n / 2;
    for (; done < target; ++done) sim.step();
    const double vt = p.v[0][0] - a * p.omega[0][1];
    se += std::pow((vt - ref.velocity(done * dt)) / v0, 2);
  }
  return std::sqrt(se / 4);
}

// ---------------------------------------------------------------------------------------
// EPSD rolling dashpot, lasting contact.
double rolling_lasting_error(DashpotVelocity d, double e_r, double steps) {
  const double kn = 1e3, mu_r = 0.1;
  const double kr = 2.25 * kn * mu_r * mu_r * kR * kR;  // rolling.hpp, R* = R for a wall
  const double i_r = kInertia + kMass * kR * kR;         // the rolling inertia C_r is scaled by
  // zeta_r = C_r / (2 sqrt(I k_r)) = eta sqrt(I_r / I): choose eta so that zeta_r = zeta(e_r).
  const double eta = zeta_of(e_r) * std::sqrt(kInertia / i_r);
  const double cr = eta * 2 * std::sqrt(i_r * kr);
  const double w0 = 1e-3;
  const Oscillator ref(kInertia, cr, kr, w0);
  // The spring's largest torque, about sqrt(k_r I) w0, stays far below M_max = mu_r R m g.
  EXPECT_LT(std::sqrt(kr * kInertia) * w0, 1e-2 * mu_r * kR * kMass * kG);
  Scene s = resting_scene(d, 0.5, 0, mu_r);
  s.contact.tangential = TangentialModel::none;
  s.contact.rolling = RollingModel::epsd;
  s.contact.epsd_damping_ratio = eta;
  Simulation sim(s, false);
  sim.particles().add(1, Vec3(0, 0, kR - kMass * kG / kn), Vec3::Zero(), Vec3::Zero(), kR, 0,
                      kRho);
  const double dt = ref.half_period() / steps;
  sim.set_dt(dt);
  // As for the tangential case: initialise() at rest (the spring stays zero), then the spin
  // and its torque at t = 0, the dashpot's -C_r w0.
  sim.initialise();
  sim.particles().omega[0] = Vec3(0, w0, 0);
  sim.particles().torque[0] = Vec3(0, -cr * w0, 0);
  const long n = std::lround(steps);
  double se = 0;
  long done = 0;
  for (int k = 1; k <= 4; ++k) {
    const long target = k * n / 2;
    for (; done < target; ++done) sim.step();
    se += std::pow((sim.particles().omega[0][1] - ref.velocity(done * dt)) / w0, 2);
  }
  return std::sqrt(se / 4);
}

struct SchemeCase {
  DashpotVelocity scheme;
  double e;
};

std::string scheme_case_name(const ::testing::TestParamInfo<SchemeCase>& info) {
  return std::string(info.param.scheme == DashpotVelocity::predicted ? "Predicted" : "HalfStep") +
         "_e0" + std::to_string(static_cast<int>(info.param.e * 10 + 0.5));
}

const auto kSchemeCases = ::testing::Values(
    SchemeCase{DashpotVelocity::predicted, 0.9}, SchemeCase{DashpotVelocity::predicted, 0.5},
    SchemeCase{DashpotVelocity::predicted, 0.1}, SchemeCase{DashpotVelocity::half_step, 0.9},
    SchemeCase{DashpotVelocity::half_step, 0.5}, SchemeCase{DashpotVelocity::half_step, 0.1});

// predicted: second order (slope >= 1.8). half_step: the dashpot's O(dt) lag, first order
// (the slope is printed and must show convergence, >= 0.8).
void check_slope(const char* what, const SchemeCase& c, double coarse, double fine) {
  const double slope = std::log2(coarse / fine);
  std::printf("%s %s e_t = %.1f: error %.3e at 20 steps, %.3e at 40: slope %.2f\n", what,
              scheme_name(c.scheme), c.e, coarse, fine, slope);
  EXPECT_GE(slope, c.scheme == DashpotVelocity::predicted ? 1.8 : 0.8);
}

class TangentialDashpotConvergence : public ::testing::TestWithParam<SchemeCase> {};

TEST_P(TangentialDashpotConvergence, LastingContactFollowsTheDampedOscillator) {
  const SchemeCase c = GetParam();
  check_slope("tangential", c, tangential_lasting_error(c.scheme, c.e, 20),
              tangential_lasting_error(c.scheme, c.e, 40));
  if (c.scheme == DashpotVelocity::predicted)
    print_sweep(("tangential lasting e_t=" + std::to_string(c.e)).c_str(),
                [&](DashpotVelocity d, double n) { return tangential_lasting_error(d, c.e, n); });
}

INSTANTIATE_TEST_SUITE_P(Schemes, TangentialDashpotConvergence, kSchemeCases, scheme_case_name);

class RollingDashpotConvergence : public ::testing::TestWithParam<SchemeCase> {};

TEST_P(RollingDashpotConvergence, EpsdFollowsTheDampedOscillator) {
  const SchemeCase c = GetParam();
  check_slope("epsd rolling", c, rolling_lasting_error(c.scheme, c.e, 20),
              rolling_lasting_error(c.scheme, c.e, 40));
  if (c.scheme == DashpotVelocity::predicted)
    print_sweep(("epsd rolling e_r=" + std::to_string(c.e)).c_str(),
                [&](DashpotVelocity d, double n) { return rolling_lasting_error(d, c.e, n); });
}

INSTANTIATE_TEST_SUITE_P(Schemes, RollingDashpotConvergence, kSchemeCases, scheme_case_name);

// ---------------------------------------------------------------------------------------
// Oblique impacts that stick: sphere-wall and pair (two equal spheres), Hooke and Hertz.
constexpr double kVn = 1.0, kVt = 0.3;

struct ObliqueCase {
  DashpotVelocity scheme;
  NormalModel model;
  bool pair;
  double e;
};

struct ObliqueReference {
  double contact_time, vt;  // vt: the contact point's tangential velocity after
};

// The normal and tangential coefficients of the contact at overlap d (normal_hooke.hpp,
// normal_hertz.hpp with the pair coefficients of one material).
struct ObliqueLaw {
  NormalModel model;
  double m_star, r_star, y_star, g_star, hooke_kn, hooke_gn, hertz_beta;
  ObliqueLaw(NormalModel law, bool pair, double e) : model(law) {
    m_star = pair ? 0.5 * kMass : kMass;
    r_star = pair ? 0.5 * kR : kR;
    y_star = kY / (2 * (1 - kNu * kNu));
    g_star = kY / (4 * (2 - kNu) * (1 + kNu));
    const double sr = std::sqrt(r_star);
    hooke_kn = (16.0 / 15.0) * sr * y_star *
               std::pow(15.0 * m_star * kVn * kVn / (16.0 * sr * y_star), 0.2);
    hooke_gn = std::sqrt(4 * m_star * hooke_kn) * zeta_of(e);
    hertz_beta = hertz_damping_for_restitution(e);
  }
  // k_n d (the spring force), gamma_n, k_t, gamma_t at overlap d >= 0.
  std::array<double, 4> at(double d) const {
    if (model == NormalModel::hooke) return {hooke_kn * d, hooke_gn, hooke_kn, hooke_gn};
    const double a = std::sqrt(r_star * d), sn = 2 * y_star * a;
    const double gn = 1.8257418583505538 * hertz_beta * std::sqrt(sn * m_star);
    return {(2.0 / 3.0) * sn * d, gn, 8 * g_star * a, gn * std::sqrt(4 * g_star / y_star)};
  }
};

// RK4 on (d, d', xi, w, omega) from first touch: m* d'' = -F_n, F_n = k_n d + gamma_n d';
// the tangential force F_t = -k_t xi - gamma_t v_t while F_n > 0 and 0 from the first time
// F_n reaches 0 on (located by bisection of the step), with v_t = w - c a omega, w' = F_t/m_w,
// omega' = -a F_t / I: for the wall c = 1, m_w = m, a = R - d; for the pair w = v_i - v_j,
// omega each sphere's spin, c = 2, m_w = m/2, a = R - d/2. After F_n = 0 only the normal
// motion continues, to the end of contact (d = 0), which gives the contact time.
ObliqueReference oblique_reference(const ObliqueLaw& law, bool pair) {
  using State = std::array<double, 5>;
  const double c = pair ? 2 : 1, m_w = pair ? 0.5 * kMass : kMass;
  bool sticking = true;
  const auto normal_force = [&](const State& y) {
    const auto k = law.at(std::max(y[0], 0.0));
    return k[0] + k[1] * y[1];
  };
  const auto rhs = [&](const State& y) {
    const auto k = law.at(std::max(y[0], 0.0));
    const double fn = k[0] + k[1] * y[1];
    const double arm = kR - (pair ? 0.5 : 1.0) * y[0];
    const double vt = y[3] - c * arm * y[4];
    const double ft = sticking ? -k[2] * y[2] - k[3] * vt : 0.0;
    return State{y[1], -fn / law.m_star, vt, ft / m_w, -arm * ft / kInertia};
  };
  const auto rk4 = [&](const State& y, double h) {
    const State k1 = rhs(y);
    State y2, y3, y4, r = y;
    for (int j = 0; j < 5; ++j) y2[j] = y[j] + 0.5 * h * k1[j];
    const State k2 = rhs(y2);
    for (int j = 0; j < 5; ++j) y3[j] = y[j] + 0.5 * h * k2[j];
    const State k3 = rhs(y3);
    for (int j = 0; j < 5; ++j) y4[j] = y[j] + h * k3[j];
    const State k4 = rhs(y4);
    for (int j = 0; j < 5; ++j) r[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
    return r;
  };
  // The step: 1/40000 of the elastic Hertz contact time (or Hooke's undamped half period).
  const double t_scale = law.model == NormalModel::hooke
                             ? kPi * std::sqrt(law.m_star / law.hooke_kn)
                             : hertz_contact_time(law.y_star, law.r_star, law.m_star, kVn);
  const double h = t_scale / 40000;
  State y{0, kVn, 0, kVt, 0};
  double t = 0;
  for (long n = 0; n < 10'000'000; ++n) {
    const State next = rk4(y, h);
    if (sticking && n > 0 && normal_force(next) <= 0) {
      double lo = 0, hi = h;  // F_n > 0 after lo, <= 0 after hi
      for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        (normal_force(rk4(y, mid)) > 0 ? lo : hi) = mid;
      }
      y = rk4(y, hi);
      t += hi;
      sticking = false;
      continue;
    }
    if (next[0] <= 0) {  // the end of contact, by linear interpolation of d
      t += h * y[0] / (y[0] - next[0]);
      return {t, next[3] - c * kR * next[4]};
    }
    y = next;
    t += h;
  }
  ADD_FAILURE() << "the reference contact did not end";
  return {0, 0};
}

// The pair in the plane of its motion (the line of centres turns as the tangential forces
// move the spheres apart sideways, so the wall's one-dimensional reference does not apply):
// RK4 on the relative position r = x_i - x_j, the relative velocity u = v_i - v_j, each
// sphere's spin omega (equal by symmetry) and the spring's length s along the tangent
// t = z x n (n = r / |r|; the law keeps the spring in the tangent plane at its length). With
// d = 2R - |r|, a = R - d/2 and the contact point's velocity v_c = u - 2 a omega t:
// F_n = k_n d + gamma_n (-u.n), F_t = -k_t s - gamma_t v_c.t while F_n > 0 (0 from the first
// time F_n reaches 0 on), s' = v_c.t, u' = 2 (F_n n + F_t t) / m, omega' = -a F_t / I.
// First touch at r = (2R, 0), u = (-v_n, v_t); the rebound's u_y - 2 R omega is compared
// (the lab-frame tangential velocity of the contact point, constant after separation).
ObliqueReference oblique_pair_reference(const ObliqueLaw& law) {
  using State = std::array<double, 6>;  // r_x, r_y, u_x, u_y, omega, s
  bool sticking = true;
  const auto forces = [&](const State& y) {  // F_n, F_t, n, t, arm
    const double dist = std::hypot(y[0], y[1]);
    const double d = 2 * kR - dist;
    const double nx = y[0] / dist, ny = y[1] / dist;
    const double arm = kR - 0.5 * d;
    const double vn = y[2] * nx + y[3] * ny;
    const double vt = -y[2] * ny + y[3] * nx - 2 * arm * y[4];
    if (d <= 0) return std::array<double, 6>{0, 0, nx, ny, arm, vt};
    const auto k = law.at(d);
    const double fn = k[0] - k[1] * vn;
    const double ft = sticking && fn > 0 ? -k[2] * y[5] - k[3] * vt : 0.0;
    return std::array<double, 6>{fn, ft, nx, ny, arm, vt};
  };
  const auto rhs = [&](const State& y) {
    const auto f = forces(y);
    const double fx = f[0] * f[2] - f[1] * f[3], fy = f[0] * f[3] + f[1] * f[2];
    return State{y[2], y[3], 2 * fx / kMass, 2 * fy / kMass, -f[4] * f[1] / kInertia, f[5]};
  };
  const auto rk4 = [&](const State& y, double h) {
    const State k1 = rhs(y);
    State y2, y3, y4, r = y;
    for (int j = 0; j < 6; ++j) y2[j] = y[j] + 0.5 * h * k1[j];
    const State k2 = rhs(y2);
    for (int j = 0; j < 6; ++j) y3[j] = y[j] + 0.5 * h * k2[j];
    const State k3 = rhs(y3);
    for (int j = 0; j < 6; ++j) y4[j] = y[j] + h * k3[j];
    const State k4 = rhs(y4);
    for (int j = 0; j < 6; ++j) r[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
    return r;
  };
  const double t_scale = law.model == NormalModel::hooke
                             ? kPi * std::sqrt(law.m_star / law.hooke_kn)
                             : hertz_contact_time(law.y_star, law.r_star, law.m_star, kVn);
  const double h = t_scale / 40000;
  State y{2 * kR, 0, -kVn, kVt, 0, 0};
  double t = 0;
  const auto normal_force = [&](const State& z) { return forces(z)[0]; };
  const auto overlap = [&](const State& z) { return 2 * kR - std::hypot(z[0], z[1]); };
  for (long n = 0; n < 10'000'000; ++n) {
    const State next = rk4(y, h);
    if (sticking && n > 0 && normal_force(next) <= 0) {
      double lo = 0, hi = h;
      for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        (normal_force(rk4(y, mid)) > 0 ? lo : hi) = mid;
      }
      y = rk4(y, hi);
      t += hi;
      sticking = false;
      continue;
    }
    if (n > 0 && overlap(next) <= 0) {
      t += h * overlap(y) / (overlap(y) - overlap(next));
      return {t, next[3] - 2 * kR * next[4]};
    }
    y = next;
    t += h;
  }
  ADD_FAILURE() << "the reference contact did not end";
  return {0, 0};
}

class ObliqueRig {
 public:
  explicit ObliqueRig(const ObliqueCase& c) : pair_(c.pair), sim_(scene(c), false) {
    if (pair_) {
      sim_.particles().add(1, Vec3(kR + 1e-3, 0, 0), Vec3::Zero(), Vec3::Zero(), kR, 0, kRho);
      sim_.particles().add(2, Vec3(-kR - 1e-3, 0, 0), Vec3::Zero(), Vec3::Zero(), kR, 0, kRho);
    } else {
      sim_.particles().add(1, Vec3(0, 0, kR + 1e-3), Vec3::Zero(), Vec3::Zero(), kR, 0, kRho);
    }
    sim_.set_dt(1e-7);
    sim_.initialise();
  }
  // The contact point's tangential velocity after an impact whose first touch falls `phase`
  // into the second step. The wall: normal z, tangential x. The pair: normal x at first
  // touch (from particle 2 to particle 1), relative velocity (-v_n, v_t, 0); the rebound's
  // u_y - R (omega_i + omega_j)_z in the lab frame (oblique_pair_reference).
  double impact(double dt, double phase) {
    Particles& p = sim_.particles();
    const double t0 = (1.0 + phase) * dt;
    for (std::size_t i = 0; i < p.size(); ++i) {
      p.omega[i].setZero();
      p.force[i].setZero();
      p.torque[i].setZero();
      if (!pair_) {
        p.x[i] = Vec3(0, 0, kR + kVn * t0);
        p.v[i] = Vec3(kVt, 0, -kVn);
      } else {
        // The particles may have been re-sorted: place them by id, so that the line of
        // centres is along x at first touch.
        const double sign = p.id[i] == 1 ? 1.0 : -1.0;
        p.x[i] = sign * Vec3(kR + 0.5 * kVn * t0, -0.5 * kVt * t0, 0);
        p.v[i] = sign * Vec3(-0.5 * kVn, 0.5 * kVt, 0);
      }
    }
    sim_.set_dt(dt);
    bool touched = false;
    for (long n = 0; n < 1'000'000; ++n) {
      sim_.step();
      if (!pair_) {
        const double d = kR - p.x[0][2];
        if (d > 0)
          touched = true;
        else if (touched)
          return p.v[0][0] - kR * p.omega[0][1];
      } else {
        const std::size_t i = p.id[0] == 1 ? 0 : 1, j = 1 - i;
        const double d = 2 * kR - (p.x[i] - p.x[j]).norm();
        if (d > 0)
          touched = true;
        else if (touched)
          return p.v[i][1] - p.v[j][1] - kR * (p.omega[i][2] + p.omega[j][2]);
      }
    }
    ADD_FAILURE() << "contact did not end";
    return 0;
  }

 private:
  static Scene scene(const ObliqueCase& c) {
    Scene s = test::one_material_scene(kY, kNu, kRho, c.e, 1e6);
    s.contact.normal = c.model;
    s.contact.tangential = TangentialModel::history;
    if (c.model == NormalModel::hooke) s.contact.hooke_characteristic_velocity = kVn;
    s.contact.dashpot_velocity = c.scheme;
    s.domain.lo = Vec3(-0.1, -0.1, -0.01);
    s.domain.hi = Vec3(0.1, 0.1, 0.03);
    s.time.max_overlap = 1;
    if (!c.pair) s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitZ()));
    return s;
  }
  bool pair_;
  Simulation sim_;
};

// rms over 32 impacts of the relative error of the rebound's tangential velocity change.
double oblique_error(ObliqueRig& rig, const ObliqueReference& ref, double steps) {
  constexpr int kPhases = 8, kLengths = 4;
  double se = 0;
  for (int j = 0; j < kLengths; ++j) {
    const double dt = ref.contact_time / (steps + (j + 0.5) / kLengths - 0.5);
    for (int k = 0; k < kPhases; ++k) {
      const double vt = rig.impact(dt, (k + 0.5) / kPhases);
      se += std::pow((vt - ref.vt) / (kVt - ref.vt), 2);
    }
  }
  return std::sqrt(se / (kPhases * kLengths));
}

std::string oblique_case_name(const ::testing::TestParamInfo<ObliqueCase>& info) {
  const ObliqueCase& c = info.param;
  return std::string(c.scheme == DashpotVelocity::predicted ? "Predicted" : "HalfStep") +
         (c.model == NormalModel::hooke ? "_Hooke" : "_Hertz") + (c.pair ? "_Pair" : "_Wall") +
         "_e0" + std::to_string(static_cast<int>(c.e * 10 + 0.5));
}

std::vector<ObliqueCase> oblique_cases() {
  std::vector<ObliqueCase> cases;
  for (DashpotVelocity d : {DashpotVelocity::predicted, DashpotVelocity::half_step})
    for (NormalModel m : {NormalModel::hooke, NormalModel::hertz})
      for (bool pair : {false, true})
        for (double e : {0.9, 0.5, 0.1}) {
          // half_step: the Hooke wall only, unless GRAINFLOW_DASHPOT_SWEEP is set.
          if (d == DashpotVelocity::half_step && (pair || m == NormalModel::hertz) &&
              !sweep_requested())
            continue;
          cases.push_back({d, m, pair, e});
        }
  return cases;
}

class ObliqueStickingConvergence : public ::testing::TestWithParam<ObliqueCase> {};

// With `predicted` the tangential spring-dashpot's impulse is integrated over the step's cell
// (contact start inside the step, the Coulomb cut where F_n reaches zero inside the step,
// the spring's first increment over the time in contact), and the dashpot sees the
// end-of-step velocity implicit in its own force: second order, impact by impact, and stable
// at 10 steps per impact where the explicit predicted dashpot was not (at e = 0.1). The test
// fits the slope of the rms error over N = 20 ... 80 and requires >= 1.8, and checks that
// N = 10 stays bounded (error <= 10 %). With half_step the tangential force still jumps at
// contact start (the dashpot) and at F_n = 0 (the spring, cut by the Coulomb limit), and the
// spring's first increment counts the whole drift of first touch: O(dt) impulse errors, first
// order (the slope >= 0.6 is asserted and the error at N = 40 below 0.2).
TEST_P(ObliqueStickingConvergence, ReboundConverges) {
  const ObliqueCase c = GetParam();
  const ObliqueLaw law(c.model, c.pair, c.e);
  const ObliqueReference ref = c.pair ? oblique_pair_reference(law) : oblique_reference(law, c.pair);
  ObliqueRig rig(c);
  double sx = 0, sy = 0, sxx = 0, sxy = 0, at40 = 0;
  const std::array<double, 5> ns{20, 28, 40, 57, 80};
  const char* name = scheme_name(c.scheme);
  const char* model = c.model == NormalModel::hooke ? "hooke" : "hertz";
  const char* geometry = c.pair ? "pair" : "wall";
  if (c.scheme == DashpotVelocity::predicted || sweep_requested()) {
    std::printf("oblique sticking %s %s %s e = %.1f:", name, model, geometry, c.e);
    for (double n : {7.0, 10.0, 14.0}) {
      if (c.model == NormalModel::hertz && n < 10) continue;  // refused: < 5 elastic contact times
      const double err = oblique_error(rig, ref, n);
      std::printf(" N=%g %.2e", n, err);
      if (c.scheme == DashpotVelocity::predicted && n >= 10) {
        EXPECT_LE(err, 0.2) << "N = " << n;
      }
    }
    std::printf("\n");
  }
  std::printf("oblique sticking %s %s %s e = %.1f (v_t after %.4f v_t before): rms error of its "
              "change",
              name, model, geometry, c.e, ref.vt / kVt);
  for (double n : ns) {
    const double err = oblique_error(rig, ref, n);
    if (n == 40) at40 = err;
    std::printf(" N=%g %.2e", n, err);
    const double x = std::log(n), y = std::log(err);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double k = ns.size();
  const double slope = -(k * sxy - sx * sy) / (k * sxx - sx * sx);
  std::printf(": fitted slope %.2f\n", slope);
  if (c.scheme == DashpotVelocity::predicted) {
    EXPECT_GE(slope, 1.8);
  } else {
    EXPECT_GE(slope, 0.6);
    EXPECT_LE(at40, 0.2);
  }
}

INSTANTIATE_TEST_SUITE_P(Schemes, ObliqueStickingConvergence, ::testing::ValuesIn(oblique_cases()),
                         oblique_case_name);

// ---------------------------------------------------------------------------------------
// Pair impacts, head-on.
class PairRig {
 public:
  PairRig(NormalModel model, double e) : sim_(scene(model, e), false) {
    sim_.particles().add(1, Vec3(kR + 1e-3, 0, 0), Vec3(-0.5 * kVn, 0, 0), Vec3::Zero(), kR, 0, kRho);
    sim_.particles().add(2, Vec3(-kR - 1e-3, 0, 0), Vec3(0.5 * kVn, 0, 0), Vec3::Zero(), kR, 0, kRho);
    sim_.set_dt(1e-7);
    sim_.initialise();
  }
  struct Impact {
    double restitution, contact_time, momentum;
  };
  Impact impact(double dt, double phase) {
    Particles& p = sim_.particles();
    const double t0 = (1.0 + phase) * dt;
    // The particles may have been re-sorted: place them by id.
    for (std::size_t i = 0; i < 2; ++i) {
      const double sign = p.id[i] == 1 ? 1.0 : -1.0;
      p.x[i] = Vec3(sign * (kR + 0.5 * kVn * t0), 0, 0);
      p.v[i] = Vec3(-sign * 0.5 * kVn, 0, 0);
      p.force[i].setZero();
    }
    sim_.set_dt(dt);
    bool touched = false;
    for (long n = 0; n < 1'000'000; ++n) {
      sim_.step();
      const double gap = std::abs(p.x[0][0] - p.x[1][0]);
      const double d = 2 * kR - gap;
      if (d > 0) {
        touched = true;
      } else if (touched) {
        const double vrel = std::abs(p.v[0][0] - p.v[1][0]);
        return {vrel / kVn, (n + 1) * dt + d / vrel - t0, p.v[0][0] + p.v[1][0]};
      }
    }
    ADD_FAILURE() << "contact did not end";
    return {0, 0, 0};
  }

 private:
  static Scene scene(NormalModel model, double e) {
    Scene s = test::one_material_scene(kY, kNu, kRho, e);
    s.contact.normal = model;
    s.contact.dashpot_velocity = DashpotVelocity::predicted;
    if (model == NormalModel::hooke) s.contact.hooke_characteristic_velocity = kVn;
    s.domain.lo = Vec3(-0.03, -0.01, -0.01);
    s.domain.hi = Vec3(0.03, 0.01, 0.01);
    s.time.max_overlap = 1;
    return s;
  }
  Simulation sim_;
};

// Hooke: the damped oscillator's contact time with m* = m/2, R* = R/2 (pair Y* equals the
// wall's for one material); Hertz: the elastic closed form, which only sets N.
double pair_contact_time(NormalModel model, double e) {
  const double m = 0.5 * kMass, r = 0.5 * kR;
  const double y_star = kY / (2 * (1 - kNu * kNu));
  if (model == NormalModel::hertz) return hertz_contact_time(y_star, r, m, kVn);
  const double sr = std::sqrt(r);
  const double k = (16.0 / 15.0) * sr * y_star * std::pow(15.0 * m * kVn * kVn / (16.0 * sr * y_star), 0.2);
  return kPi / std::sqrt(k / m * (1 - std::pow(zeta_of(e), 2)));
}

struct PairCase {
  NormalModel model;
  double e;
};

class PairImpactConvergence : public ::testing::TestWithParam<PairCase> {};

TEST_P(PairImpactConvergence, RestitutionErrorFallsAtSecondOrder) {
  const PairCase c = GetParam();
  PairRig rig(c.model, c.e);
  const double tc = pair_contact_time(c.model, c.e);
  double max_momentum = 0;
  const auto errors = [&](double steps) {
    constexpr int kPhases = 8, kLengths = 4;
    double se = 0, st = 0;
    for (int j = 0; j < kLengths; ++j) {
      const double dt = tc / (steps + (j + 0.5) / kLengths - 0.5);
      for (int k = 0; k < kPhases; ++k) {
        const PairRig::Impact r = rig.impact(dt, (k + 0.5) / kPhases);
        se += std::pow(r.restitution / c.e - 1, 2);
        st += std::pow(r.contact_time / tc - 1, 2);
        max_momentum = std::max(max_momentum, std::abs(r.momentum));
      }
    }
    return std::array<double, 2>{std::sqrt(se / 32), std::sqrt(st / 32)};
  };
  const std::array<double, 2> coarse = errors(20), fine = errors(40);
  const double slope_e = std::log2(coarse[0] / fine[0]);
  const double slope_t = std::log2(coarse[1] / fine[1]);
  const char* law = c.model == NormalModel::hooke ? "hooke" : "hertz";
  std::printf("pair %s e = %.1f: rms restitution error %.3e at 20, %.3e at 40: slope %.2f\n", law,
              c.e, coarse[0], fine[0], slope_e);
  if (c.model == NormalModel::hooke)
    std::printf("pair hooke e = %.1f: rms contact-time error %.3e at 20, %.3e at 40: slope %.2f\n",
                c.e, coarse[1], fine[1], slope_t);
  EXPECT_GE(slope_e, 1.8);
  if (c.model == NormalModel::hooke) {
    EXPECT_GE(slope_t, 1.8);
  }
  // A pair's force is applied with opposite signs: the total momentum (zero) to round-off.
  EXPECT_LE(max_momentum, 1e-14 * kVn);
}

INSTANTIATE_TEST_SUITE_P(Laws, PairImpactConvergence,
                         ::testing::Values(PairCase{NormalModel::hooke, 0.9},
                                           PairCase{NormalModel::hooke, 0.5},
                                           PairCase{NormalModel::hooke, 0.1},
                                           PairCase{NormalModel::hertz, 0.9},
                                           PairCase{NormalModel::hertz, 0.5},
                                           PairCase{NormalModel::hertz, 0.1}),
                         [](const ::testing::TestParamInfo<PairCase>& param_info) {
                           return std::string(param_info.param.model == NormalModel::hooke ? "Hooke"
                                                                                     : "Hertz") +
                                  "_e0" + std::to_string(static_cast<int>(param_info.param.e * 10 + 0.5));
                         });

}  // namespace
}  // namespace grainflow
