#include "dem/engine/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "dem/insert/insertion.hpp"
#include "dem/walls/stl_reader.hpp"

namespace grainflow {
namespace {
bool is_set(const ContactHistory& h) { return !h.tangential.isZero(0) || !h.rolling.isZero(0); }

template <class T>
void keep_unflagged(std::vector<T>& a, const std::vector<char>& drop) {
  std::size_t w = 0;
  for (std::size_t r = 0; r < a.size(); ++r)
    if (!drop[r]) {
      if (w != r) a[w] = std::move(a[r]);  // a self-move would empty a vector element
      ++w;
    }
  a.resize(w);
}

template <class T>
void reorder(std::vector<T>& a, const std::vector<std::size_t>& perm) {
  std::vector<T> out;
  out.reserve(perm.size());
  for (std::size_t k : perm) out.push_back(std::move(a[k]));
  a.swap(out);
}
}  // namespace

Simulation::Simulation(const Scene& scene, bool insert, MPI_Comm comm,
                       std::array<int, 3> processor_grid)
    : scene_(scene), comm_(comm), table_(scene) {
  if (processor_grid == std::array<int, 3>{0, 0, 0}) processor_grid = scene.parallel.grid;
  automatic_grid_ = processor_grid == std::array<int, 3>{0, 0, 0};
  try {
    decomp_ = std::make_unique<Decomposition>(comm, scene.domain, processor_grid);
  } catch (const std::invalid_argument& e) {
    throw SetupError(scene_.file + ": error: " + e.what() +
                     "; change `parallel.grid` or the number of MPI ranks");
  }
  exchange_ = std::make_unique<Exchange>(*decomp_);
  constants_.hooke_characteristic_velocity =
      scene.contact.hooke_characteristic_velocity.value_or(0.0);
  constants_.hooke_kn = scene.contact.hooke_kn.value_or(0.0);
  constants_.hooke_kt = scene.contact.hooke_kt.value_or(constants_.hooke_kn);
  constants_.epsd_damping_ratio = scene.contact.epsd_damping_ratio;
  sweep_ = select_sweep(scene.contact);
  try {
    walls_ = WallSet(scene_);  // reads STL meshes
  } catch (const GeometryError& e) {
    throw SetupError(e.what());
  }
  streams_ = StreamInsertion(scene_);
  if (insert) insert_particles(scene_, p_, next_id_, &walls_);
}

void Simulation::initialise() {
  double r_max = 0;
  for (double r : p_.radius) r_max = std::max(r_max, r);
  r_max = std::max(r_max, streams_.max_radius());  // particles still to come
  MPI_Allreduce(MPI_IN_PLACE, &r_max, 1, MPI_DOUBLE, MPI_MAX, comm_);
  const Vec3 length = decomp_->length();
  if (r_max == 0) r_max = length.minCoeff() / 100;  // empty scene: any grid works
  skin_ = scene_.neighbour.skin.value_or(0.4 * r_max);
  cutoff_ = 2 * r_max + skin_;
  for (int a = 0; a < 3; ++a)
    if (scene_.domain.periodic[a] && length[a] < 2 * cutoff_) {
      std::ostringstream msg;
      msg << scene_.file << ": error: periodic axis " << "xyz"[a] << " is " << length[a]
          << " m long, shorter than twice the interaction range (2 r_max + skin = " << cutoff_
          << " m); enlarge the domain along it or reduce the skin";
      throw SetupError(msg.str());
    }
  if (automatic_grid_ && !cuts_imposed_ && decomp_->size() > 1) fit_grid_to_domain();
  for (int a = 0; a < 3; ++a)
    if (decomp_->dims()[a] > 1 && decomp_->thinnest_box() < cutoff_) {
      std::ostringstream msg;
      msg << scene_.file << ": error: with " << decomp_->dims()[0] << " x " << decomp_->dims()[1]
          << " x " << decomp_->dims()[2] << " ranks, a subdomain is " << decomp_->thinnest_box()
          << " m thick, thinner than the interaction range (2 r_max + skin = " << cutoff_
          << " m); use fewer MPI ranks";
      throw SetupError(msg.str());
    }

  // Every rank holds the same full set here: the report is the same everywhere.
  report_ = check_time_step(scene_, p_, table_, constants_);
  if (dt_ <= 0) dt_ = report_.dt;
  if (dt_ <= 0)
    throw SetupError(scene_.file +
                     ": error: time.rayleigh_fraction needs particles to size the time step; "
                     "give time.step instead");

  std::vector<char> foreign(p_.size());
  for (std::size_t i = 0; i < p_.size(); ++i) foreign[i] = !decomp_->owns(p_.x[i]);
  p_.remove_if(foreign);
  if (!restored_springs_.empty()) {
    // Each rank keeps the springs of the particles it owns (the file lists a pair's
    // spring under each partner).
    CarriedState c;
    c.springs = CarriedSprings(sweep_.keeps_tangential, sweep_.keeps_rolling);
    std::vector<GlobalId> owned = p_.id;
    std::sort(owned.begin(), owned.end());
    for (const CheckpointSpring& sp : restored_springs_) {
      if (!std::binary_search(owned.begin(), owned.end(), sp.particle)) continue;
      if (sp.partner >= 0)
        c.springs.add_pair(sp.particle, sp.partner, sp.tangential, sp.rolling);
      else if (static_cast<std::size_t>(-1 - sp.partner) < walls_.history_columns())
        c.springs.add_wall(sp.particle, static_cast<int>(-1 - sp.partner),
                           {sp.tangential, sp.rolling});
    }
    pending_carried_ = std::move(c);
    restored_springs_.clear();
  }

  grid_ = std::make_unique<BinGrid>(decomp_->lo() - Vec3::Constant(cutoff_),
                                    decomp_->hi() + Vec3::Constant(cutoff_), cutoff_);
  walls_.move_to(time_);
  walls_.fit_grids(r_max);  // mesh search cells of one particle diameter
  const bool restoring = restored_;
  mark_leaving();
  rebuild();
  // A restored run keeps the checkpoint's forces: evaluating the contacts again
  // would advance every spring a second time for the same step, and the force terms
  // are already in them. Only the implicit drag is set, from the checkpoint.
  if (restoring)
    restore_implicit_drag();
  else
    check_contacts(compute_forces(), true);
  initialised_ = true;
}

void Simulation::mark_leaving() {
  const Domain& d = scene_.domain;
  leaving_.clear();
  for (std::size_t i = 0; i < p_.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (!d.periodic[a] && (p_.x[i][a] < d.lo[a] || p_.x[i][a] > d.hi[a])) {
        leaving_.resize(p_.size(), 0);
        leaving_[i] = 1;
      }
}

void Simulation::kick_and_drift() {
  // One pass over the particles: the first half kick (as half_kick()), x += dt v, then the
  // tests of mark_leaving() and of the skin on the new x, and the largest |v|^2 for
  // contact_may_be_unresolved(). The kick is the last use of the step's forces, so the same
  // pass sets them to gravity for the next evaluation (compute_forces()). Each particle's
  // operations are those of the separate passes, in the same order. A periodic side has
  // infinite bounds here: nothing leaves through it.
  const Domain& d = scene_.domain;
  constexpr double inf = std::numeric_limits<double>::infinity();
  Vec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = d.periodic[a] ? -inf : d.lo[a];
    hi[a] = d.periodic[a] ? inf : d.hi[a];
  }
  const double limit2 = 0.25 * skin_ * skin_;
  const std::size_t n = p_.size();
  // The arrays' addresses and dt read once: a store through x could otherwise change them.
  const double dt = dt_, h = 0.5 * dt_;
  Vec3* xs = p_.x.data();
  Vec3* vs = p_.v.data();
  Vec3* ws = p_.omega.data();
  Vec3* force = p_.force.data();
  Vec3* torque = p_.torque.data();
  const Vec3 g = scene_.gravity;
  const double* mass = p_.mass.data();
  const double* inertia = p_.inertia.data();
  const double* drag_k = drag_.coefficient.data();
  const Vec3* fluid_u = drag_.fluid_velocity.data();
  const Vec3* built = x_at_build_.data();
  leaving_.clear();
  const auto pass = [&]<bool Drag, bool Spin>() {
    bool moved_far = false;
    double v2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      Vec3& v = vs[i];
      if constexpr (!Drag) {
        v += (h / mass[i]) * force[i];
      } else {
        const double a = h / mass[i], k = drag_k[i];
        v = (v + a * (force[i] + k * fluid_u[i])) / (1 + a * k);
      }
      if constexpr (Spin) ws[i] += (h / inertia[i]) * torque[i];
      force[i] = mass[i] * g;
      torque[i].setZero();
      Vec3& x = xs[i];
      x += dt * v;
      moved_far |= (x - built[i]).squaredNorm() > limit2;
      // | rather than ||: one branch, taken only by a particle that leaves.
      if ((x[0] < lo[0]) | (x[0] > hi[0]) | (x[1] < lo[1]) | (x[1] > hi[1]) | (x[2] < lo[2]) |
          (x[2] > hi[2])) [[unlikely]] {
        leaving_.resize(n, 0);
        leaving_[i] = 1;
      }
      v2 = std::max(v2, v.squaredNorm());
    }
    moved_beyond_half_skin_ = moved_far;
    local_speed2_ = v2;
  };
  const bool drag = !drag_.coefficient.empty(), spin = sweep_.needs_spin;
  if (drag)
    spin ? pass.template operator()<true, true>() : pass.template operator()<true, false>();
  else
    spin ? pass.template operator()<false, true>() : pass.template operator()<false, false>();
  fresh_from_kick_ = true;
}

