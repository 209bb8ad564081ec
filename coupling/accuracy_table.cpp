#include "coupling/accuracy_table.hpp"

#include <cmath>
#include <cstdio>
#include <iterator>
#include <sstream>
#include <vector>

namespace grainflow::coupling {
namespace {

std::string percent(double x, int decimals = 1) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.*f %%", decimals, 100 * x);
  return buf;
}

std::string number(double x, int digits = 3) {
  std::ostringstream out;
  out.precision(digits);
  out << x;
  return out.str();
}

bool near(double a, double b) { return std::abs(a - b) <= kRelativeTolerance * std::abs(b); }

// x within [lo, hi], the ends with the tolerance; returns x moved onto an end it is near.
bool within(double x, double lo, double hi, double& snapped) {
  snapped = near(x, lo) ? lo : near(x, hi) ? hi : x;
  return snapped >= lo && snapped <= hi;
}

std::string footprint_line(const CoupledSettings& s) {
  std::ostringstream out;
  out << "footprint " << s.method << ", sampling " << s.sampling << ", cells of "
      << number(s.cell_over_d) << " d: ";
  if (s.regime != Regime::packed_bed || s.drag != kFootprintDrag) {
    out << "no measured table (the footprint sweep is a packed bed with drag " << kFootprintDrag
        << ")";
    return out.str();
  }
  std::vector<FootprintAccuracy> pts;
  for (const FootprintAccuracy& a : kFootprintAccuracy)
    if (s.method == a.method && s.sampling == a.sampling) pts.push_back(a);
  double x = 0;
  if (pts.size() < 2 || !within(s.cell_over_d, pts.front().cell_over_d, pts.back().cell_over_d, x)) {
    out << "outside the measured 2-4 d";
    return out.str();
  }
  for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
    const FootprintAccuracy &a = pts[k], &b = pts[k + 1];
    if (x > b.cell_over_d) continue;
    const double f = (x - a.cell_over_d) / (b.cell_over_d - a.cell_over_d);
    out << "packed-bed pressure drop vs Ergun " << percent(a.dp_error + f * (b.dp_error - a.dp_error))
        << ", coupling " << std::lround(100 * (a.coupling_share + f * (b.coupling_share - a.coupling_share)))
        << " % of CPU (measured at " << kFootprintSteps << " DEM steps per fluid step)";
    break;
  }
  return out.str();
}

std::string interval_line(const CoupledSettings& s) {
  std::ostringstream out;
  out << s.steps_per_fluid << " DEM steps per fluid step: ";
  const IntervalSweep* sweep = nullptr;
  for (const IntervalSweep& w : kIntervalSweeps)
    if (w.regime == s.regime && s.drag == w.drag) sweep = &w;
  if (!sweep) {
    out << "no measured table (the interval sweeps are a packed bed with drag gidaspow and a "
           "single settling sphere with drag schiller_naumann)";
    return out.str();
  }
  if (s.method != sweep->method || s.sampling != sweep->sampling ||
      !near(s.cell_over_d, sweep->cell_over_d)) {
    out << "no measured table for these settings (the " << sweep->name << " sweep used footprint " << sweep->method << ", sampling " << sweep->sampling
        << ", cells of " << number(sweep->cell_over_d) << " d)";
    return out.str();
  }
  const IntervalAccuracy* iv = sweep->rows;
  const int last = sweep->size - 1;
  if (s.steps_per_fluid < iv[0].steps_per_fluid || s.steps_per_fluid > iv[last].steps_per_fluid) {
    out << "outside the measured " << iv[0].steps_per_fluid << "-" << iv[last].steps_per_fluid;
    return out.str();
  }
  for (int k = 0; k < last; ++k) {
    if (s.steps_per_fluid > iv[k + 1].steps_per_fluid) continue;
    const double f = std::log(double(s.steps_per_fluid) / iv[k].steps_per_fluid) /
                     std::log(double(iv[k + 1].steps_per_fluid) / iv[k].steps_per_fluid);
    // Two decimals: the settling sphere's errors differ by 0.04 points over N = 1-100.
    out << sweep->quantity << " " << percent(iv[k].error + f * (iv[k + 1].error - iv[k].error), 2)
        << " (measured " << percent(iv[0].error, 2) << " at N = " << iv[0].steps_per_fluid << ", "
        << percent(iv[last].error, 2) << " at N = " << iv[last].steps_per_fluid << ")";
    break;
  }
  return out.str();
}

}  // namespace

Regime classify_regime(long particles, double mean_void_fraction_at_particles) {
  if (particles == 1) return Regime::single_particle;
  if (particles > 1 && mean_void_fraction_at_particles <= kPackedBedMaxVoidFraction)
    return Regime::packed_bed;
  return Regime::other;
}

const char* regime_name(Regime r) {
  switch (r) {
    case Regime::packed_bed: return "packed bed";
    case Regime::single_particle: return "single particle";
    case Regime::other: break;
  }
  return "neither a packed bed nor a single particle";
}

std::string describe_coupled_accuracy(const CoupledSettings& s) {
  std::ostringstream out;
  out << "accuracy (docs/accuracy-vs-cost-coupled.md): " << regime_name(s.regime)
      << " (mean void fraction at the particles " << number(s.mean_void_fraction, 4) << "), drag "
      << s.drag << "\n  ";
  if (s.regime == Regime::other) {
    out << "no measured table matches: the tables are a packed bed (void fraction at the "
           "particles <= "
        << kPackedBedMaxVoidFraction << ", drag gidaspow) and a single settling sphere (drag "
                                        "schiller_naumann)";
    return out.str();
  }
  if (s.drag_void_fraction != "cell") {
    out << "dragVoidFraction " << s.drag_void_fraction
        << ": no measured table here (the tables are for dragVoidFraction cell); its fixed-bed "
           "measurements are in docs/models/bed-surface.md";
    return out.str();
  }
  if (s.diffusion_bandwidth_over_d > 0) {
    out << "diffusionBandwidth " << number(s.diffusion_bandwidth_over_d, 3)
        << " d: no measured table here (the tables are without averaging); its hindered-"
           "settling measurements are in docs/models/undisturbed-velocity.md";
    return out.str();
  }
  out << footprint_line(s) << "\n  " << interval_line(s);
  return out.str();
}

}  // namespace grainflow::coupling
