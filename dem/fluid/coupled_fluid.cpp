#include "dem/fluid/coupled_fluid.hpp"

#include <stdexcept>
#include <string>

namespace grainflow {

void CoupledFluid::set(std::vector<GlobalId> ids, std::vector<CoupledSample> samples,
                       std::vector<Vec3> vorticity, std::vector<SelfDisturbance> disturbance,
                       std::vector<double> temperature, std::vector<Vec3> cell_velocity) {
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
  if (!temperature.empty() && temperature.size() != samples.size())
    throw std::invalid_argument("CoupledFluid::set: " + std::to_string(samples.size()) +
                                " samples but " + std::to_string(temperature.size()) +
                                " temperatures");
  if (!cell_velocity.empty() && cell_velocity.size() != samples.size())
    throw std::invalid_argument("CoupledFluid::set: " + std::to_string(samples.size()) +
                                " samples but " + std::to_string(cell_velocity.size()) +
                                " cell velocities");
  ids_ = std::move(ids);
  spare_ = std::move(samples_);
  samples_ = std::move(samples);
  spare_vorticity_ = std::move(vorticity_);
  vorticity_ = std::move(vorticity);
  spare_disturbance_ = std::move(disturbance_);
  disturbance_ = std::move(disturbance);
  spare_temperature_ = std::move(temperature_);
  temperature_ = std::move(temperature);
  spare_cell_velocity_ = std::move(cell_velocity_);
  cell_velocity_ = std::move(cell_velocity);
  if (!temperature_.empty()) {
    heat_.assign(temperature_.size(), 0.0);
    heat_conductance_.assign(temperature_.size(), 0.0);
    heat_x_.assign(temperature_.size(), Vec3::Zero());
  }
  index_.clear();
  remapped_ = false;  // the samples themselves serve the particles while their order holds
}

CoupledFluid::View CoupledFluid::at_particles(const Particles& p) {
  const bool curl = !vorticity_.empty(), self = !disturbance_.empty();
  const bool heat = !temperature_.empty(), cells = !cell_velocity_.empty();
  const auto view = [curl, self, heat, cells](
                        const std::vector<CoupledSample>& s, const std::vector<Vec3>& w,
                        const std::vector<SelfDisturbance>& d, const std::vector<double>& t,
                        const std::size_t* entry, const std::vector<Vec3>& u) {
    return View{s.data(),          curl ? w.data() : nullptr, self ? d.data() : nullptr,
                heat ? t.data() : nullptr, entry, s.size(), cells ? u.data() : nullptr};
  };
  if (!remapped_ && p.id == ids_)
    return view(samples_, vorticity_, disturbance_, temperature_, nullptr, cell_velocity_);
  if (remapped_ && p.id == mapped_ids_)
    return view(mapped_, mapped_vorticity_, mapped_disturbance_, mapped_temperature_,
                heat ? mapped_entry_.data() : nullptr, mapped_cell_velocity_);
  if (index_.empty()) {
    index_.reserve(ids_.size());
    for (std::size_t k = 0; k < ids_.size(); ++k) index_.emplace(ids_[k], k);
  }
  mapped_.resize(p.size());
  if (curl) mapped_vorticity_.resize(p.size());
  if (self) mapped_disturbance_.resize(p.size());
  if (cells) mapped_cell_velocity_.resize(p.size());
  if (heat) {
    mapped_temperature_.resize(p.size());
    mapped_entry_.resize(p.size());
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto it = index_.find(p.id[i]);
    if (it != index_.end()) {
      mapped_[i] = samples_[it->second];
      if (curl) mapped_vorticity_[i] = vorticity_[it->second];
      if (self) mapped_disturbance_[i] = disturbance_[it->second];
      if (cells) mapped_cell_velocity_[i] = cell_velocity_[it->second];
      if (heat) {
        mapped_temperature_[i] = temperature_[it->second];
        mapped_entry_[i] = it->second;
      }
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
    // A late arrival is sampled in the cell that holds it: its cell velocity is its sample.
    if (cells) {
      mapped_cell_velocity_[i] = f.velocity;
      cell_velocity_.push_back(f.velocity);
    }
    if (heat) {
      mapped_temperature_[i] = f.temperature;
      mapped_entry_[i] = temperature_.size();
      temperature_.push_back(f.temperature);
      heat_.push_back(0.0);
      heat_conductance_.push_back(0.0);
      heat_x_.push_back(p.x[i]);
    }
    ++late_;
  }
  mapped_ids_ = p.id;
  remapped_ = true;
  return view(mapped_, mapped_vorticity_, mapped_disturbance_, mapped_temperature_,
              heat ? mapped_entry_.data() : nullptr, mapped_cell_velocity_);
}

}  // namespace grainflow