bool Simulation::needs_rebuild() const {
  int local = !leaving_.empty() || moved_beyond_half_skin_;
  if (decomp_->size() == 1) return local;
  int any = 0;
  MPI_Allreduce(&local, &any, 1, MPI_INT, MPI_LOR, comm_);
  return any;
}

CarriedState Simulation::take_histories() {
  CarriedState c;
  c.springs = CarriedSprings(sweep_.keeps_tangential, sweep_.keeps_rolling);
  if (sweep_.has_history) {
    // Counted first, so that the records take one allocation of the exact size.
    const std::size_t lists = local_list_.offsets.size();
    std::size_t pairs = 0, walls = 0;
    for (std::size_t i = 0; i + 1 < lists; ++i) {
      for (int k = local_list_.offsets[i]; k < local_list_.offsets[i + 1]; ++k)
        pairs += is_set(local_springs_[k]);
      for (int k = ghost_list_.offsets[i]; k < ghost_list_.offsets[i + 1]; ++k)
        pairs += is_set(ghost_springs_[k]);
    }
    for (const auto& column : wall_history_)
      for (const ContactHistory& h : column) walls += is_set(h);
    c.springs.reserve(pairs, walls);
    for (std::size_t i = 0; i + 1 < lists; ++i) {
      for (int k = local_list_.offsets[i]; k < local_list_.offsets[i + 1]; ++k)
        if (const ContactHistory h = local_springs_[k]; is_set(h))
          c.springs.add_pair(p_.id[i], p_.id[local_list_.j[k]], h.tangential, h.rolling);
      for (int k = ghost_list_.offsets[i]; k < ghost_list_.offsets[i + 1]; ++k)
        if (const ContactHistory h = ghost_springs_[k]; is_set(h))
          c.springs.add_pair(p_.id[i], ghosts_.id[ghost_list_.j[k]], h.tangential, h.rolling);
    }
    for (std::size_t col = 0; col < wall_history_.size(); ++col)
      for (std::size_t k = 0; k < wall_history_[col].size(); ++k)
        if (is_set(wall_history_[col][k]))
          c.springs.add_wall(p_.id[wall_neighbours_.particle_of(col, k)], static_cast<int>(col),
                             wall_history_[col][k]);
  }
  // Released before the new lists are built: the old and new copies do not coexist.
  local_springs_.reset(0, false, false);
  ghost_springs_.reset(0, false, false);
  std::vector<std::vector<ContactHistory>>().swap(wall_history_);
  return c;
}

