#include "dem/engine/time_step_accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "dem/engine/time_step_accuracy_table.hpp"

namespace grainflow {

double interpolate_log_log(std::span<const double> xs, std::span<const double> ys, double x) {
  if (xs.size() != ys.size() || xs.size() < 2)
    throw std::invalid_argument("interpolate_log_log needs two or more points, as many x as y");
  // The segment holding x, or the end segment beyond either end.
  const auto upper = std::upper_bound(xs.begin() + 1, xs.end() - 1, x);
  const std::size_t k = static_cast<std::size_t>(std::distance(xs.begin(), upper)) - 1;
  const double lx0 = std::log(xs[k]), lx1 = std::log(xs[k + 1]);
  const double ly0 = std::log(ys[k]), ly1 = std::log(ys[k + 1]);
  return std::exp(ly0 + (ly1 - ly0) * (std::log(x) - lx0) / (lx1 - lx0));
}

namespace {

constexpr double kFloor = 1e-12;  // errors below round-off are stored as this (log-safe)

ImpactAccuracy on_curve(const measured::ImpactCurve& c, double n) {
  auto at = [&](const double(&ys)[measured::kImpactPoints]) {
    double clean[measured::kImpactPoints];
    for (int k = 0; k < measured::kImpactPoints; ++k) clean[k] = std::max(ys[k], kFloor);
    return interpolate_log_log(c.steps, clean, std::max(n, c.steps[0]));
  };
  ImpactAccuracy a;
  a.restitution_rms = at(c.restitution_rms);
  a.restitution_max = at(c.restitution_max);
  a.contact_time_rms = at(c.contact_time_rms);
  a.contact_time_max = at(c.contact_time_max);
  a.coarser_than_measured = n < c.steps[0];
  a.extrapolated = n > c.steps[measured::kImpactPoints - 1];
  return a;
}

std::vector<const measured::ImpactCurve*> curves_of(NormalModel model, DashpotVelocity dashpot) {
  std::vector<const measured::ImpactCurve*> out;
  for (const measured::ImpactCurve& c : measured::kImpactCurves)
    if (c.hooke == (model == NormalModel::hooke) &&
        c.predicted == (dashpot == DashpotVelocity::predicted))
      out.push_back(&c);
  std::sort(out.begin(), out.end(),
            [](auto* a, auto* b) { return a->restitution < b->restitution; });
  return out;
}

}  // namespace

std::pair<double, double> measured_steps_per_impact(NormalModel model) {
  double lo = 1e300, hi = 0;
  for (const measured::ImpactCurve* c : curves_of(model, DashpotVelocity::half_step)) {
    lo = std::min(lo, c->steps[0]);
    hi = std::max(hi, c->steps[measured::kImpactPoints - 1]);
  }
  return {lo, hi};
}

ImpactAccuracy impact_accuracy(NormalModel model, double restitution, double steps_per_impact,
                               DashpotVelocity dashpot) {
  const std::vector<const measured::ImpactCurve*> curves = curves_of(model, dashpot);
  if (curves.empty()) throw std::logic_error("no measured impact curve for this normal model");
  if (restitution <= curves.front()->restitution) {
    ImpactAccuracy a = on_curve(*curves.front(), steps_per_impact);
    if (restitution < curves.front()->restitution)
      a.below_restitution = curves.front()->restitution;
    return a;
  }
  if (restitution >= curves.back()->restitution) return on_curve(*curves.back(), steps_per_impact);
  std::size_t k = 1;
  while (curves[k]->restitution < restitution) ++k;
  if (curves[k]->restitution == restitution) return on_curve(*curves[k], steps_per_impact);
  const ImpactAccuracy lo = on_curve(*curves[k - 1], steps_per_impact);
  const ImpactAccuracy hi = on_curve(*curves[k], steps_per_impact);
  const double w = (restitution - curves[k - 1]->restitution) /
                   (curves[k]->restitution - curves[k - 1]->restitution);
  auto mix = [w](double a, double b) { return std::exp((1 - w) * std::log(a) + w * std::log(b)); };
  ImpactAccuracy a;
  a.restitution_rms = mix(lo.restitution_rms, hi.restitution_rms);
  a.restitution_max = mix(lo.restitution_max, hi.restitution_max);
  a.contact_time_rms = mix(lo.contact_time_rms, hi.contact_time_rms);
  a.contact_time_max = mix(lo.contact_time_max, hi.contact_time_max);
  a.coarser_than_measured = lo.coarser_than_measured || hi.coarser_than_measured;
  a.extrapolated = lo.extrapolated || hi.extrapolated;
  return a;
}

}  // namespace grainflow
