#pragma once
// The time scales of heat transfer against dt (DESIGN.md §9), for `grain check` and start-up
// (docs/models/heat-transfer.md, "Limits"):
//   conduction through the stiffest contact: tau_k = m c / (2 k* a), a = sqrt(R* delta) at
//     the largest overlap the run allows (time.max_overlap of the smaller radius), for the
//     smallest particle of each material against each material and each fixed-temperature
//     wall. Explicit: with z such contacts a particle's temperature is stable for
//     dt < tau_k / z (Gershgorin); z = 12, the most equal spheres can have, is refused
//     beyond and warned above a tenth of it.
//   convection of the smallest particle, at rest in the prescribed flow:
//     tau_h = m c / (h A); implicit, stable at any dt, warned above 0.2 tau_h (the implicit
//     step's lag, dt / (2 tau_h), reaches 10 %).
#include "dem/core/particles.hpp"
#include "dem/engine/time_step.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

constexpr double kThermalContacts = 12;       // contacts per particle for the conduction limit
constexpr double kWarnConductionFraction = 0.1;  // of the stability limit
constexpr double kWarnConvectionFraction = 0.2;  // dt / tau_h

struct ThermalLimits {
  double conduction_time = 0;  // tau_k, smallest; infinity when no contact conducts
  double convection_time = 0;  // tau_h, smallest; infinity without convection
};

// Adds the notes (and the verdict) to `rep` (rep.dt set); returns the time scales.
ThermalLimits check_thermal_limits(const Scene& scene, const Particles& p, TimeStepReport& rep);

}  // namespace grainflow