void Simulation::restore_histories(CarriedState& carried) {
  CarriedSprings& cs = carried.springs;
  cs.index();
  local_springs_.reset(local_list_.pairs(), sweep_.keeps_tangential, sweep_.keeps_rolling);
  ghost_springs_.reset(ghost_list_.pairs(), sweep_.keeps_tangential, sweep_.keeps_rolling);
  wall_history_.assign(walls_.history_columns(), {});
  if (!sweep_.has_history) {
    cs.clear();
    return;
  }
  // The wall springs along the new wall lists: a particle now off a wall's list cannot touch
  // the wall before the next rebuild (and does not now), so its spring there ends.
  for (std::size_t col = 0; col < wall_history_.size(); ++col)
    wall_history_[col].assign(wall_neighbours_.column_size(col, p_.size()), ContactHistory{});
  if (cs.walls() > 0)
    for (std::size_t col = 0; col < wall_history_.size(); ++col)
      for (std::size_t k = 0; k < wall_history_[col].size(); ++k) {
        const GlobalId id = p_.id[wall_neighbours_.particle_of(col, k)];
        if (const std::size_t r = cs.find_wall(id, static_cast<int>(col));
            r != CarriedSprings::npos)
          wall_history_[col][k] = cs.wall(r);
      }
  if (cs.pairs() > 0)
    for (std::size_t i = 0; i < p_.size(); ++i) {
      const GlobalId a = p_.id[i];
      for (int k = local_list_.offsets[i]; k < local_list_.offsets[i + 1]; ++k)
        if (const std::size_t r = cs.find_pair(a, p_.id[local_list_.j[k]]);
            r != CarriedSprings::npos)
          local_springs_.set(k, cs.pair(r));
      for (int k = ghost_list_.offsets[i]; k < ghost_list_.offsets[i + 1]; ++k)
        if (const std::size_t r = cs.find_pair(a, ghosts_.id[ghost_list_.j[k]]);
            r != CarriedSprings::npos)
          ghost_springs_.set(k, cs.pair(r));
    }
  cs.clear();
}

void Simulation::apply_order(const std::vector<std::size_t>& perm, CarriedState& carried) {
  p_.permute(perm);
  if (carried.carries_drag) reorder(carried.drag, perm);
}

double Simulation::load_imbalance() const {
  double n[2] = {static_cast<double>(p_.size()), static_cast<double>(p_.size())};
  MPI_Allreduce(MPI_IN_PLACE, &n[0], 1, MPI_DOUBLE, MPI_MAX, comm_);
  MPI_Allreduce(MPI_IN_PLACE, &n[1], 1, MPI_DOUBLE, MPI_SUM, comm_);
  const double mean = n[1] / decomp_->size();
  return mean > 0 ? n[0] / mean : 1.0;
}

