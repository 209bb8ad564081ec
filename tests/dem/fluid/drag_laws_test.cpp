// Each drag law against values recomputed independently from the original formula,
// and the limits each law must reach. Reference values: tests/dem/fluid/drag_reference.py
// (plain Python floats, written from the papers' own forms — C_D, β, Ergun's Δp/L, the
// total-force ratio F — not from the C++ algebra). Its printed table is kReference.
// Tolerance 1e-10 relative: both sides are double-precision evaluations of the same
// closed form in different algebraic arrangements; their round-off differs by ~1e-15.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "dem/fluid/drag_law.hpp"
#include "dem/fluid/gidaspow.hpp"

namespace grainflow {
namespace {

constexpr double kD = 1e-3, kRho = 1000, kMu = 1e-3;

DragInput input(double eps, double u) { return {kD, u, eps, kRho, kMu}; }

// U for a superficial Reynolds number Re = ρ ε d U/μ.
double slip_for(double re, double eps) { return re * kMu / (kRho * eps * kD); }

double stokes() { return 3 * std::numbers::pi * kMu * kD; }

struct Row {
  const char* law;
  double eps, u, k;
};

const Row kReference[] = {
    {"schiller_naumann", 0.4, 0.00025, 9.97021819756392e-06},
    {"schiller_naumann", 0.4, 0.024999999999999998, 2.232945596110439e-05},
    {"schiller_naumann", 0.4, 1.25, 0.00021598449493429828},
    {"schiller_naumann", 0.4, 5.0, 0.0008639379797371931},
    {"schiller_naumann", 0.6, 0.0001666666666666667, 9.837609127968916e-06},
    {"schiller_naumann", 0.6, 0.016666666666666666, 1.9192031862903624e-05},
    {"schiller_naumann", 0.6, 0.8333333333333334, 0.0001529621102620735},
    {"schiller_naumann", 0.6, 3.3333333333333335, 0.0005759586531581288},
    {"schiller_naumann", 0.85, 0.00011764705882352942, 9.749754182026991e-06},
    {"schiller_naumann", 0.85, 0.011764705882352941, 1.7113454391648118e-05},
    {"schiller_naumann", 0.85, 0.5882352941176471, 0.00012241581053494007},
    {"schiller_naumann", 0.85, 2.3529411764705883, 0.0004065590492880909},
    {"schiller_naumann", 0.95, 0.00010526315789473683, 9.725847119918216e-06},
    {"schiller_naumann", 0.95, 0.010526315789473684, 1.654783250012644e-05},
    {"schiller_naumann", 0.95, 0.5263157894736842, 0.00011410356041697207},
    {"schiller_naumann", 0.95, 2.1052631578947367, 0.0003637633598893445},
    {"di_felice", 0.4, 0.00025, 0.00011348494270402343},
    {"di_felice", 0.4, 0.024999999999999998, 0.0001271322607785328},
    {"di_felice", 0.4, 1.25, 0.0012438697125665304},
    {"di_felice", 0.4, 5.0, 0.004505669868530277},
    {"di_felice", 0.6, 0.0001666666666666667, 3.841676887132992e-05},
    {"di_felice", 0.6, 0.016666666666666666, 5.368084760092596e-05},
    {"di_felice", 0.6, 0.8333333333333334, 0.0004732718782505809},
    {"di_felice", 0.6, 3.3333333333333335, 0.0015882627483850549},
    {"di_felice", 0.85, 0.00011764705882352942, 1.5150193018591742e-05},
    {"di_felice", 0.85, 0.011764705882352941, 2.5595714474814908e-05},
    {"di_felice", 0.85, 0.5882352941176471, 0.00020635099375747792},
    {"di_felice", 0.85, 2.3529411764705883, 0.0006485175955502492},
    {"di_felice", 0.95, 0.00010526315789473683, 1.1255766231529882e-05},
    {"di_felice", 0.95, 0.010526315789473684, 2.0204741414503286e-05},
    {"di_felice", 0.95, 0.5263157894736842, 0.00015830181375912962},
    {"di_felice", 0.95, 2.1052631578947367, 0.00048719323360341647},
    {"rong", 0.4, 0.00025, 0.00011464951811178692},
    {"rong", 0.4, 0.024999999999999998, 0.00013102853086843474},
    {"rong", 0.4, 1.25, 0.0012699793875957715},
    {"rong", 0.4, 5.0, 0.0045685935379799324},
    {"rong", 0.6, 0.0001666666666666667, 5.0052524621570606e-05},
    {"rong", 0.6, 0.016666666666666666, 5.640735172971691e-05},
    {"rong", 0.6, 0.8333333333333334, 0.000550342876711473},
    {"rong", 0.6, 3.3333333333333335, 0.001989399081793335},
    {"rong", 0.85, 0.00011764705882352942, 1.8285142101223158e-05},
    {"rong", 0.85, 0.011764705882352941, 2.6847043767531966e-05},
    {"rong", 0.85, 0.5882352941176471, 0.00023123674571891807},
    {"rong", 0.85, 2.3529411764705883, 0.00076284769112772},
    {"rong", 0.95, 0.00010526315789473683, 1.210479094695632e-05},
    {"rong", 0.95, 0.010526315789473684, 2.0695765158055352e-05},
    {"rong", 0.95, 0.5263157894736842, 0.00016591368292024277},
    {"rong", 0.95, 2.1052631578947367, 0.0005192886026017364},
    {"wen_yu", 0.4, 0.00025, 0.00011015462117861332},
    {"wen_yu", 0.4, 0.024999999999999998, 0.0001848249259920905},
    {"wen_yu", 0.4, 1.25, 0.0012526249187896658},
    {"wen_yu", 0.4, 5.0, 0.00391817275863051},
    {"wen_yu", 0.6, 0.0001666666666666667, 3.7614984291033244e-05},
    {"wen_yu", 0.6, 0.016666666666666666, 6.311298258210197e-05},
    {"wen_yu", 0.6, 0.8333333333333334, 0.0004277393552689007},
    {"wen_yu", 0.6, 3.3333333333333335, 0.0013379557315753852},
    {"wen_yu", 0.85, 0.00011764705882352942, 1.4945193596398104e-05},
    {"wen_yu", 0.85, 0.011764705882352941, 2.5076063726031293e-05},
    {"wen_yu", 0.85, 0.5882352941176471, 0.00016994949203836635},
    {"wen_yu", 0.85, 2.3529411764705883, 0.000531596857175115},
    {"wen_yu", 0.95, 0.00010526315789473683, 1.1129973858406631e-05},
    {"wen_yu", 0.95, 0.010526315789473684, 1.8674628196835884e-05},
    {"wen_yu", 0.95, 0.5263157894736842, 0.00012656466384566446},
    {"wen_yu", 0.95, 2.1052631578947367, 0.00039589043028496524},
    {"ergun", 0.4, 0.00025, 0.00011803879897394145},
    {"ergun", 0.4, 0.024999999999999998, 0.00014071717094204283},
    {"ergun", 0.4, 1.25, 0.001263182046130896},
    {"ergun", 0.4, 5.0, 0.004699299010994732},
    {"ergun", 0.6, 0.0001666666666666667, 5.2512593869379394e-05},
    {"ergun", 0.6, 0.016666666666666666, 6.763150851478027e-05},
    {"ergun", 0.6, 0.8333333333333334, 0.0008159414253073491},
    {"ergun", 0.6, 3.3333333333333335, 0.0031066860685499066},
    {"ergun", 0.85, 0.00011764705882352942, 1.3967767337284032e-05},
    {"ergun", 0.85, 0.011764705882352941, 2.4639942381096423e-05},
    {"ergun", 0.85, 0.5882352941176471, 0.0005528587071758509},
    {"ergun", 0.85, 2.3529411764705883, 0.0021698549259353034},
    {"ergun", 0.95, 0.00010526315789473683, 4.230126950228364e-06},
    {"ergun", 0.95, 0.010526315789473684, 1.3778915147323655e-05},
    {"ergun", 0.95, 0.5263157894736842, 0.0004863957047005249},
    {"ergun", 0.95, 2.1052631578947367, 0.0019331817951695081},
    {"gidaspow", 0.4, 0.00025, 0.00011803879897394145},
    {"gidaspow", 0.4, 0.024999999999999998, 0.00014071717094204283},
    {"gidaspow", 0.4, 1.25, 0.001263182046130896},
    {"gidaspow", 0.4, 5.0, 0.004699299010994732},
    {"gidaspow", 0.6, 0.0001666666666666667, 5.2512593869379394e-05},
    {"gidaspow", 0.6, 0.016666666666666666, 6.763150851478027e-05},
    {"gidaspow", 0.6, 0.8333333333333334, 0.0008159414253073491},
    {"gidaspow", 0.6, 3.3333333333333335, 0.0031066860685499066},
    {"gidaspow", 0.85, 0.00011764705882352942, 1.4945193596398104e-05},
    {"gidaspow", 0.85, 0.011764705882352941, 2.5076063726031293e-05},
    {"gidaspow", 0.85, 0.5882352941176471, 0.00016994949203836635},
    {"gidaspow", 0.85, 2.3529411764705883, 0.000531596857175115},
    {"gidaspow", 0.95, 0.00010526315789473683, 1.1129973858406631e-05},
    {"gidaspow", 0.95, 0.010526315789473684, 1.8674628196835884e-05},
    {"gidaspow", 0.95, 0.5263157894736842, 0.00012656466384566446},
    {"gidaspow", 0.95, 2.1052631578947367, 0.00039589043028496524},
    {"koch_hill", 0.4, 0.00025, 0.00014155715846658656},
    {"koch_hill", 0.4, 0.024999999999999998, 0.0001599205749161309},
    {"koch_hill", 0.4, 1.25, 0.0010688169446410511},
    {"koch_hill", 0.4, 5.0, 0.0038511527703295827},
    {"koch_hill", 0.6, 0.0001666666666666667, 6.29082707772047e-05},
    {"koch_hill", 0.6, 0.016666666666666666, 7.047362361267887e-05},
    {"koch_hill", 0.6, 0.8333333333333334, 0.0004449203801159457},
    {"koch_hill", 0.6, 3.3333333333333335, 0.001591185961248395},
    {"koch_hill", 0.85, 0.00011764705882352942, 2.6467888919130503e-05},
    {"koch_hill", 0.85, 0.011764705882352941, 3.157061943780677e-05},
    {"koch_hill", 0.85, 0.5882352941176471, 0.0002841300087460262},
    {"koch_hill", 0.85, 2.3529411764705883, 0.0010572709964242492},
    {"koch_hill", 0.95, 0.00010526315789473683, 1.6534482993326433e-05},
    {"koch_hill", 0.95, 0.010526315789473684, 2.1076775806028343e-05},
    {"koch_hill", 0.95, 0.5263157894736842, 0.00024589732916198144},
    {"koch_hill", 0.95, 2.1052631578947367, 0.0009341235129046951},
    {"beetstra", 0.4, 0.00025, 0.00014267597221703817},
    {"beetstra", 0.4, 0.024999999999999998, 0.00015529964879254868},
    {"beetstra", 0.4, 1.25, 0.000996126522879285},
    {"beetstra", 0.4, 5.0, 0.003255718943832981},
    {"beetstra", 0.6, 0.0001666666666666667, 6.680066920092792e-05},
    {"beetstra", 0.6, 0.016666666666666666, 7.613858660290157e-05},
    {"beetstra", 0.6, 0.8333333333333334, 0.000521828792941293},
    {"beetstra", 0.6, 3.3333333333333335, 0.0016906522304856399},
    {"beetstra", 0.85, 0.00011764705882352942, 2.5802853847430932e-05},
    {"beetstra", 0.85, 0.011764705882352941, 3.286779992088602e-05},
    {"beetstra", 0.85, 0.5882352941176471, 0.00026492186081620157},
    {"beetstra", 0.85, 2.3529411764705883, 0.000851779733510668},
    {"beetstra", 0.95, 0.00010526315789473683, 1.580206038691596e-05},
    {"beetstra", 0.95, 0.010526315789473684, 2.2062195124908743e-05},
    {"beetstra", 0.95, 0.5263157894736842, 0.000196700522605044},
    {"beetstra", 0.95, 2.1052631578947367, 0.0006263163085868829},
    {"tenneti_garg_subramaniam", 0.4, 0.00025, 0.00013033075983009325},
    {"tenneti_garg_subramaniam", 0.4, 0.024999999999999998, 0.00015251408127397594},
    {"tenneti_garg_subramaniam", 0.4, 1.25, 0.0006710146201489276},
    {"tenneti_garg_subramaniam", 0.4, 5.0, 0.0019396783865206605},
    {"tenneti_garg_subramaniam", 0.6, 0.0001666666666666667, 6.197964253683229e-05},
    {"tenneti_garg_subramaniam", 0.6, 0.016666666666666666, 7.523132984871056e-05},
    {"tenneti_garg_subramaniam", 0.6, 0.8333333333333334, 0.0003448150336594881},
    {"tenneti_garg_subramaniam", 0.6, 3.3333333333333335, 0.0009576827490118303},
    {"tenneti_garg_subramaniam", 0.85, 0.00011764705882352942, 2.4422156869763924e-05},
    {"tenneti_garg_subramaniam", 0.85, 0.011764705882352941, 3.238691917379521e-05},
    {"tenneti_garg_subramaniam", 0.85, 0.5882352941176471, 0.00015391450450627766},
    {"tenneti_garg_subramaniam", 0.85, 2.3529411764705883, 0.00037601641610964827},
    {"tenneti_garg_subramaniam", 0.95, 0.00010526315789473683, 1.4955526166078804e-05},
    {"tenneti_garg_subramaniam", 0.95, 0.010526315789473684, 2.1897921688546703e-05},
    {"tenneti_garg_subramaniam", 0.95, 0.5263157894736842, 0.00012152750665958534},
    {"tenneti_garg_subramaniam", 0.95, 2.1052631578947367, 0.00029237591367917463},
};

TEST(DragLaws, MatchIndependentReferenceValues) {
  int checked = 0;
  for (const Row& r : kReference) {
    const double k = drag_law(r.law).function(input(r.eps, r.u));
    EXPECT_NEAR(k / r.k, 1.0, 1e-10) << r.law << " eps=" << r.eps << " U=" << r.u;
    ++checked;
  }
  // 9 laws x 4 void fractions x 4 Reynolds numbers.
  EXPECT_EQ(checked, 9 * 4 * 4);
}

TEST(DragLaws, RegistryListsEveryNameOnUnknownName) {
  try {
    drag_law("difelice");
    FAIL() << "no error for an unknown name";
  } catch (const UnknownDragLaw& e) {
    EXPECT_STREQ(e.what(),
                 "unknown drag law 'difelice'; allowed: schiller_naumann, di_felice, rong, wen_yu, "
                 "ergun, gidaspow, koch_hill, beetstra, tenneti_garg_subramaniam");
  }
  EXPECT_EQ(drag_laws().size(), 9u);
}

// Schiller–Naumann → Stokes 3πμd as Re₀ → 0: the deviation is 0.15 Re₀^0.687
// (1.1e-5 at Re₀ = 1e-6, 9e-8 at 1e-9, exactly 0 at Re₀ = 0).
TEST(DragLaws, SchillerNaumannTendsToStokes) {
  for (double re : {1e-6, 1e-9, 0.0}) {
    const double k = drag_law("schiller_naumann").function(input(1.0, slip_for(re, 1.0)));
    EXPECT_NEAR(k / stokes(), 1.0, 0.1501 * std::pow(re, 0.687) + 1e-15) << "Re0=" << re;
  }
}

// ε → 1, what each dense law tends to (docs/models/fluid-forces.md, table "ε → 1"):
//  wen_yu, gidaspow, tenneti_garg_subramaniam: exactly Schiller–Naumann (Re < 1000);
//  rong: exactly di_felice (both reduce to the Dallavalle single-sphere drag);
//  di_felice: (0.63√Re + 4.8)²/24 × Stokes, 0.96 × Stokes as Re → 0;
//  koch_hill, beetstra: Stokes as Re → 0 (their own inertial fits above);
//  ergun: 1.75 ρ_f U V_p/d — a packed-bed law, no viscous part left, not Stokes.
TEST(DragLaws, DenseLawsAtVoidFractionOne) {
  auto k = [](const char* law, double eps, double re) {
    return drag_law(law).function(input(eps, slip_for(re, eps)));
  };
  for (double re : {1e-3, 1.0, 10.0, 100.0, 999.0}) {
    const double sn = k("schiller_naumann", 1, re);
    EXPECT_NEAR(k("wen_yu", 1, re) / sn, 1, 1e-14) << re;
    EXPECT_NEAR(k("gidaspow", 1, re) / sn, 1, 1e-14) << re;
    EXPECT_NEAR(k("tenneti_garg_subramaniam", 1, re) / sn, 1, 1e-14) << re;
    EXPECT_NEAR(k("rong", 1, re) / k("di_felice", 1, re), 1, 1e-14) << re;
    const double dallavalle = std::pow(0.63 * std::sqrt(re) + 4.8, 2) / 24;
    EXPECT_NEAR(k("di_felice", 1, re) / stokes() / dallavalle, 1, 1e-13) << re;
    const double u = slip_for(re, 1);
    EXPECT_NEAR(k("ergun", 1, re) / (1.75 * kRho * u * std::numbers::pi * kD * kD / 6), 1, 1e-13);
    // The laws are continuous into ε = 1 (no special case at φ = 0). Tenneti's
    // 0.48 φ^{1/3} and Koch–Hill's 3√(φ/2) approach slowly: at φ = 1e-15 they move K by
    // 5e-6 and 7e-8, hence 1e-5.
    for (const DragLaw& law : drag_laws())
      EXPECT_NEAR(law.function(input(1 - 1e-15, u)) / law.function(input(1, u)), 1, 1e-5)
          << law.name << " Re=" << re;
  }
  for (const char* law : {"koch_hill", "beetstra"})
    EXPECT_NEAR(k(law, 1, 1e-9) / stokes(), 1, 1e-4) << law;
  EXPECT_NEAR(k("di_felice", 1, 1e-12) / stokes(), 0.96, 1e-4);
  // Beetstra's ε = 1 limit is its own expression, F = 1 + (0.413 Re/24)(1 + 8.4 Re^−0.343)
  // /(1 + Re^−½): Stokes as Re → 0 but NOT Schiller–Naumann at finite Re (the fit covers
  // φ >= 0.1; Tenneti et al. 2011 note the same). The ratio to Schiller–Naumann is printed.
  for (double re : {1.0, 10.0, 100.0, 500.0}) {
    const double f = 1 + 0.413 * re / 24 * (1 + 8.4 * std::pow(re, -0.343)) / (1 + 1 / std::sqrt(re));
    EXPECT_NEAR(k("beetstra", 1, re) / stokes() / f, 1, 1e-13) << re;
    std::printf("beetstra/schiller_naumann at eps = 1, Re = %g: %.4f\n", re,
                k("beetstra", 1, re) / k("schiller_naumann", 1, re));
  }
}

// Dense Stokes limits agree: at Re → 0 and φ >= 0.4 Koch–Hill's F₀ = 10φ/ε³ is the
// Carman–Kozeny total force, so K/3πμd = 10φ/ε exactly; Beetstra's K/3πμd =
// 10φ/ε + ε³(1 + 1.5√φ) must be within that ε³ term of it (a normalisation slip of one ε
// between the two would show as a factor 1/ε ≈ 2). Tolerance: the ε³ term, 4 % at φ = 0.6.
TEST(DragLaws, DenseStokesLimitsAgree) {
  for (double eps : {0.4, 0.5, 0.6}) {
    const double phi = 1 - eps, u = slip_for(1e-12, eps);
    const double kh = drag_law("koch_hill").function(input(eps, u)) / stokes();
    const double bvk = drag_law("beetstra").function(input(eps, u)) / stokes();
    EXPECT_NEAR(kh, 10 * phi / eps, 1e-9 * kh);
    EXPECT_NEAR(bvk / kh, 1, std::pow(eps, 3) * (1 + 1.5 * std::sqrt(phi)) / kh + 1e-9) << eps;
  }
}

// K >= 0 and finite everywhere on a grid of (ε, Re) covering the laws' ranges and beyond,
// including Re = 0 and ε at its lower bound kLowestVoidFraction.
TEST(DragLaws, NonNegativeAndFiniteOnGrid) {
  for (const DragLaw& law : drag_laws())
    for (double eps = kLowestVoidFraction; eps <= 1 + 1e-12; eps += 0.05)
      for (double re : {0.0, 1e-8, 1e-3, 0.1, 1.0, 10.0, 100.0, 999.0, 1000.0, 1e4, 1e5}) {
        const double k = law.function(input(std::min(eps, 1.0), slip_for(re, std::min(eps, 1.0))));
        EXPECT_TRUE(std::isfinite(k) && k >= 0) << law.name << " eps=" << eps << " Re=" << re
                                                << " K=" << k;
      }
}

// Gidaspow switches from Ergun to Wen–Yu at ε = 0.8 with a jump (not a blend). At
// Re → 0 the closed forms give K/3πμd = 25φ/(3ε) = 25/12 below and 0.8^{−2.65} above.
TEST(DragLaws, GidaspowSwitchAtPointEight) {
  const double u = slip_for(1e-9, 0.8);
  const double below = gidaspow(input(std::nextafter(0.8, 0.0), u));
  const double at = gidaspow(input(0.8, u));
  EXPECT_NEAR(below / stokes(), 25.0 / 12.0, 1e-6);
  EXPECT_NEAR(at / stokes(), std::pow(0.8, -2.65), 1e-6);
  const double jump = at / below;
  std::printf("gidaspow jump at eps = 0.8, Re -> 0: wen_yu/ergun = %.4f\n", jump);
  EXPECT_NEAR(jump, 0.867, 1e-3);
  EXPECT_EQ(at, wen_yu(input(0.8, u)));
  EXPECT_EQ(below, ergun(input(std::nextafter(0.8, 0.0), u)));
}

}  // namespace
}  // namespace grainflow
