#include "dem/fluid/coupled_fluid.hpp"

#include <stdexcept>
#include <string>

namespace grainflow {

void CoupledFluid::set(std::vector<GlobalId> ids, std::vector<CoupledSample> samples,
                       std::vector<Vec3> vorticity, std::vector<SelfDisturbance> disturbance) {
  if (ids.size() != samples.size())
    throw std::invalid_argument("CoupledFluid::set: " + std::to_string(ids.size()) + " ids but " +
                                std::to_string(samples.size()) + " samples");
  if (!vorticity.empty() && vorticity.size() != samples.size())
    throw std::invalid_argument("CoupledFluid::set: " + std::to_string(samples.size()) +
                                " samples but " + std::to_string(vorticity.size()) +
                                " vorticities");
  if (!disturbance.empty() && disturbance.size() != samples.size())
    throw std::invalid_argument("CoupledFluid::set: " + std::to_string(samples.size()) +
                                " samples but " + std::to_string(disturbance.size()) +
                                " self-disturbances");
  ids_ = std::move(ids);
  spare_ = std::move(samples_);
  samples_ = std::move(samples);
  spare_vorticity_ = std::move(vorticity_);
  vorticity_ = std::move(vorticity);
  spare_disturbance_ = std::move(disturbance_);
  disturbance_ = std::move(disturbance);
  index_.clear();
  remapped_ = false;  // the samples themselves serve the particles while their order holds
}

CoupledFluid::View CoupledFluid::at_particles(const Particles& p) {
  const bool curl = !vorticity_.empty(), self = !disturbance_.empty();
  const auto view = [curl, self](const std::vector<CoupledSample>& s, const std::vector<Vec3>& w,
                                 const std::vector<SelfDisturbance>& d) {
    return View{s.data(), curl ? w.data() : nullptr, self ? d.data() : nullptr, s.size()};
  };
  if (!remapped_ && p.id == ids_) return view(samples_, vorticity_, disturbance_);
  if (remapped_ && p.id == mapped_ids_)
    return view(mapped_, mapped_vorticity_, mapped_disturbance_);
  if (index_.empty()) {
    index_.reserve(ids_.size());
    for (std::size_t k = 0; k < ids_.size(); ++k) index_.emplace(ids_[k], k);
  }
  mapped_.resize(p.size());
  if (curl) mapped_vorticity_.resize(p.size());
  if (self) mapped_disturbance_.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto it = index_.find(p.id[i]);
    if (it != index_.end()) {
      mapped_[i] = samples_[it->second];
      if (curl) mapped_vorticity_[i] = vorticity_[it->second];
      if (self) mapped_disturbance_[i] = disturbance_[it->second];
      continue;
    }
    if (!sampler_)
      throw std::logic_error("particle " + std::to_string(p.id[i]) +
                             " has no fluid sample and the coupling set no sampler");
    const FluidSample f = sampler_(p.x[i]);
    mapped_[i] = CoupledSample{f.velocity, f.void_fraction, f.pressure_gradient,
                               f.viscous_stress_divergence};
    // Keep it for later re-maps within this interval.
    index_.emplace(p.id[i], samples_.size());
    ids_.push_back(p.id[i]);
    samples_.push_back(mapped_[i]);
    if (curl) {
      mapped_vorticity_[i] = f.vorticity;
      vorticity_.push_back(f.vorticity);
    }
    // A late arrival's disturbance is not known: its drag takes the sampled velocity.
    if (self) {
      mapped_disturbance_[i] = SelfDisturbance{};
      disturbance_.push_back(SelfDisturbance{});
    }
    ++late_;
  }
  mapped_ids_ = p.id;
  remapped_ = true;
  return view(mapped_, mapped_vorticity_, mapped_disturbance_);
}

}  // namespace grainflow