void Simulation::balance_cuts() {
  // Per axis with several ranks: a global histogram of particle coordinates gives
  // the planes that split the particles evenly. Each plane moves at most half the
  // narrower of its two boxes per call, so that no particle ends up more than one
  // box from its owner (migration reaches neighbours only), and no box gets
  // thinner than the interaction range (ghosts come from neighbours only).
  const Domain& dom = scene_.domain;
  for (int a = 0; a < 3; ++a) {
    const int n = decomp_->dims()[a];
    if (n == 1) continue;
    const int bins = 64 * n;
    const double lo = dom.lo[a], width = (dom.hi[a] - dom.lo[a]) / bins;
    std::vector<double> hist(bins, 0.0);
    for (const Vec3& x : p_.x)
      hist[std::clamp(static_cast<int>((x[a] - lo) / width), 0, bins - 1)] += 1;
    MPI_Allreduce(MPI_IN_PLACE, hist.data(), bins, MPI_DOUBLE, MPI_SUM, comm_);
    double total = 0;
    for (double h : hist) total += h;
    if (total == 0) return;
    const std::vector<double>& old = decomp_->cuts(a);
    std::vector<double> cuts = old;
    double cumulative = 0;
    int b = 0;
    for (int k = 1; k < n; ++k) {
      const double target = total * k / n;
      while (b < bins && cumulative + hist[b] < target) cumulative += hist[b++];
      const double frac = b < bins && hist[b] > 0 ? (target - cumulative) / hist[b] : 0.0;
      const double ideal = lo + (b + frac) * width;
      const double step = 0.5 * std::min(old[k] - old[k - 1], old[k + 1] - old[k]);
      cuts[k] = std::clamp(ideal, old[k] - step, old[k] + step);
    }
    for (int k = 1; k < n; ++k) cuts[k] = std::max(cuts[k], cuts[k - 1] + cutoff_);
    for (int k = n - 1; k >= 1; --k) cuts[k] = std::min(cuts[k], cuts[k + 1] - cutoff_);
    decomp_->set_cuts(a, cuts);
  }
  grid_ = std::make_unique<BinGrid>(decomp_->lo() - Vec3::Constant(cutoff_),
                                    decomp_->hi() + Vec3::Constant(cutoff_), cutoff_);
}

void Simulation::fit_grid_to_domain() {
  // The grid is a function of the scene alone (the domain and the interaction range), so a
  // restart builds the same boxes and continues bit for bit.
  const std::array<int, 3> dims =
      choose_processor_grid(decomp_->size(), decomp_->length(), cutoff_);
  if (dims == decomp_->dims()) return;
  exchange_.reset();
  decomp_ = std::make_unique<Decomposition>(comm_, scene_.domain, dims);
  exchange_ = std::make_unique<Exchange>(*decomp_);
}

void Simulation::set_cut_planes(int axis, const std::vector<double>& planes) {
  cuts_imposed_ = true;
  try {
    decomp_->set_cuts(axis, planes);
  } catch (const std::invalid_argument& e) {
    throw SetupError(scene_.file + ": error: cut planes along " + std::string(1, "xyz"[axis]) +
                     ": " + e.what());
  }
}

void Simulation::restore(const CheckpointData& checkpoint) {
  p_ = checkpoint.particles;
  restored_drag_.clear();
  for (std::size_t i = 0; i < checkpoint.drag_coefficient.size(); ++i)
    restored_drag_[checkpoint.particles.id[i]] = {checkpoint.drag_coefficient[i],
                                                  checkpoint.drag_fluid_velocity[i]};
  time_ = checkpoint.time;
  if (dt_ <= 0) dt_ = checkpoint.dt;
  counters_.steps = checkpoint.step;
  next_id_ = checkpoint.next_id;
  restored_springs_ = checkpoint.springs;
  restored_ = true;
  // Stream insertions continue where they were: delivered totals, radii drawn but not yet
  // placed and the generators, so the restart inserts what the uninterrupted run would.
  const std::string where = "checkpoint '" + checkpoint.file + "'";
  if (!checkpoint.streams) {
    if (!streams_.empty())
      throw SetupError(scene_.file + ": error: the scene has " + std::to_string(streams_.size()) +
                       " stream insertion(s), but " + where +
                       " holds no stream state (group 'streams'; it was written by a grain "
                       "before format grainflow-checkpoint-2), so the streams' delivered "
                       "totals and random sequences cannot be continued. Run the scene from "
                       "the start, or restart from a checkpoint written by this version");
    return;
  }
  try {
    streams_.restore_state(*checkpoint.streams);
  } catch (const std::invalid_argument& e) {
    throw SetupError(scene_.file + ": error: " + where + ": " + e.what() +
                     "; restart with the scene the checkpoint was written with");
  }
}

