#pragma once
// Where a time step sits on the measured accuracy curve (docs/accuracy-vs-cost.md).
//
// benchmarks/accuracy_cost measures the relative error of a sphere-wall impact, in
// restitution (against the requested e) and in contact time (against the closed form),
// as a function of the number of steps per impact N = t_c / dt, t_c counted as
// `grain check` counts it (time_step.hpp: elastic Hertz, damped Hooke). Scaled by its own
// overlap and time, an impact has no parameter left but the damping (restitution_mapping.hpp
// for Hertz; the damping ratio for Hooke), so the error depends on N and e alone — not on
// material, size or speed; the benchmark checks this collapse. Each point is the statistics
// over impacts starting at every offset within a step and lasting N - 1/2 ... N + 1/2 steps.
//
// The measured table is compiled in (time_step_accuracy_table.hpp, written by
// benchmarks/accuracy_cost/report.py). Between its points errors are interpolated linearly
// in (log N, log error), between restitution values linearly in (e, log error).
#include <span>

#include "dem/scene/scene.hpp"

namespace grainflow {

struct ImpactAccuracy {
  double restitution_rms = 0;  // relative error of e: root mean square over impacts
  double restitution_max = 0;  // and the largest magnitude
  double contact_time_rms = 0;
  double contact_time_max = 0;
  // Outside the measured range. Coarser than measured: the values are those of the coarsest
  // point, a lower bound. Finer than measured (or e below the lowest measured): the end
  // segment extended, an extrapolation.
  bool coarser_than_measured = false;
  bool extrapolated = false;
  // e below the lowest measured restitution: the values are that curve's, a lower bound (the
  // errors grow as e falls).
  double below_restitution = 0;  // the lowest measured e when below it, else 0
};

// Errors of an impact of the given model and restitution resolved by `steps_per_impact` steps,
// with the dashpots of contact.dashpot_velocity (both measured over the same steps).
ImpactAccuracy impact_accuracy(NormalModel model, double restitution, double steps_per_impact,
                               DashpotVelocity dashpot = DashpotVelocity::half_step);

// Measured range of steps per impact (smallest, largest) for the model.
std::pair<double, double> measured_steps_per_impact(NormalModel model);

// y at x from points (xs strictly ascending, ys > 0) by linear interpolation in (log x, log y);
// beyond either end the end segment is extended (a power law).
double interpolate_log_log(std::span<const double> xs, std::span<const double> ys, double x);

}  // namespace grainflow
