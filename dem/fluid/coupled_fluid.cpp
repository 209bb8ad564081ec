#include "dem/fluid/coupled_fluid.hpp"

#include <stdexcept>
#include <string>

namespace grainflow {

void CoupledFluid::set(std::vector<GlobalId> ids, std::vector<FluidSample> samples) {
  if (ids.size() != samples.size())
    throw std::invalid_argument("CoupledFluid::set: " + std::to_string(ids.size()) + " ids but " +
                                std::to_string(samples.size()) + " samples");
  ids_ = std::move(ids);
  spare_ = std::move(samples_);
  samples_ = std::move(samples);
  index_.clear();
  remapped_ = false;  // the samples themselves serve the particles while their order holds
}

const std::vector<FluidSample>& CoupledFluid::at_particles(const Particles& p) {
  if (!remapped_ && p.id == ids_) return samples_;
  if (remapped_ && p.id == mapped_ids_) return mapped_;
  if (index_.empty()) {
    index_.reserve(ids_.size());
    for (std::size_t k = 0; k < ids_.size(); ++k) index_.emplace(ids_[k], k);
  }
  mapped_.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto it = index_.find(p.id[i]);
    if (it != index_.end()) {
      mapped_[i] = samples_[it->second];
      continue;
    }
    if (!sampler_)
      throw std::logic_error("particle " + std::to_string(p.id[i]) +
                             " has no fluid sample and the coupling set no sampler");
    mapped_[i] = sampler_(p.x[i]);
    // Keep it for later re-maps within this interval.
    index_.emplace(p.id[i], samples_.size());
    ids_.push_back(p.id[i]);
    samples_.push_back(mapped_[i]);
    ++late_;
  }
  mapped_ids_ = p.id;
  remapped_ = true;
  return mapped_;
}

}  // namespace grainflow