void Simulation::write_checkpoint(const std::string& path) {
  CheckpointData d;
  d.time = time_;
  d.dt = dt_;
  d.step = counters_.steps;
  d.next_id = next_id_;
  d.particles = p_;
  if (!terms_.empty()) {
    d.drag_coefficient = drag_.coefficient;
    d.drag_fluid_velocity = drag_.fluid_velocity;
  }
  d.streams = streams_.save_state();
  // Every spring, listed under each partner that this rank owns.
  if (sweep_.has_history) {
    const std::size_t lists = local_list_.offsets.size();
    for (std::size_t i = 0; i + 1 < lists; ++i) {
      for (int k = local_list_.offsets[i]; k < local_list_.offsets[i + 1]; ++k)
        if (const ContactHistory h = local_springs_[k]; is_set(h)) {
          const std::size_t j = local_list_.j[k];
          d.springs.push_back({p_.id[i], p_.id[j], h.tangential, h.rolling});
          d.springs.push_back({p_.id[j], p_.id[i], h.tangential, h.rolling});
        }
      for (int k = ghost_list_.offsets[i]; k < ghost_list_.offsets[i + 1]; ++k)
        if (const ContactHistory h = ghost_springs_[k]; is_set(h))
          d.springs.push_back({p_.id[i], ghosts_.id[ghost_list_.j[k]], h.tangential, h.rolling});
    }
  }
  for (std::size_t w = 0; w < wall_history_.size(); ++w)
    for (std::size_t k = 0; k < wall_history_[w].size(); ++k)
      if (is_set(wall_history_[w][k]))
        d.springs.push_back({p_.id[wall_neighbours_.particle_of(w, k)],
                             -1 - static_cast<GlobalId>(w), wall_history_[w][k].tangential,
                             wall_history_[w][k].rolling});
  grainflow::write_checkpoint(comm_, path, d);
  mark_leaving();
  rebuild(/*keep_drag=*/true);  // the next half kick uses the drag of this step's end
}

void Simulation::rebuild(bool keep_drag) {
  // The positions of the last build are done with (the skin test asked them); released
  // now, they do not add to the memory peak of the rebuild.
  std::vector<Vec3>().swap(x_at_build_);
  // Springs by global ids (indices change below); after a restore, those of the checkpoint.
  CarriedState carried = pending_carried_ ? std::move(*pending_carried_) : take_histories();
  pending_carried_.reset();
  carried.carries_drag = keep_drag && !terms_.empty();
  if (carried.carries_drag)
    for (std::size_t i = 0; i < p_.size(); ++i) {
      const Vec3& u = drag_.fluid_velocity[i];
      carried.drag.push_back({drag_.coefficient[i], u[0], u[1], u[2]});
    }
  // Rebalance every 10th rebuild, when the busiest rank holds 10 % more than the mean.
  if (scene_.parallel.balance && decomp_->size() > 1 && counters_.rebuilds % 10 == 0 &&
      load_imbalance() > 1.1)
    balance_cuts();
  if (!leaving_.empty()) {
    const long before = static_cast<long>(p_.size());
    p_.remove_if(leaving_);  // their springs stay behind in `carried`, never looked up
    if (carried.carries_drag) keep_unflagged(carried.drag, leaving_);
    counters_.removed += before - static_cast<long>(p_.size());
    leaving_.clear();
  }
  exchange_->migrate(p_, carried);
  apply_order(grid_->sort_permutation(p_), carried);
  exchange_->borders(p_, cutoff_, ghosts_);
  grid_->build(p_, ghosts_, skin_, local_list_, ghost_list_);
  wall_neighbours_.build(p_, walls_, skin_);
  restore_histories(carried);
  if (carried.carries_drag) {
    drag_.coefficient.resize(p_.size());
    drag_.fluid_velocity.resize(p_.size());
    for (std::size_t i = 0; i < p_.size(); ++i) {
      const std::array<double, 4>& k = carried.drag[i];
      drag_.coefficient[i] = k[0];
      drag_.fluid_velocity[i] = Vec3(k[1], k[2], k[3]);
    }
  }
  // Bounds for contact_may_be_unresolved, over the particles that can touch anything here:
  // the least m^2/r, and the largest Y* of a pair with one of their materials.
  lightest_q_ = std::numeric_limits<double>::infinity();
  smallest_radius_ = std::numeric_limits<double>::infinity();
  std::vector<char> present(table_.size(), 0);
  for (std::size_t i = 0; i < p_.size(); ++i) {
    lightest_q_ = std::min(lightest_q_, p_.mass[i] * p_.mass[i] / p_.radius[i]);
    smallest_radius_ = std::min(smallest_radius_, p_.radius[i]);
    present[p_.material[i]] = 1;
  }
  for (std::size_t k = 0; k < ghosts_.size(); ++k) {
    lightest_q_ = std::min(lightest_q_, ghosts_.mass[k] * ghosts_.mass[k] / ghosts_.radius[k]);
    present[ghosts_.material[k]] = 1;
  }
  largest_y_star_ = 0;
  for (int a = 0; a < table_.size(); ++a) {
    if (!present[a]) continue;
    for (int b = 0; b < table_.size(); ++b)
      largest_y_star_ = std::max(largest_y_star_, table_(a, b).y_star);
  }
  uniform_ = find_uniform_pairs(p_, ghosts_);
  x_at_build_ = p_.x;
  ++counters_.rebuilds;
}

