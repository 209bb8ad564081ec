// The contact law evaluated on several contacts at once (dem/core/lanes.hpp) gives every
// contact bit for bit the result it gets alone, whichever lane it sits in. The pair sweeps rely
// on it: a pair across two ranks is evaluated on both, in lanes that differ from rank to rank,
// and both ranks must apply exactly opposite forces.
//
// Reference: ContactLaw<HertzNormal, HistoryTangential>::evaluate with V = double, the scalar
// code; and, for a purely normal elastic contact, the Hertz force F = (4/3) Y* sqrt(R*) d^{3/2}
// (Hertz 1881), independent of the code. Contacts: random overlaps, relative velocities, spins
// and springs, with some springs zero (a contact's first step) and some contacts sliding (the
// Coulomb limit), in every mix across the lanes.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "dem/contact/contact_law.hpp"

namespace grainflow {
namespace {

using Law = ContactLaw<HertzNormal, HistoryTangential, NoRolling, NoCohesion>;
// contact.dashpot_velocity: predicted (the cell-integrated normal dashpot, with its branches for
// a contact that began in the last drift or ends in the next: the random overlaps reach below
// dt |v|).
using PredictedLaw = ContactLaw<HertzNormal, HistoryTangential, NoRolling, NoCohesion, true>;

// The material-pair constants the law reads, as lanes (what the sweeps gather).
template <class V>
struct Coefficients {
  V y_star, g_star, hertz_beta, hertz_gt_per_gn, friction;
};

struct Case {
  ContactGeometry g;
  Vec3 spring;
};

PairCoefficients material() {
  PairCoefficients pc;
  const double y = 5e6, nu = 0.3;
  pc.y_star = 1.0 / (2 * (1 - nu * nu) / y);
  pc.g_star = 1.0 / (2 * 2 * (2 - nu) * (1 + nu) / y);
  pc.hertz_gt_per_gn = std::sqrt(4 * pc.g_star / pc.y_star);
  pc.hertz_beta = -0.4;  // a restitution of about 0.28
  pc.friction = 0.5;
  return pc;
}

std::vector<Case> random_cases(int count) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Case> cases;
  for (int k = 0; k < count; ++k) {
    Case c;
    ContactGeometry& g = c.g;
    g.n = Vec3(u(rng), u(rng), u(rng)).normalized();
    const double r_i = 1e-3 * (1 + 0.5 * u(rng)), r_j = 1e-3 * (1 + 0.5 * u(rng));
    g.overlap = 1e-5 * (1.05 + u(rng));
    g.distance = r_i + r_j - g.overlap;
    g.r_i = r_i;
    g.r_j = r_j;
    g.arm_i = r_i - 0.5 * g.overlap;
    g.arm_j = r_j - 0.5 * g.overlap;
    g.r_star = r_i * r_j / (r_i + r_j);
    g.m_star = 1e-5 * (1 + 0.5 * u(rng));
    g.roll_inertia = 0;
    g.v_rel = 0.1 * Vec3(u(rng), u(rng), u(rng));
    g.w_rel = 100 * Vec3(u(rng), u(rng), u(rng));
    // The predicted end-of-step velocities differ from the half-step ones by an O(dt) kick.
    g.v_pred = g.v_rel + 0.01 * Vec3(u(rng), u(rng), u(rng));
    g.w_pred = g.w_rel + 10 * Vec3(u(rng), u(rng), u(rng));
    g.wall = false;
    // Every third spring zero; the others from sticking (1e-8 m) to sliding (1e-5 m).
    const double length = k % 3 == 0 ? 0 : std::pow(10.0, -8 + 3 * (0.5 + 0.5 * u(rng)));
    const Vec3 t = Vec3(u(rng), u(rng), u(rng)).cross(g.n).normalized();
    c.spring = length * t + 1e-3 * length * g.n;  // slightly off the tangent plane
    cases.push_back(c);
  }
  return cases;
}

bool same(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}
bool same(const Vec3& a, const Vec3& b) {
  return same(a[0], b[0]) && same(a[1], b[1]) && same(a[2], b[2]);
}

struct Scalar {
  ContactResult r;
  Vec3 spring;
};

template <class L = Law>
Scalar evaluate_alone(const Case& c, const PairCoefficients& pc, double dt) {
  Scalar s{ContactResult{}, c.spring};
  Vec3 rolling = Vec3::Zero();
  s.r = L::evaluate(c.g, pc, ContactConstants{}, s.spring, rolling, dt);
  return s;
}

// Evaluates the cases `pick[0..W)` in the lanes of V and checks each against its alone result.
template <class V, class L = Law>
void check_lanes(const std::vector<Case>& cases, const std::vector<Scalar>& alone,
                 const std::vector<int>& pick, const PairCoefficients& pc, double dt) {
  constexpr int W = lane_count<V>;
  const auto geometry = [&](int l) -> const ContactGeometry& { return cases[pick[l]].g; };
  ContactGeometryT<V> g;
  g.n = gather3<V>([&](int l) -> const Vec3& { return geometry(l).n; });
  g.overlap = gather<V>([&](int l) { return geometry(l).overlap; });
  g.distance = gather<V>([&](int l) { return geometry(l).distance; });
  g.r_i = gather<V>([&](int l) { return geometry(l).r_i; });
  g.r_j = gather<V>([&](int l) { return geometry(l).r_j; });
  g.arm_i = gather<V>([&](int l) { return geometry(l).arm_i; });
  g.arm_j = gather<V>([&](int l) { return geometry(l).arm_j; });
  g.r_star = gather<V>([&](int l) { return geometry(l).r_star; });
  g.m_star = gather<V>([&](int l) { return geometry(l).m_star; });
  g.roll_inertia = V{};
  g.v_rel = gather3<V>([&](int l) -> const Vec3& { return geometry(l).v_rel; });
  g.w_rel = gather3<V>([&](int l) -> const Vec3& { return geometry(l).w_rel; });
  g.v_pred = gather3<V>([&](int l) -> const Vec3& { return geometry(l).v_pred; });
  g.w_pred = gather3<V>([&](int l) -> const Vec3& { return geometry(l).w_pred; });
  g.wall = false;
  const auto all = [&](double v) { return broadcast<V>(v); };
  const Coefficients<V> lanes_pc{all(pc.y_star), all(pc.g_star), all(pc.hertz_beta),
                                 all(pc.hertz_gt_per_gn), all(pc.friction)};
  V3<V> spring = gather3<V>([&](int l) -> const Vec3& { return cases[pick[l]].spring; });
  V3<V> rolling = zero3<V>();
  const ContactResultT<V> r = L::evaluate(g, lanes_pc, ContactConstants{}, spring, rolling, dt);
  for (int l = 0; l < W; ++l) {
    const Scalar& a = alone[pick[l]];
    EXPECT_TRUE(same(lane(r.force, l), a.r.force)) << "case " << pick[l] << " lane " << l;
    EXPECT_TRUE(same(lane(r.torque_i, l), a.r.torque_i)) << "case " << pick[l] << " lane " << l;
    EXPECT_TRUE(same(lane(r.torque_j, l), a.r.torque_j)) << "case " << pick[l] << " lane " << l;
    EXPECT_TRUE(same(lane(spring, l), a.spring)) << "case " << pick[l] << " lane " << l;
  }
}

TEST(ContactLanes, EveryLaneGivesTheScalarResultToTheLastBit) {
  const PairCoefficients pc = material();
  const double dt = 1.5e-5;
  const std::vector<Case> cases = random_cases(60);
  std::vector<Scalar> alone;
  int sliding = 0, fresh = 0;
  for (const Case& c : cases) {
    alone.push_back(evaluate_alone(c, pc, dt));
    fresh += c.spring.squaredNorm() == 0;
    // A sliding contact's tangential force is at the Coulomb limit mu F_n.
    const Vec3 f = alone.back().r.force;
    const double fn = f.dot(c.g.n), ft = (f - fn * c.g.n).norm();
    sliding += ft > (1 - 1e-9) * pc.friction * std::max(fn, 0.0);
  }
  ASSERT_GT(sliding, 5) << "the cases must mix sliding and sticking contacts";
  ASSERT_LT(sliding, 55);
  ASSERT_GT(fresh, 10);
  const int n = static_cast<int>(cases.size());
  for (int k = 0; k < n; ++k) {
    // Each case in every lane, next to different neighbours.
    check_lanes<Lanes2>(cases, alone, {k, (k + 1) % n}, pc, dt);
    check_lanes<Lanes2>(cases, alone, {(k + 7) % n, k}, pc, dt);
    check_lanes<Lanes2x2>(cases, alone, {k, (k + 3) % n, (k + 5) % n, (k + 11) % n}, pc, dt);
    check_lanes<Lanes2x2>(cases, alone, {(k + 2) % n, (k + 9) % n, k, (k + 4) % n}, pc, dt);
    check_lanes<Lanes2x2>(cases, alone, {k, k, k, k}, pc, dt);
    check_lanes<Lanes4>(cases, alone, {k, (k + 3) % n, (k + 5) % n, (k + 11) % n}, pc, dt);
    check_lanes<Lanes4>(cases, alone, {(k + 2) % n, (k + 9) % n, k, (k + 4) % n}, pc, dt);
  }
}

TEST(ContactLanes, PredictedDashpotGivesTheScalarResultToTheLastBit) {
  const PairCoefficients pc = material();
  const double dt = 2e-4;  // dt |v| spans the overlaps: contacts start and end in the step
  const std::vector<Case> cases = random_cases(60);
  std::vector<Scalar> alone;
  int starts = 0, ends = 0;
  for (const Case& c : cases) {
    alone.push_back(evaluate_alone<PredictedLaw>(c, pc, dt));
    const double vn = c.g.v_rel.dot(c.g.n);  // > 0: separating
    starts += c.g.overlap + dt * vn <= 0;    // began within the last drift
    ends += c.g.overlap - dt * vn < 0;       // ends within the next
    EXPECT_TRUE(std::isfinite(alone.back().r.force.norm()));
  }
  ASSERT_GT(starts, 2) << "the cases must include contacts that began within the step";
  ASSERT_GT(ends, 2) << "the cases must include contacts that end within the next step";
  const int n = static_cast<int>(cases.size());
  for (int k = 0; k < n; ++k) {
    check_lanes<Lanes2, PredictedLaw>(cases, alone, {k, (k + 1) % n}, pc, dt);
    check_lanes<Lanes2x2, PredictedLaw>(cases, alone, {k, (k + 3) % n, (k + 5) % n, (k + 11) % n},
                                        pc, dt);
    check_lanes<Lanes2x2, PredictedLaw>(cases, alone, {k, k, k, k}, pc, dt);
    check_lanes<Lanes4, PredictedLaw>(cases, alone, {k, (k + 3) % n, (k + 5) % n, (k + 11) % n}, pc,
                                      dt);
  }
}

TEST(ContactLanes, ElasticNormalForceIsHertzInEveryLane) {
  // No damping, no tangential motion: F = (4/3) Y* sqrt(R*) d^{3/2} along n. Tolerance 1e-12
  // relative: a few roundings of the stiffness and the product.
  PairCoefficients pc = material();
  pc.hertz_beta = 0;
  std::vector<Case> cases = random_cases(4);
  for (Case& c : cases) {
    c.g.v_rel.setZero();
    c.g.w_rel.setZero();
    c.g.v_pred.setZero();
    c.g.w_pred.setZero();
    c.spring.setZero();
  }
  ContactGeometryT<Lanes2x2> g;
  const auto geometry = [&](int l) -> const ContactGeometry& { return cases[l].g; };
  g.n = gather3<Lanes2x2>([&](int l) -> const Vec3& { return geometry(l).n; });
  g.overlap = gather<Lanes2x2>([&](int l) { return geometry(l).overlap; });
  g.arm_i = gather<Lanes2x2>([&](int l) { return geometry(l).arm_i; });
  g.arm_j = gather<Lanes2x2>([&](int l) { return geometry(l).arm_j; });
  g.r_star = gather<Lanes2x2>([&](int l) { return geometry(l).r_star; });
  g.m_star = gather<Lanes2x2>([&](int l) { return geometry(l).m_star; });
  g.v_rel = zero3<Lanes2x2>();
  g.w_rel = zero3<Lanes2x2>();
  g.v_pred = zero3<Lanes2x2>();
  g.w_pred = zero3<Lanes2x2>();
  g.wall = false;
  const auto all = [&](double v) { return broadcast<Lanes2x2>(v); };
  const Coefficients<Lanes2x2> lanes_pc{all(pc.y_star), all(pc.g_star), all(0.0),
                                        all(pc.hertz_gt_per_gn), all(pc.friction)};
  Lanes3<Lanes2x2> spring = zero3<Lanes2x2>(), rolling = zero3<Lanes2x2>();
  const ContactResultT<Lanes2x2> r =
      Law::evaluate(g, lanes_pc, ContactConstants{}, spring, rolling, 1e-5);
  for (int l = 0; l < 4; ++l) {
    const ContactGeometry& c = cases[l].g;
    const double hertz = 4.0 / 3.0 * pc.y_star * std::sqrt(c.r_star) * std::pow(c.overlap, 1.5);
    EXPECT_NEAR(lane(r.force, l).dot(c.n) / hertz, 1.0, 1e-12) << "lane " << l;
    EXPECT_LT((lane(r.force, l) - lane(r.force, l).dot(c.n) * c.n).norm(), 1e-12 * hertz);
  }
}

}  // namespace
}  // namespace grainflow
