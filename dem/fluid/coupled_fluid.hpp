#pragma once
// The fluid state at this rank's particles when a fluid solver supplies it (two-way
// coupling, coupling/dem_link.hpp): the coupling samples the fluid at every local
// particle once per fluid step; the DEM then advances several sub-steps with those
// samples. Between two fluid steps particles may be re-sorted or migrate between ranks,
// so samples are kept by global id and re-mapped to the particles' current order when
// the order changes. A particle that arrived from another rank during the interval has
// no sample here: it is sampled on arrival through the coupling's sampler (it now lies
// in this rank's cells) and counted (late_samples).
//
// The fluid-force term writes back, per particle, the explicit part of the force that
// the fluid gets through the exchange term (exchange_force, in the particles' order of
// the last step): which forces that includes depends on the VANS model (vans_model.hpp).
#include <functional>
#include <unordered_map>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/fluid/fluid_sample.hpp"

namespace grainflow {

class CoupledFluid {
 public:
  using Sampler = std::function<FluidSample(const Vec3& x)>;

  // Samples of the particles `ids` (any order). Replaces the previous set.
  void set(std::vector<GlobalId> ids, std::vector<FluidSample> samples);
  // The storage of the set before the last set() (its values stale), for the next set to
  // be written into without a new allocation each fluid step; empty if taken already.
  std::vector<FluidSample> take_spare() { return std::move(spare_); }
  void set_sampler(Sampler sampler) { sampler_ = std::move(sampler); }

  // The samples in the current order of `p` (cheap when the order has not changed).
  const std::vector<FluidSample>& at_particles(const Particles& p);

  long late_samples() const { return late_; }
  void reset_late_samples() { late_ = 0; }

  // Per particle of the last step, in its order: the explicit force on the particle
  // that the fluid gets back (with opposite sign) through the exchange term [N].
  std::vector<Vec3> exchange_force;

 private:
  std::vector<GlobalId> ids_;
  std::vector<FluidSample> samples_;
  std::vector<FluidSample> spare_;  // the previous samples_ (take_spare)
  std::unordered_map<GlobalId, std::size_t> index_;  // built on the first re-map after set()
  // After a re-sort, migration or late arrival: the samples in the particles' new order.
  // Until then the samples are served as set (no copy per fluid step).
  bool remapped_ = false;
  std::vector<GlobalId> mapped_ids_;                 // order of `mapped_`
  std::vector<FluidSample> mapped_;
  Sampler sampler_;
  long late_ = 0;
};

}  // namespace grainflow