ContactGuards Simulation::compute_forces() {
  if (!fresh_from_kick_) {  // else kick_and_drift() has set them
    const Vec3 g = scene_.gravity;
    for (std::size_t i = 0; i < p_.size(); ++i) {
      p_.force[i] = p_.mass[i] * g;
      p_.torque[i].setZero();
    }
  }
  // clang-format off
  ContactSweep s{
      p_,       ghosts_,       local_list_,      ghost_list_, local_springs_, ghost_springs_,
      walls_,   wall_history_, wall_neighbours_, table_,      constants_,     dt_,
      uniform_, 0,             0.0,              WorstContact{}, UnresolvedContact{}};
  // clang-format on
  sweep_.run(s);
  // The fastest local particle bounds both the steps-per-contact gate and the travel guard;
  // kick_and_drift() has found it (in the same order) unless a rebuild came since.
  double v2_local = 0;
  if (fresh_from_kick_)
    v2_local = local_speed2_;
  else
    for (const Vec3& v : p_.v) v2_local = std::max(v2_local, v.squaredNorm());
  if (scene_.contact.normal == NormalModel::hertz && scene_.time.min_steps_per_contact > 0 &&
      contact_may_be_unresolved(v2_local)) {
    s.unresolved.set(scene_.time.min_steps_per_contact, dt_);
    steps_per_contact_sweep(s);
  }
  fresh_from_kick_ = false;
  counters_.contacts = s.contacts;
  counters_.max_overlap_ratio = s.max_overlap_ratio;
  apply_force_terms();
  return {s.worst, s.unresolved, fastest_particle(v2_local)};
}

FastParticle Simulation::fastest_particle(double v2_max) const {
  // A particle that moves more than its radius r in one step can cross a (two-sided,
  // thin) mesh wall, or pass through another particle, without the two ever overlapping at
  // the end of a step, so no contact guard can see it (docs/stability.md). The drift just
  // made moved each particle by |v| dt with the velocity of the half kick before it. The
  // gate needs no division: nobody can exceed the limit while v_max dt <= limit r_min.
  FastParticle fast;
  const double limit = scene_.time.max_step_travel;
  if (limit <= 0 || v2_max * dt_ * dt_ <= limit * limit * smallest_radius_ * smallest_radius_)
    return fast;
  for (std::size_t i = 0; i < p_.size(); ++i) {
    const double speed = std::sqrt(p_.v[i].squaredNorm());
    const double ratio = speed * dt_ / (limit * p_.radius[i]);
    if (ratio > fast.ratio) fast = {ratio, i, speed};
  }
  return fast;
}

bool Simulation::contact_may_be_unresolved(double v2_local) const {
  // A Hertz contact fails when m*^2 < k R* Y*^2 v (contact_sweep.hpp). Its approach speed
  // v is at most |v_a| + |v_b| (a fixed wall: |v_a|); m*^2/R* >= q/4 with q = m_s^2/r_s of
  // the lighter partner s (m* >= m_s/2, R* <= min(r_a, r_b)); and Y* <= the table's
  // largest. So while 2 v_max stays below q_min / (4 k Y*max^2), no contact can fail and
  // the sweep need not ask: one pass over the velocities instead of a test per contact.
  for (const WallSet::Entry& w : walls_.walls())
    if (w.pose.moving() || w.surface_velocity.squaredNorm() > 0) return true;
  double v2 = v2_local;
  for (const Vec3& v : ghosts_.v) v2 = std::max(v2, v.squaredNorm());
  const double k = std::pow(scene_.time.min_steps_per_contact * dt_ / 2.868, 5);
  const double floor = lightest_q_ / (4 * k * largest_y_star_ * largest_y_star_);
  return 4 * v2 >= floor * floor;
}

bool Simulation::check_contacts(const ContactGuards& s, bool finite_here) const {
  // One reduction serves the three guards and the finiteness of the step's end, and the
  // guards speak only when some rank is beyond a limit, which every rank learns through it:
  // keep the common path to that one call.
  const double limit = scene_.time.max_overlap;
  const double n_min = scene_.time.min_steps_per_contact;
  const FastParticle& fast = s.fast;
  // Largest overlap ratio; fewest steps per contact as N_min / N (> 1 when under-resolved);
  // the longest travel in the last drift over its limit (> 1 beyond it); 1 when this rank
  // holds a non-finite state.
  const double mine[4] = {counters_.max_overlap_ratio,
                          s.unresolved.fewest > 0 ? n_min / s.unresolved.fewest : 0.0,
                          fast.ratio, finite_here ? 0.0 : 1.0};
  double worst[4] = {mine[0], mine[1], mine[2], mine[3]};
  if (decomp_->size() > 1) MPI_Allreduce(MPI_IN_PLACE, worst, 4, MPI_DOUBLE, MPI_MAX, comm_);
  if (worst[0] <= limit && worst[1] <= 1 && worst[2] <= 1) return worst[3] == 0;
  std::ostringstream o;
  o.precision(4);
  o << scene_.file << ": error: t = " << time_ << " s (step " << counters_.steps + 1 << "): ";
  if (worst[0] <= limit && worst[1] <= 1) {  // the travel guard (a contact's guard comes first)
    if (mine[2] != worst[2]) {
      agree_on_error(comm_, "");  // another rank holds the particle and speaks
      return worst[3] == 0;       // not reached: agree_on_error throws on every rank
    }
    const std::size_t i = fast.index;
    // The speed of the drift (the last half kick has changed v since).
    const double speed = fast.speed, r = p_.radius[i];
    const double travel_limit = scene_.time.max_step_travel;
    const Vec3& x = p_.x[i];
    o << "particle " << p_.id[i] << " moves " << speed * dt_ / r
      << " of its radii per step (speed " << speed << " m/s, radius " << r << " m, dt = "
      << dt_ << " s, at (" << x[0] << ", " << x[1] << ", " << x[2] << ") m); the limit is "
      << travel_limit
      << " (key time.max_step_travel). So fast a particle can pass through a mesh wall or "
         "another particle between two steps without ever overlapping it, which no contact "
         "guard can see. A step of at most "
      << travel_limit * r / speed << " s keeps it within the limit";
    if (scene_.contact.normal == NormalModel::hertz) {
      // An impact at that speed on a wall of its own material: R* = r, m* = m.
      const double tc =
          hertz_contact_time(table_(p_.material[i], p_.material[i]).y_star, r, p_.mass[i], speed);
      o << "; resolving an impact at that speed needs at most " << tc / 20
        << " s (1/20 of the Hertz contact time against a wall of its own material)";
    }
    o << ". If the speed itself is unphysical, look for what caused it (an initial velocity, a "
         "fluid force, a contact in the steps before)";
    agree_on_error(comm_, o.str());
    return worst[3] == 0;  // not reached
  }
  const bool overlap = worst[0] > limit;  // the overlap guard speaks first
  const WorstContact& w = overlap ? s.worst : s.unresolved.contact;
  if (overlap ? mine[0] != worst[0] : mine[1] != worst[1]) {
    agree_on_error(comm_, "");  // another rank holds the contact and speaks
    return worst[3] == 0;       // not reached
  }
  if (w.b >= 0)
    o << "particles " << w.a << " and " << w.b;
  else
    o << "particle " << w.a << " and a wall";
  const double tc =
      hertz_contact_time(w.y_star, w.r_star, w.m_star, std::max(std::abs(w.speed), 1e-12));
  const char* remedy =
      " s would (1/20 of the Hertz contact time at that speed); lower time.step or "
      "time.rayleigh_fraction, or raise time.expected_max_speed so that grain check warns "
      "about it";
  if (!overlap) {
    o << " approach at " << w.speed << " m/s, overlapping by " << 100 * s.unresolved.overlap_ratio
      << " % of the smaller radius. At that speed a Hertz contact lasts " << tc << " s: only "
      << s.unresolved.fewest << " steps of dt = " << dt_ << " s (fewer than " << n_min
      << ", key time.min_steps_per_contact). So coarse a step cannot resolve the contact and "
         "can give it back more energy than it took. A step of at most "
      << tc / 20 << remedy;
  } else {
    o << " overlap by " << 100 * worst[0] << " % of the smaller radius (limit " << 100 * limit
      << " %, key time.max_overlap)";
    if (w.speed > 1e-9)
      o << ", approaching at " << w.speed << " m/s: the time step dt = " << dt_
        << " s is too large to resolve this impact. A step of at most " << tc / 20 << remedy;
    else if (w.speed < -1e-9)
      // Deep and already separating at its first sight: the centre jumped past the other
      // body's surface (a two-sided mesh, another particle's centre) within one step.
      o << ", moving apart at " << -w.speed << " m/s: the centre has most likely crossed the "
        << "other surface within one step of dt = " << dt_ << " s (tunnelled; or the two were "
        << "placed overlapping). A step of at most " << tc / 20 << remedy;
    else
      o << " without approaching each other: the overlap was there at the start, or the load "
        << "compresses a too-soft material; check the initial positions (insertion, CSV) or "
        << "raise the Young's modulus";
  }
  agree_on_error(comm_, o.str());  // the rank holding the worst contact speaks
  return worst[3] == 0;            // not reached: agree_on_error throws on every rank
}

void Simulation::restore_implicit_drag() {
  if (terms_.empty()) return;
  if (restored_drag_.empty()) {
    // A checkpoint without drag (written by a run without fluid forces; every rank
    // reads the whole file, so all take this branch): the terms' drag at the restored
    // state, without adding their forces a second time.
    const std::vector<Vec3> force = p_.force, torque = p_.torque;
    apply_force_terms();
    p_.force = force;
    p_.torque = torque;
    return;
  }
  drag_.coefficient.assign(p_.size(), 0.0);
  drag_.fluid_velocity.assign(p_.size(), Vec3::Zero());
  for (std::size_t i = 0; i < p_.size(); ++i) {
    const auto it = restored_drag_.find(p_.id[i]);
    if (it == restored_drag_.end()) continue;
    drag_.coefficient[i] = it->second.first;
    drag_.fluid_velocity[i] = it->second.second;
  }
  restored_drag_.clear();
}

void Simulation::apply_force_terms() {
  if (!terms_.empty()) {
    drag_.coefficient.assign(p_.size(), 0.0);
    drag_.fluid_velocity.assign(p_.size(), Vec3::Zero());
    for (auto& term : terms_) term->add(p_, time_, drag_);
  }
}

namespace {
// One half kick of velocity Verlet over n particles: v += h/m F (implicit in v where drag
// is set), and w += h/I T when the law has torques. Written on the arrays' addresses, one
// loop per case, so that the loops hold no branch and no reload of an address. With Guard,
// returns whether every x, v and w is finite after it: x - x is 0 for a finite x and NaN
// for an infinite or NaN one, and NaN stays in a sum.
template <bool Guard, bool Drag, bool Spin>
bool kick(std::size_t n, double h, const Vec3* x, Vec3* v, Vec3* w, const Vec3* force,
          const Vec3* torque, const double* mass, const double* inertia, const double* drag_k,
          const Vec3* fluid_u) {
  double nan_if_any = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if constexpr (!Drag) {
      v[i] += (h / mass[i]) * force[i];
    } else {
      // v' = v + h/m (F + K (u - v'))  =>  v' = (v + h/m (F + K u)) / (1 + h K / m)
      const double a = h / mass[i], k = drag_k[i];
      v[i] = (v[i] + a * (force[i] + k * fluid_u[i])) / (1 + a * k);
    }
    if constexpr (Spin) w[i] += (h / inertia[i]) * torque[i];
    if constexpr (Guard) nan_if_any += ((x[i] - x[i]) + (v[i] - v[i]) + (w[i] - w[i])).sum();
  }
  return nan_if_any == 0;
}
}  // namespace

template <bool Guard>
bool Simulation::half_kick() {
  const double h = 0.5 * dt_;
  const std::size_t n = p_.size();
  const double* k = drag_.coefficient.data();
  const Vec3* u = drag_.fluid_velocity.data();
  Particles& p = p_;
  const auto run = [&]<bool Drag, bool Spin>() {
    return kick<Guard, Drag, Spin>(n, h, p.x.data(), p.v.data(), p.omega.data(), p.force.data(),
                                   p.torque.data(), p.mass.data(), p.inertia.data(), k, u);
  };
  const bool drag = !drag_.coefficient.empty(), spin = sweep_.needs_spin;
  if (drag)
    return spin ? run.template operator()<true, true>() : run.template operator()<true, false>();
  return spin ? run.template operator()<false, true>() : run.template operator()<false, false>();
}

void Simulation::step() {
  if (!initialised_) initialise();
  // Velocity Verlet: half kick, drift, new forces, half kick.
  kick_and_drift();
  // Stream insertion (dem/insert/stream_insertion.hpp); new particles force a rebuild.
  const bool inserted = !streams_.empty() && streams_.insert(time_ + dt_, p_, ghosts_, walls_,
                                                             *decomp_, next_id_, comm_) > 0;
  if (sweep_.has_history)  // inserted particles: a spring in the columns of every particle
    for (std::size_t col = 0; col < wall_history_.size(); ++col)
      if (wall_neighbours_.list_of_column(col).all) wall_history_[col].resize(p_.size());
  if (inserted) mark_leaving();  // the new particles too
  if (inserted || needs_rebuild()) {
    rebuild();
    fresh_from_kick_ = false;  // particles came, left or arrived from other ranks
  } else
    exchange_->forward(p_, ghosts_);
  time_ += dt_;
  walls_.move_to(time_);
  const ContactGuards guards = compute_forces();
  state_finite_ = half_kick<true>();
  finite_everywhere_ = check_contacts(guards, state_finite_);
  ++counters_.steps;
}

void Simulation::advance_to(double t_end) {
  if (!initialised_) initialise();
  while (time_ < t_end - 0.5 * dt_) step();
}

double Simulation::kinetic_energy_translational() const {
  double e = 0;
  for (std::size_t i = 0; i < p_.size(); ++i) e += 0.5 * p_.mass[i] * p_.v[i].squaredNorm();
  return e;
}

double Simulation::kinetic_energy_rotational() const {
  double e = 0;
  for (std::size_t i = 0; i < p_.size(); ++i) e += 0.5 * p_.inertia[i] * p_.omega[i].squaredNorm();
  return e;
}

GlobalState Simulation::global_state() const {
  double sums[5] = {static_cast<double>(p_.size()), static_cast<double>(counters_.contacts),
                    static_cast<double>(counters_.removed), kinetic_energy_translational(),
                    kinetic_energy_rotational()};
  double overlap = counters_.max_overlap_ratio;
  MPI_Allreduce(MPI_IN_PLACE, sums, 5, MPI_DOUBLE, MPI_SUM, comm_);
  MPI_Allreduce(MPI_IN_PLACE, &overlap, 1, MPI_DOUBLE, MPI_MAX, comm_);
  GlobalState s;
  s.particles = std::lround(sums[0]);
  s.contacts = std::lround(sums[1]);
  s.removed = std::lround(sums[2]);
  s.kinetic_translational = sums[3];
  s.kinetic_rotational = sums[4];
  s.max_overlap_ratio = overlap;
  return s;
}

}  // namespace grainflow
