#include "dem/engine/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "dem/contact/normal_hooke.hpp"
#include "dem/core/number_format.hpp"
#include "dem/engine/finite_guard.hpp"
#include "dem/engine/insertion_record.hpp"
#include "dem/engine/restored_state.hpp"
#include "dem/insert/insertion.hpp"
#include "dem/walls/stl_reader.hpp"
#include "dem/walls/wall_contact.hpp"
#include "dem/walls/wall_travel.hpp"

namespace grainflow {
namespace {
// How a half kick treats the spin: not at all (no torques), w += h/I T, or implicit in w
// where a force term sets a spin drag (ImplicitDrag::spin_coefficient).
enum SpinKick { kNoSpin, kSpin, kImplicitSpin };

// The three components of a particle's x, v or w while the integrator updates them, held in
// registers: loaded from the arrays once, stored once. With Eigen's Vec3 for the copies GCC
// keeps them on the stack, writes the components one by one and reads them back two at a
// time, a load the processor cannot serve from its store buffer: it waits until the stores
// reach the cache (perf: a third of the kick-and-drift pass, two thirds of the last half
// kick, on the settled bed of benchmarks/peers). Each operation is Eigen's, component by
// component, without fused multiply-adds: the same bits.
struct Triple {
  double x, y, z;
};
[[gnu::always_inline]] inline Triple load(const Vec3& a) { return {a[0], a[1], a[2]}; }
[[gnu::always_inline]] inline void store(const Triple& t, Vec3& a) {
  a[0] = t.x;
  a[1] = t.y;
  a[2] = t.z;
}
// y + s a (Eigen's `y += s * a`).
[[gnu::always_inline]] inline Triple add_scaled(const Triple& y, double s, const Vec3& a) {
  return {y.x + s * a[0], y.y + s * a[1], y.z + s * a[2]};
}
[[gnu::always_inline]] inline Triple add_scaled(const Triple& y, double s, const Triple& a) {
  return {y.x + s * a.x, y.y + s * a.y, y.z + s * a.z};
}
// y after a half kick of F with the implicit drag K (U - y'), s = h/m (or h/I for the spin):
// y' = y + s (F + K (U - y'))  =>  y' = (y + s (F + K U)) / (1 + s K).
[[gnu::always_inline]] inline Triple implicit_kick(const Triple& y, double s, const Vec3& f,
                                                   double k, const Vec3& u) {
  const double d = 1 + s * k;
  return {(y.x + s * (f[0] + k * u[0])) / d, (y.y + s * (f[1] + k * u[1])) / d,
          (y.z + s * (f[2] + k * u[2])) / d};
}
// y + (y - y0): the velocity predicted at the step's end (Particles::v_pred).
[[gnu::always_inline]] inline Triple extrapolated(const Triple& y, const Triple& y0) {
  return {y.x + (y.x - y0.x), y.y + (y.y - y0.y), y.z + (y.z - y0.z)};
}
// |a - b|^2 in Eigen's order: (d_x^2 + d_y^2) + d_z^2.
[[gnu::always_inline]] inline double squared_distance(const Triple& a, const Vec3& b) {
  const double dx = a.x - b[0], dy = a.y - b[1], dz = a.z - b[2];
  return (dx * dx + dy * dy) + dz * dz;
}
[[gnu::always_inline]] inline double squared_norm(const Triple& a) {
  return (a.x * a.x + a.y * a.y) + a.z * a.z;
}

SpinKick spin_kick(const ImplicitDrag& drag, bool needs_spin) {
  if (!drag.spin_coefficient.empty()) return kImplicitSpin;
  return needs_spin ? kSpin : kNoSpin;
}

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
  exchange_ = std::make_unique<Exchange>(
      *decomp_, scene_.contact.dashpot_velocity == DashpotVelocity::predicted);
  constants_.hooke_characteristic_velocity =
      scene.contact.hooke_characteristic_velocity.value_or(0.0);
  constants_.hooke_kn = scene.contact.hooke_kn.value_or(0.0);
  constants_.hooke_kt = scene.contact.hooke_kt.value_or(constants_.hooke_kn);
  constants_.epsd_damping_ratio = scene.contact.epsd_damping_ratio;
#if defined(GRAINFLOW_AVX512_SWEEP)
  // The contact sweep is compiled for AVX-512 F and VL (GRAINFLOW_AVX, CMakeLists.txt): refused
  // here rather than stopped by an illegal instruction in the first step.
  if (!__builtin_cpu_supports("avx512f") || !__builtin_cpu_supports("avx512vl"))
    throw SetupError(
        "grain: error: this build's contact sweep needs a processor with AVX-512 F and VL "
        "(GRAINFLOW_AVX was AUTO or AVX512 on the machine that built it), and this processor "
        "lacks them; rebuild on this machine, or anywhere with `cmake -DGRAINFLOW_AVX=ON` for "
        "processors with AVX or `-DGRAINFLOW_AVX=OFF` for any x86-64 (the results are the same "
        "to the last bit)");
#elif defined(GRAINFLOW_AVX_SWEEP)
  // The contact sweep is compiled for AVX (GRAINFLOW_AVX, CMakeLists.txt): refused here rather
  // than stopped by an illegal instruction in the first step.
  if (!__builtin_cpu_supports("avx"))
    throw SetupError(
        "grain: error: this build's contact sweep needs a processor with AVX (GRAINFLOW_AVX was "
        "AUTO or ON on the machine that built it), and this processor has none; rebuild on this "
        "machine, or anywhere with `cmake -DGRAINFLOW_AVX=OFF` for any x86-64 (the results are "
        "the same to the last bit)");
#endif
  sweep_ = select_sweep(scene.contact, scene.parallel.reproducible);
  walls_ = WallSet(scene_);  // reads STL meshes (GeometryError: bad input, exit code 2)
  streams_ = StreamInsertion(scene_);
  streams_.check_faces(scene_, walls_);
  if (scene_.output.wall_loads) {
    wall_forces_.assign(walls_.walls().size(), Vec3::Zero());
    wall_impulse_ = wall_forces_;
  }
  if (scene_.heat) heat_ = std::make_unique<HeatTransfer>(scene_);
  if (insert) {
    insert_particles(scene_, p_, next_id_, &walls_, &insertion_notes_);
    walls_.check_closed_meshes(p_.x);  // every rank holds every inserted particle here
  }
}

void Simulation::initialise() {
  // Before the first step the dashpots see the initial velocities (particles.hpp).
  p_.v_pred = p_.v;
  p_.omega_pred = p_.omega;
  double r_max = 0;
  for (double r : p_.radius) r_max = std::max(r_max, r);
  r_max = std::max(r_max, streams_.max_radius());  // particles still to come
  // A restart keeps the range of the run it continues, whose largest particle may have left.
  if (restored_largest_radius_) r_max = std::max(r_max, *restored_largest_radius_);
  MPI_Allreduce(MPI_IN_PLACE, &r_max, 1, MPI_DOUBLE, MPI_MAX, comm_);
  const Vec3 length = decomp_->length();
  if (r_max == 0) r_max = length.minCoeff() / 100;  // empty scene: any grid works
  largest_radius_ = r_max;
  skin_ = scene_.neighbour.skin.value_or(0.4 * r_max);
  cutoff_ = 2 * r_max + skin_;
  for (int a = 0; a < 3; ++a)
    if (scene_.domain.periodic[a] && length[a] < 2 * cutoff_) {
      // The remedies as values that work when set as written: a length rounded up, a skin
      // rounded down (none when the particles alone need more than the axis has).
      std::ostringstream msg;
      msg << scene_.file << ": error: periodic axis "
          << "xyz"[a] << " is " << length[a]
          << " m long, shorter than twice the interaction range (2 r_max + skin = " << cutoff_
          << " m, r_max = " << r_max << " m, skin = " << skin_ << " m): make the domain at least "
          << exact_number(round_up_3(2 * cutoff_)) << " m long along "
          << "xyz"[a];
      double skin = round_down_3(0.5 * length[a] - 2 * r_max);
      while (skin > 0 && 2 * (2 * r_max + skin) > length[a]) skin = round_down_3(0.999 * skin);
      if (skin > 0)
        msg << ", or set neighbour.skin to at most " << exact_number(skin)
            << " m (the lists are then rebuilt more often)";
      else
        msg << " (no skin fits: twice the largest diameter, " << 4 * r_max
            << " m, is already longer)";
      throw SetupError(msg.str());
    }
  if (cuts_imposed_) {
    grid_choice_ = GridChoice::imposed;
  } else if (!automatic_grid_ && restored_grid_ && restored_grid_->ranks == decomp_->size() &&
             restored_grid_->dims == decomp_->dims()) {
    // The scene's grid is the checkpoint's: its planes are where that run had them (uniform,
    // or moved by parallel.balance), so the run continues bit for bit.
    take_restored_grid(*restored_grid_);
    grid_choice_ = GridChoice::given_checkpoint;
  } else if (automatic_grid_) {
    // On as many ranks as wrote the checkpoint, its boxes: the run continues bit for bit.
    if (restored_grid_ && restored_grid_->ranks == decomp_->size())
      take_restored_grid(*restored_grid_);
    else if (decomp_->size() > 1)
      fit_grid_to_particles();
    else
      grid_choice_ = GridChoice::domain;  // one box, the domain
  }
  restored_grid_.reset();
  for (int a = 0; a < 3; ++a)
    if (decomp_->dims()[a] > 1 && decomp_->thinnest_box() < cutoff_) {
      std::ostringstream msg;
      msg << scene_.file << ": error: with " << decomp_->dims()[0] << " x " << decomp_->dims()[1]
          << " x " << decomp_->dims()[2] << " ranks, a subdomain is " << decomp_->thinnest_box()
          << " m thick, thinner than the interaction range (2 r_max + skin = " << cutoff_ << " m); "
          << (automatic_grid_ ? std::string("use fewer MPI ranks")
                              : "give parallel.grid fewer ranks, and run on as many MPI "
                                "ranks as it then has");
      throw SetupError(msg.str());
    }

  // Every rank holds the same full set here: the report is the same everywhere.
  // A restart keeps the checkpoint's step (restore): the report judges that one.
  report_ = check_time_step(scene_, p_, table_, constants_,
                            restored_ ? std::optional<double>(dt_) : std::nullopt);
  if (dt_ <= 0) dt_ = report_.dt;
  if (dt_ <= 0) {
    const std::string where =
        scene_.time.step_source.empty() ? scene_.file : scene_.time.step_source;
    throw SetupError(
        where + ": error: time.rayleigh_fraction sizes the step by the Rayleigh time of the " +
        (p_.size() == 0
             ? std::string("particles present at the start, and there are none")
             : "contacts, and no contact can happen in this scene (" + std::to_string(p_.size()) +
                   " particle(s), " +
                   (scene_.walls.empty() ? "no walls" : "nothing they can touch") + ")") +
        "; give time.step instead" +
        (scene_.fluid ? std::string(" (`grain check` prints the fluid forces' limits on it)")
                      : std::string()));
  }
  check_walls_travel();

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

  make_bin_grid();
  walls_.move_to(time_);
  walls_.fit_grids(r_max);  // mesh search cells of one particle diameter
  const bool restoring = restored_;
  mark_leaving();
  rebuild();
  // A restored run keeps the checkpoint's forces: evaluating the contacts again
  // would advance every spring a second time for the same step, and the force terms
  // are already in them. Only the implicit drag is set, from the checkpoint. A fresh run
  // evaluates its initial state: the contacts present start with springs that have not
  // moved, so this evaluation advances none (the first step advances them by v(dt/2) dt).
  if (restoring)
    restore_implicit_drag();
  else
    check_contacts(compute_forces(false), true);
  check_force_limits();
  initialised_ = true;
}

void Simulation::check_walls_travel() {
  // The smallest particle present or still to come, the one a wall passes most easily:
  // (radius, material), the lowest material index among equals, agreed by every rank.
  struct {
    double radius;
    int material;
  } smallest{std::numeric_limits<double>::infinity(), -1};
  auto take = [&](double r, int m) {
    if (r < smallest.radius || (r == smallest.radius && m < smallest.material)) smallest = {r, m};
  };
  for (std::size_t i = 0; i < p_.size(); ++i) take(p_.radius[i], p_.material[i]);
  for (const Insertion& ins : scene_.insertions)
    if (ins.kind == Insertion::Kind::stream) take(min_radius(ins.radius), ins.material);
  MPI_Allreduce(MPI_IN_PLACE, &smallest, 1, MPI_DOUBLE_INT, MPI_MINLOC, comm_);
  const WallTravelReport walls =
      check_wall_travel(scene_, walls_, dt_, std::isfinite(smallest.radius) ? smallest.radius : 0.0,
                        smallest.material, table_,
                        report_.verdict == TimeStepReport::Verdict::refuse
                            ? report_.refusal_step  // every refusing limit's, conduction's too
                            : std::numeric_limits<double>::infinity());
  for (const std::string& note : walls.notes) report_.notes.push_back(note);
  if (!walls.error.empty()) throw SetupError(walls.error);
  check_mesh_tunnelling(walls, std::isfinite(smallest.radius) ? smallest.radius : 0.0);
}

void Simulation::check_mesh_tunnelling(const WallTravelReport& walls, double r_min) {
  // A mesh is a two-sided sheet, and its overlap r - |c - q| falls again once a centre has
  // crossed it. From an overlap of at most L r on one side to at most L r on the other, a centre
  // travels at least 2 (1 - L) r relative to the mesh. The particles move at most
  // max_step_travel radii per step, a moving mesh its own travel per smallest radius: below
  // 2 (1 - L) together, every crossing passes an overlap above L at the end of some step, which
  // the overlap guard stops. (Planes and cylinders have a signed distance: always seen.)
  const double travel = scene_.time.max_step_travel, limit = scene_.time.max_overlap;
  if (travel <= 0 || r_min <= 0) return;
  double wall_travel = 0;
  std::string fastest;
  bool meshes = false;
  for (const Wall& w : scene_.walls) meshes |= w.kind == Wall::Kind::mesh;
  if (!meshes) return;
  for (const WallTravel& w : walls.walls)
    if (scene_.walls[w.index].kind == Wall::Kind::mesh && w.travel / r_min > wall_travel) {
      wall_travel = w.travel / r_min;
      fastest = w.name;
    }
  mesh_walls_ = true;
  mesh_wall_travel_ = wall_travel;
  const double crossing = 2 * (1 - limit);
  if (travel + wall_travel < crossing) return;
  const double overlap_fit = round_down_3(0.999 * (1 - (travel + wall_travel) / 2));
  const double travel_fit = round_down_3(0.999 * (crossing - wall_travel));
  std::ostringstream o;
  o.precision(4);
  o << scene_.file << ": error: time.max_overlap = " << limit
    << " with mesh walls: a centre that crosses a "
    << "mesh (a two-sided sheet) from an overlap below " << limit << " of its radius on one side "
    << "to one below it on the other travels only 2 (1 - " << limit << ") = " << crossing
    << " radii, and a particle may move " << travel << " radii per step (time.max_step_travel)";
  if (wall_travel > 0) o << ", mesh '" << fastest << "' " << wall_travel << " smallest radii";
  o << ": such a tunnel would pass between two steps without an overlap the guard sees. ";
  if (overlap_fit > 0) o << "Lower time.max_overlap to " << overlap_fit;
  if (overlap_fit > 0 && travel_fit > 0) o << ", or ";
  if (travel_fit > 0)
    o << (overlap_fit > 0 ? "lower" : "Lower") << " time.max_step_travel to " << travel_fit;
  if (overlap_fit <= 0 && travel_fit <= 0) o << "Slow the mesh down, or lower time.step";
  throw SetupError(o.str());
}

std::vector<TermLimit> Simulation::gather_force_limits() const {
  std::vector<TermLimit> limits;
  for (const auto& term : terms_)
    for (TermLimit& l : term->limits(p_, time_)) limits.push_back(std::move(l));
  // The smallest time scale and limit over the ranks, with the particle of the time scale
  // (the same list of terms on every rank).
  const std::size_t n = limits.size();
  if (n > 0 && decomp_->size() > 1) {
    std::vector<double> least(2 * n);
    for (std::size_t k = 0; k < n; ++k) {
      least[2 * k] = limits[k].tau;
      least[2 * k + 1] = limits[k].dt_max;
    }
    MPI_Allreduce(MPI_IN_PLACE, least.data(), static_cast<int>(2 * n), MPI_DOUBLE, MPI_MIN, comm_);
    std::vector<std::int64_t> who(n);
    for (std::size_t k = 0; k < n; ++k)
      who[k] = limits[k].tau == least[2 * k] ? limits[k].particle
                                             : std::numeric_limits<std::int64_t>::max();
    MPI_Allreduce(MPI_IN_PLACE, who.data(), static_cast<int>(n), MPI_INT64_T, MPI_MIN, comm_);
    for (std::size_t k = 0; k < n; ++k) {
      limits[k].tau = least[2 * k];
      limits[k].dt_max = least[2 * k + 1];
      limits[k].particle = who[k];
    }
  }
  return limits;
}

void Simulation::recheck_force_limits() {
  if (terms_.empty()) return;
  const std::vector<TermLimit> now = gather_force_limits();  // collective
  for (const TermLimit& l : now) {
    if (!(dt_ > l.dt_max)) continue;
    double at_start = std::numeric_limits<double>::infinity();
    for (const TermLimit& s : force_limits_)
      if (s.term == l.term) at_start = s.dt_max;
    std::ostringstream o;
    o.precision(4);
    o << scene_.file << ": error: at t = " << time_ << " s, dt = " << dt_
      << " s is beyond the stability limit of the fluid force '" << l.term
      << "' (dt <= " << l.dt_max << " s; " << l.rule << "), set by particle " << l.particle
      << ": the flow has grown past what the start-up allowed (dt <= " << at_start
      << " s then); the run stops before the force makes it unstable. Use dt <= " << 0.9 * l.dt_max
      << " s, or remove '" << l.term << "' from fluid.forces";
    throw SetupError(o.str());
  }
}

void Simulation::check_force_limits() {
  force_limits_ = gather_force_limits();
  force_limit_notes_.clear();
  for (const TermLimit& l : force_limits_) {
    std::ostringstream o;
    o.precision(4);
    o << "fluid force " << l.term << ": ";
    if (l.time_scale == "none")
      o << l.rule;
    else {
      if (std::isfinite(l.tau))
        o << "time scale " << l.time_scale << " = " << l.tau << " s (particle " << l.particle
          << "), dt/tau = " << dt_ / l.tau;
      else  // no particle feels the force yet (none placed, or a law that vanishes at eps = 1)
        o << "time scale " << l.time_scale << ": none finite at start-up (no particle feels "
          << "this force yet)";
      o << "; " << l.rule;
      if (std::isfinite(l.dt_max)) o << "; dt <= " << l.dt_max << " s";
    }
    report_.notes.push_back(o.str());
    force_limit_notes_.push_back(o.str());
    if (dt_ > l.dt_max) {
      o.str("");
      o << "error: dt = " << dt_ << " s is beyond the stability limit of the fluid force '"
        << l.term << "' (dt <= " << l.dt_max << " s; " << l.rule
        << "); use dt <= " << 0.9 * l.dt_max << " s, or remove '" << l.term
        << "' from fluid.forces";
      report_.notes.push_back(o.str());
      force_limit_notes_.push_back(o.str());
      report_.refuse_above(0.9 * l.dt_max);
    }
  }
}

std::string Simulation::force_limits_summary() const {
  if (force_limits_.empty()) return {};
  std::ostringstream o;
  o.precision(3);
  o << "fluid force terms enabled (at start-up):";
  const char* sep = " ";
  for (const TermLimit& l : force_limits_) {
    o << sep << l.term;
    sep = ", ";
    if (l.time_scale == "none") {
      o << " (no limit)";
    } else if (!std::isfinite(l.tau)) {
      o << " (no time scale yet)";
    } else {
      o << " (dt/tau = " << dt_ / l.tau;
      if (l.implicit)
        o << ", implicit";
      else if (std::isfinite(l.dt_max))
        o << ", dt/limit = " << dt_ / l.dt_max;
      else
        o << ", stable at any dt";
      o << ")";
    }
  }
  return o.str();
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
  // With contact.dashpot_velocity: predicted, the same pass predicts the end-of-step
  // velocities the dashpots see (Particles::v_pred):
  // the half kick's increment once more, v* = v(t + dt/2) + (v(t + dt/2) - v(t)), which is
  // v(t) + dt F(t)/m without drag and includes the implicit drag's response with it. v* is
  // v(t + dt) to O(dt^2), so the dashpot forces, and with them damped impacts, are second
  // order in dt; the springs still see the half-step velocity (midpoint rule). The owner
  // computes v* and sends it to the ghosts: both ranks of a pair read the same bits.
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
  Vec3* vps = p_.v_pred.data();
  Vec3* wps = p_.omega_pred.data();
  Vec3* force = p_.force.data();
  Vec3* torque = p_.torque.data();
  const Vec3 g = scene_.gravity;
  const double* mass = p_.mass.data();
  const double* inertia = p_.inertia.data();
  const double* drag_k = drag_.coefficient.data();
  const Vec3* fluid_u = drag_.fluid_velocity.data();
  const Vec3* built = x_at_build_.data();
  leaving_.clear();
  const double* spin_k = drag_.spin_coefficient.data();
  const Vec3* fluid_w = drag_.fluid_spin.data();
  const auto pass = [&]<bool Drag, SpinKick Spin, bool Predict>() {
    bool moved_far = false;
    double v2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Triple v_start = load(vs[i]);
      const double a = h / mass[i];
      const Triple v = Drag ? implicit_kick(v_start, a, force[i], drag_k[i], fluid_u[i])
                            : add_scaled(v_start, a, force[i]);
      store(v, vs[i]);
      if constexpr (Predict) store(extrapolated(v, v_start), vps[i]);
      if constexpr (Spin != kNoSpin) {
        const Triple w_start = load(ws[i]);
        const double b = h / inertia[i];
        const Triple w = Spin == kImplicitSpin
                             ? implicit_kick(w_start, b, torque[i], spin_k[i], fluid_w[i])
                             : add_scaled(w_start, b, torque[i]);
        store(w, ws[i]);
        if constexpr (Predict) store(extrapolated(w, w_start), wps[i]);
      }
      force[i] = mass[i] * g;
      torque[i].setZero();
      const Triple x = add_scaled(load(xs[i]), dt, v);
      store(x, xs[i]);
      moved_far |= squared_distance(x, built[i]) > limit2;
      // | rather than ||: one branch, taken only by a particle that leaves.
      if ((x.x < lo[0]) | (x.x > hi[0]) | (x.y < lo[1]) | (x.y > hi[1]) | (x.z < lo[2]) |
          (x.z > hi[2])) [[unlikely]] {
        leaving_.resize(n, 0);
        leaving_[i] = 1;
      }
      v2 = std::max(v2, squared_norm(v));
    }
    moved_beyond_half_skin_ = moved_far;
    local_speed2_ = v2;
  };
  const bool predict = scene_.contact.dashpot_velocity == DashpotVelocity::predicted;
  const auto run = [&]<bool Drag, SpinKick Spin>() {
    predict ? pass.template operator()<Drag, Spin, true>()
            : pass.template operator()<Drag, Spin, false>();
  };
  const bool drag = !drag_.coefficient.empty();
  const SpinKick spin = spin_kick(drag_, sweep_.needs_spin);
  if (drag && spin == kImplicitSpin)
    run.template operator()<true, kImplicitSpin>();
  else if (drag)
    spin == kSpin ? run.template operator()<true, kSpin>()
                  : run.template operator()<true, kNoSpin>();
  else
    spin == kSpin ? run.template operator()<false, kSpin>()
                  : run.template operator()<false, kNoSpin>();
  fresh_from_kick_ = true;
}

bool Simulation::needs_rebuild() const {
  // 2: a leaving particle is behind a wall (rare: looked at only when one leaves).
  int local = !leaving_.empty() || moved_beyond_half_skin_;
  if (!leaving_.empty() && !left_through_wall_message().empty()) local = 2;
  int any = local;
  if (decomp_->size() > 1) {
    const double start = MPI_Wtime();
    MPI_Allreduce(&local, &any, 1, MPI_INT, MPI_MAX, comm_);
    collective_wait_seconds_ += MPI_Wtime() - start;
  }
  left_through_wall_ = any == 2;
  return any > 0;
}

std::string Simulation::left_through_wall_message() const {
  // A plane or a cylinder is one-sided: a centre behind it crossed it within a step, between
  // two looks of the overlap guard (with time.max_overlap near 1, or the other guards off),
  // and a wall on a domain side then let the particle out as if through an open side. A mesh
  // has no far side; its crossing is kept in view by the check of max_overlap against
  // max_step_travel (docs/scene-reference.md).
  for (std::size_t i = 0; i < leaving_.size(); ++i) {
    if (!leaving_[i]) continue;
    const double r = p_.radius[i];
    for (const WallSet::Entry& w : walls_.walls()) {
      if (w.kind == Wall::Kind::mesh) continue;
      WallTouch t;
      const bool touching = w.kind == Wall::Kind::plane ? touch_plane(w.plane, p_.x[i], r, t)
                                                        : touch_cylinder(w.cylinder, p_.x[i], r, t);
      if (!touching || t.overlap <= r) continue;
      std::ostringstream o;
      o.precision(4);
      const double speed = p_.v[i].norm();
      o << scene_.file << ": error: t = " << time_ << " s (step " << counters_.steps
        << "): particle " << p_.id[i] << " left the domain behind wall '" << w.name
        << "', its centre " << (t.overlap - r) / r << " of its radius past it (speed " << speed
        << " m/s, radius " << r << " m, dt = " << dt_ << " s): it crossed the wall within a "
        << "step, between two looks of the overlap guard (time.max_overlap = "
        << scene_.time.max_overlap << "), and would have been counted as leaving through an "
        << "open side. A step of at most "
        << round_down_3((1 - scene_.time.max_overlap) * r / speed)
        << " s keeps a crossing at that speed in view (it moves the particle less than "
        << "1 - max_overlap of its radius per step); or lower time.max_overlap";
      if (scene_.time.min_steps_per_contact <= 0 || scene_.time.max_step_travel <= 0)
        o << ", and turn time.min_steps_per_contact or time.max_step_travel back on (0 turned "
             "them off)";
      return o.str();
    }
  }
  return "";
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
  // Imposed planes (a coupled run's: the fluid mesh's) are not the DEM's to move: off them,
  // a particle would be owned by a rank that does not hold its cell.
  if (cuts_imposed_) return;
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
  make_bin_grid();
}

void Simulation::make_bin_grid() {
  if (scene_.parallel.reproducible)
    grid_ = std::make_unique<BinGrid>(
        BinGrid::anchored(scene_.domain.lo, scene_.domain.hi, cutoff_));
  else
    grid_ = std::make_unique<BinGrid>(decomp_->lo() - Vec3::Constant(cutoff_),
                                      decomp_->hi() + Vec3::Constant(cutoff_), cutoff_);
}

void Simulation::remake_decomposition(const std::array<int, 3>& dims) {
  if (dims == decomp_->dims()) return;
  exchange_.reset();
  decomp_ = std::make_unique<Decomposition>(comm_, scene_.domain, dims);
  exchange_ = std::make_unique<Exchange>(
      *decomp_, scene_.contact.dashpot_velocity == DashpotVelocity::predicted);
}

void Simulation::fit_grid_to_particles() {
  const Vec3 length = decomp_->length();
  // Particles still to come (streams) land where the scene sends them, not where the
  // particles of the start are: such a scene, like an empty one, is cut for its domain.
  const bool by_particles = p_.size() > 0 && streams_.empty();
  std::optional<Vec3> extent;
  if (by_particles) {
    Vec3 lo = p_.x[0], hi = p_.x[0];
    for (const Vec3& x : p_.x) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    // The cut through the particles plus the ghost layer on either side of it.
    extent = ((hi - lo) + Vec3::Constant(cutoff_)).cwiseMin(length);
  }
  const std::array<int, 3> dims = choose_processor_grid(decomp_->size(), length, cutoff_, extent);
  remake_decomposition(dims);
  grid_choice_ = by_particles ? GridChoice::particles : GridChoice::domain;
  if (!by_particles) return;
  const Domain& d = scene_.domain;
  std::vector<double> coordinate(p_.size());
  for (int a = 0; a < 3; ++a) {
    if (dims[a] == 1) continue;
    for (std::size_t i = 0; i < p_.size(); ++i) coordinate[i] = p_.x[i][a];
    decomp_->set_cuts(a, balanced_cut_planes(coordinate, d.lo[a], d.hi[a], dims[a], cutoff_));
  }
}

void Simulation::take_restored_grid(const CheckpointGrid& grid) {
  remake_decomposition(grid.dims);
  for (int a = 0; a < 3; ++a) {
    try {
      decomp_->set_cuts(a, grid.cuts[a]);
    } catch (const std::invalid_argument& e) {  // check_checkpoint has refused such planes
      throw SetupError(scene_.file + ": error: the cut planes along " +
                       std::string(1, "xyz"[a]) + " of the restored checkpoint: " + e.what());
    }
  }
  grid_choice_ = GridChoice::checkpoint;
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
  // Stream insertions continue where they were: delivered totals, radii drawn but not yet
  // placed and the generators, so the restart inserts what the uninterrupted run would.
  const std::string where = "checkpoint '" + checkpoint.file + "'";
  // The scene's insertions must be the run's (a changed one would be skipped or, a stream's
  // rate, applied back to t = 0).
  if (checkpoint.insertions) check_insertions(*checkpoint.insertions, scene_, checkpoint.file);
  if (!checkpoint.streams && !streams_.empty())
    throw SetupError(scene_.file + ": error: the scene has " + std::to_string(streams_.size()) +
                     " stream insertion(s), but " + where +
                     " holds no stream state (group 'streams'; it was written by a grain "
                     "before format grainflow-checkpoint-2), so the streams' delivered "
                     "totals and random sequences cannot be continued. Run the scene from "
                     "the start, or restart from a checkpoint written by this version");
  if (checkpoint.streams) {
    try {
      streams_.restore_state(*checkpoint.streams);
    } catch (const std::invalid_argument& e) {
      throw SetupError(scene_.file + ": error: " + where + ": " + e.what() +
                       "; restart with the scene the checkpoint was written with");
    }
  }
  // Before anything else uses the state (a material index indexes tables, a position bins).
  std::vector<long> delivered;
  for (std::size_t k = 0; k < streams_.size(); ++k) delivered.push_back(streams_.count_inserted(k));
  // A changed domain first: the decomposition's rule below would take it for damage.
  if (checkpoint.model) check_model(*checkpoint.model, scene_, checkpoint.file, "domain.");
  check_checkpoint(checkpoint, scene_, walls_.history_columns(), streams_.max_radius(), delivered);

  if (heat_ && !checkpoint.has_temperature)
    throw SetupError(scene_.file + ": error: heat is on, but " + where +
                     " holds no particle temperatures (it was written by a run without heat "
                     "transfer); run the scene from the start, or restart with a scene whose "
                     "heat settings match the checkpoint's run");
  // The run's model: after the rules above, whose messages name a changed density or parcel
  // class more precisely.
  if (checkpoint.model) check_model(*checkpoint.model, scene_, checkpoint.file);
  p_ = checkpoint.particles;
  restored_drag_.clear();
  for (std::size_t i = 0; i < checkpoint.drag_coefficient.size(); ++i)
    restored_drag_[checkpoint.particles.id[i]] = {checkpoint.drag_coefficient[i],
                                                  checkpoint.drag_fluid_velocity[i]};
  time_ = checkpoint.time;
  // The run continues with the step it was written with (check_restart_step).
  if (dt_ <= 0) dt_ = checkpoint.dt;
  counters_.steps = checkpoint.step;
  counters_.rebuilds = checkpoint.rebuilds;  // paces parallel.balance as in the written run
  restored_largest_radius_ = checkpoint.largest_radius;
  {
    int rank = 0;  // the removed total is a sum over ranks: rank 0 carries the earlier part
    MPI_Comm_rank(comm_, &rank);
    counters_.removed = rank == 0 ? checkpoint.removed : 0;
  }
  next_id_ = checkpoint.next_id;
  restored_springs_ = checkpoint.springs;
  restored_grid_ = checkpoint.grid;
  // The wall loads' sums since the last log row before the checkpoint (global, so rank 0
  // takes them); a checkpoint without them starts the sums at the restart.
  if (!wall_impulse_.empty() && !checkpoint.wall_impulse.empty()) {
    const std::vector<double>& j = checkpoint.wall_impulse;
    if (j.size() != 3 * wall_impulse_.size() + 1 ||
        !std::all_of(j.begin(), j.end(), [](double x) { return std::isfinite(x); }) || j.back() < 0)
      throw SetupError(scene_.file + ": error: " + where + ": attribute 'wall_impulse' holds " +
                       std::to_string(j.size()) + " values" +
                       (j.size() == 3 * wall_impulse_.size() + 1
                            ? " with a non-finite value or a negative time span"
                            : std::string(", but the scene's ") +
                                  std::to_string(wall_impulse_.size()) + " walls need " +
                                  std::to_string(3 * wall_impulse_.size() + 1)) +
                       "; the file is damaged or from another scene: restart from another "
                       "checkpoint, or with the scene it was written with");
    int rank = 0;
    MPI_Comm_rank(comm_, &rank);
    for (std::size_t w = 0; w < wall_impulse_.size(); ++w)
      wall_impulse_[w] =
          rank == 0 ? Vec3(checkpoint.wall_impulse[3 * w], checkpoint.wall_impulse[3 * w + 1],
                           checkpoint.wall_impulse[3 * w + 2])
                    : Vec3::Zero();
    wall_load_time_ = checkpoint.wall_impulse.back();
  }
  // Last, after every rule (which names a value it refuses): the root attributes against
  // their checksum, which no rule sees for a value that is merely wrong (a dt, a time, a
  // step with one flipped bit).
  if (checkpoint.attributes_checksum_stored &&
      checkpoint.attributes_checksum_stored != checkpoint.attributes_checksum_read) {
    char sums[64];
    std::snprintf(sums, sizeof sums, "stored 0x%08x, computed 0x%08x",
                  *checkpoint.attributes_checksum_stored, *checkpoint.attributes_checksum_read);
    throw StateError(checkpoint.file +
                     ": error: the root group's attributes (time, dt, step, next_id, rebuilds, "
                     "material_coarse_grain, material_real, wall_impulse, largest_radius, "
                     "removed, skin, rayleigh_fraction) do not match their "
                     "checksum, attribute 'attributes_checksum' (" +
                     sums +
                     "): the checkpoint was changed or damaged after it was written; restart "
                     "from an earlier checkpoint of this run (no file was changed or deleted)");
  }
  restored_ = true;
  network_recorded_ = false;
}

void Simulation::write_checkpoint(const std::string& path) {
  CheckpointData d;
  d.time = time_;
  d.dt = dt_;
  d.step = counters_.steps;
  d.rebuilds = counters_.rebuilds;
  if (initialised_) {
    d.largest_radius = largest_radius_;
    d.skin = skin_;
  }
  d.rayleigh_fraction = scene_.time.rayleigh_fraction.value_or(0.0);
  d.removed = counters_.removed;
  MPI_Allreduce(MPI_IN_PLACE, &d.removed, 1, MPI_LONG, MPI_SUM, comm_);
  d.next_id = next_id_;
  d.particles = p_;
  d.has_temperature = heat_ != nullptr;
  for (std::size_t m = 0; m < scene_.materials.size(); ++m) {
    const Material& mat = scene_.materials[m];
    d.material_coarse_grain.push_back(mat.coarse_grain);
    d.material_real.push_back(mat.real_material < 0 ? static_cast<int>(m) : mat.real_material);
  }
  if (!terms_.empty()) {
    d.drag_coefficient = drag_.coefficient;
    d.drag_fluid_velocity = drag_.fluid_velocity;
  }
  d.streams = streams_.save_state();
  d.insertions = insertion_record(scene_);
  d.model = scene_.model_record;
  if (log_record_ && !log_record_->empty()) d.log = *log_record_;  // (empty: not kept)
  if (!wall_impulse_.empty()) {
    d.wall_impulse.reserve(3 * wall_impulse_.size() + 1);
    for (const Vec3& j : wall_impulse_)
      d.wall_impulse.insert(d.wall_impulse.end(), {j[0], j[1], j[2]});
    MPI_Allreduce(MPI_IN_PLACE, d.wall_impulse.data(), static_cast<int>(d.wall_impulse.size()),
                  MPI_DOUBLE, MPI_SUM, comm_);
    // This run goes on as a restart from the file does (restore): the sums so far on rank 0,
    // none on the others, so that the next row adds the ranks' parts in the same order (on 2
    // ranks a restart's row had differed from its run's in the last bit).
    int rank = 0;
    MPI_Comm_rank(comm_, &rank);
    for (std::size_t w = 0; w < wall_impulse_.size(); ++w)
      wall_impulse_[w] = rank == 0 ? Vec3(d.wall_impulse[3 * w], d.wall_impulse[3 * w + 1],
                                          d.wall_impulse[3 * w + 2])
                                   : Vec3::Zero();
    d.wall_impulse.push_back(wall_load_time_);
  }
  CheckpointGrid& grid = d.grid.emplace();
  grid.ranks = decomp_->size();
  grid.dims = decomp_->dims();
  for (int a = 0; a < 3; ++a) grid.cuts[a] = decomp_->cuts(a);
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
  refresh_spin_drag();          // in the new order, as a restart from the file finds it
}

void Simulation::refresh_spin_drag() {
  // The spin drag is not in the checkpoint: a function of the particles' state, the terms
  // give it again, without adding their forces a second time or changing the drag.
  bool spin = false;
  for (const auto& term : terms_) spin |= term->implicit_spin();
  if (!spin) return;
  const std::vector<Vec3> force = p_.force, torque = p_.torque;
  const std::vector<double> k = drag_.coefficient;
  const std::vector<Vec3> u = drag_.fluid_velocity;
  apply_force_terms();
  p_.force = force;
  p_.torque = torque;
  drag_.coefficient = k;
  drag_.fluid_velocity = u;
}

void Simulation::rebuild(bool keep_drag) {
  fluid_explicit_.clear();  // in the old order; a recording evaluation follows a step's rebuild
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
  if (left_through_wall_) agree_on_error(comm_, left_through_wall_message());  // throws
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
  if (scene_.parallel.reproducible)
    canonical_.build(p_, ghosts_, local_list_, ghost_list_, *grid_);
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

ContactGuards Simulation::compute_forces(bool advance_springs) {
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
      advance_springs ? dt_ : 0.0,
      uniform_, 0,             0.0,              WorstContact{}, UnresolvedContact{}};
  // clang-format on
  s.canonical = &canonical_;
  if (forward_pending_) s.ghosts_ready = [this] { finish_forward(); };
  if (!wall_forces_.empty()) {
    std::fill(wall_forces_.begin(), wall_forces_.end(), Vec3::Zero());
    s.wall_forces = &wall_forces_;
  }
  // Before the sweep: it reads the springs as the sweep will, and leaves them unchanged.
  if (record_contacts_) {
    finish_forward();
    sweep_.report(s, network_);
    network_recorded_ = true;
  } else if (network_recorded_) {
    network_.clear();  // of another step: never to be read as this one's
    network_recorded_ = false;
  }
  sweep_.run(s);
  finish_forward();  // when the sweep read no ghost
  if (advance_springs && !wall_forces_.empty()) {  // a step's forces (not the initial state's)
    for (std::size_t w = 0; w < wall_forces_.size(); ++w) wall_impulse_[w] += dt_ * wall_forces_[w];
    wall_load_time_ += dt_;
  }
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
  if (record_fluid_ && !terms_.empty()) {
    // The terms add to the contact forces; their share is the difference (rounded at the
    // scale of the whole force), so the forces are summed as without the record.
    fluid_explicit_ = p_.force;
    apply_force_terms();
    for (std::size_t i = 0; i < p_.size(); ++i)
      fluid_explicit_[i] = p_.force[i] - fluid_explicit_[i];
  } else {
    fluid_explicit_.clear();  // of another step: never to be read as this one's
    apply_force_terms();
  }
  return {s.worst, s.unresolved, fastest_particle(v2_local)};
}

void Simulation::finish_forward() {
  if (!forward_pending_) return;
  forward_pending_ = false;
  exchange_->forward_end(p_, ghosts_);
}

FastParticle Simulation::fastest_particle(double v2_max) const {
  // A particle that moves more than its radius r in one step can cross a (two-sided,
  // thin) mesh wall, or pass through another particle, without the two ever overlapping at
  // the end of a step, so no contact guard can see it (docs/stability.md). The drift just
  // made moved each particle by |v| dt with the velocity of the half kick before it. The
  // gate needs no division: nobody can exceed the limit while v_max dt <= limit r_min.
  FastParticle fast;
  const double limit = scene_.time.max_step_travel;
  // Nothing to pass through where nothing can touch (one particle, no walls).
  if (limit <= 0 || !scene_.contacts_possible ||
      v2_max * dt_ * dt_ <= limit * limit * smallest_radius_ * smallest_radius_)
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
  if (decomp_->size() > 1) {
    const double start = MPI_Wtime();
    MPI_Allreduce(MPI_IN_PLACE, worst, 4, MPI_DOUBLE, MPI_MAX, comm_);
    collective_wait_seconds_ += MPI_Wtime() - start;
  }
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
         "guard can see. A step of at most ";
    // Within the limit, and (when the start-up time-step check refuses dt as well, which it
    // reports only after this first step) within what that check accepts.
    const double within = round_down_3(travel_limit * r / speed);
    // The start-up limits' smallest proposal (refusal_step): the contacts' and, with heat,
    // conduction's; proposing the contacts' alone was refused again for conduction (found by
    // the hard-scene generator, thermal seed 717).
    const bool startup =
        report_.verdict == TimeStepReport::Verdict::refuse && report_.refusal_step < within;
    if (startup)
      o << round_down_3(report_.refusal_step) << " s keeps it within the limit (" << within
        << " s) and passes every start-up check of dt (the Rayleigh and contact times"
        << (scene_.heat ? ", heat conduction" : "") << "), which refuse dt = " << dt_ << " s too";
    else
      o << within << " s keeps it within the limit";
    // A one-way flow faster than the particle drags it on towards its own speed: a step
    // that fits only today's speed is refused again a few steps later.
    double fluid_max = 0;
    if (scene_.fluid)
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3 at((corner & 1) ? scene_.domain.hi[0] : scene_.domain.lo[0],
                     (corner & 2) ? scene_.domain.hi[1] : scene_.domain.lo[1],
                     (corner & 4) ? scene_.domain.hi[2] : scene_.domain.lo[2]);
        fluid_max =
            std::max(fluid_max, scene_.fluid->field.sample(at, scene_.gravity).velocity.norm());
      }
    if (fluid_max > speed)
      o << "; the fluid reaches " << fluid_max << " m/s in the domain and drags the particle "
        << "towards it: a step of at most " << round_down_3(travel_limit * r / fluid_max)
        << " s keeps it within the limit at that speed";
    // Gravity goes on accelerating a falling particle: a step that fits today's speed is
    // refused again a few steps later. The speed gravity alone gives it by the end of the run,
    // or by a fall across the domain's bounded extent along gravity, whichever is less.
    const double g = scene_.gravity.norm();
    if (g > 0 && scene_.time.end > time_) {
      double fall = 0;
      bool bounded = true;
      for (int a = 0; a < 3; ++a) {
        const double along = std::abs(scene_.gravity[a]) / g;
        if (along <= 1e-12) continue;
        if (scene_.domain.periodic[a]) bounded = false;
        fall += along * (scene_.domain.hi[a] - scene_.domain.lo[a]);
      }
      const double by_end = speed + g * (scene_.time.end - time_);
      const double v_g =
          bounded ? std::min(by_end, std::sqrt(speed * speed + 2 * g * fall)) : by_end;
      if (v_g > 1.01 * std::max(speed, fluid_max))
        o << "; gravity alone takes it to " << v_g << " m/s by "
          << (bounded && v_g < by_end ? "a fall across the domain" : "the end of the run")
          << ": a step of at most " << round_down_3(travel_limit * r / v_g)
          << " s keeps it within the limit then";
    }
    if (scene_.contact.normal == NormalModel::hertz) {
      // An impact at that speed on a wall of its own material: R* = r, m* = m.
      const double tc =
          hertz_contact_time(table_(p_.material[i], p_.material[i]).y_star, r, p_.mass[i], speed);
      if (std::isfinite(tc))
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
  // Every ghost gets its owner's force (collective), so that the load describe_overlap finds
  // on a particle held by another rank (or on a periodic image) is the force itself, not its
  // weight: the message is then the same on any number of ranks.
  if (overlap) {
    std::vector<double> local(3 * p_.size());
    for (std::size_t i = 0; i < p_.size(); ++i) {
      Vec3 f = p_.force[i];
      if (i < drag_.coefficient.size())
        f += drag_.coefficient[i] * (drag_.fluid_velocity[i] - p_.v[i]);
      for (int a = 0; a < 3; ++a) local[3 * i + a] = f[a];
    }
    exchange_->forward_values(local, 3, ghost_force_);
  }
  if (overlap ? mine[0] != worst[0] : mine[1] != worst[1]) {
    agree_on_error(comm_, "");  // another rank holds the contact and speaks
    return worst[3] == 0;       // not reached
  }
  if (w.b >= 0) {
    o << "particles " << w.a << " and " << w.b;
  } else {
    // The wall it overlaps most (this rank holds the particle): named, among several walls.
    int wall = -1;
    for (std::size_t i = 0; i < p_.size() && wall < 0; ++i)
      if (p_.id[i] == w.a) wall = walls_.deepest_overlap(p_.x[i], p_.radius[i]).wall;
    if (wall >= 0)
      o << "particle " << w.a << " and wall '" << walls_.walls()[wall].name << "'";
    else
      o << "particle " << w.a << " and a wall";
  }
  if (!overlap) {
    const double tc =
        hertz_contact_time(w.y_star, w.r_star, w.m_star, std::max(std::abs(w.speed), 1e-12));
    o << " approach at " << w.speed << " m/s, overlapping by " << 100 * s.unresolved.overlap_ratio
      << " % of the smaller radius. At that speed a Hertz contact lasts " << tc << " s: only "
      << s.unresolved.fewest << " steps of dt = " << dt_ << " s (fewer than " << n_min
      << ", key time.min_steps_per_contact). So coarse a step cannot resolve the contact and "
         "can give it back more energy than it took. A step of at most ";
    // In the first step the start-up check may refuse dt as well (it reports after it): then
    // the proposal is also within every limit that check has (conduction's, with heat).
    const bool startup =
        report_.verdict == TimeStepReport::Verdict::refuse && report_.refusal_step < tc / 20;
    if (startup)
      o << round_down_3(report_.refusal_step) << " s would (1/20 of the Hertz contact time at "
        << "that speed is " << tc / 20
        << " s, and every start-up check of dt (the Rayleigh and contact times"
        << (scene_.heat ? ", heat conduction" : "") << "), which refuse dt = " << dt_
        << " s too, needs at most " << round_down_3(report_.refusal_step) << " s)";
    else
      o << tc / 20 << " s would (1/20 of the Hertz contact time at that speed)";
    o << "; lower time.step or time.rayleigh_fraction, or raise time.expected_max_speed so that "
         "grain check warns about it; or set time.min_steps_per_contact: 0 to let such contacts "
         "through (to measure under-resolved impacts on purpose)";
  } else {
    o << " overlap by " << 100 * worst[0] << " % of the smaller radius (limit " << 100 * limit
      << " %, key time.max_overlap)";
    describe_overlap(o, w, worst[0]);
  }
  agree_on_error(comm_, o.str());  // the rank holding the worst contact speaks
  return worst[3] == 0;            // not reached: agree_on_error throws on every rank
}

namespace {
// A contact is resolved with at least this many steps per contact time; a proposed step is
// the contact time over it, and is proposed only when it is smaller than the step that ran.
constexpr double kResolvingSteps = 20;

// At most 2 significant digits, rounded up (a proposal that must be reached).
double round_up(double x) {
  if (!(x > 0) || !std::isfinite(x)) return x;
  const double unit = std::pow(10.0, std::floor(std::log10(x)) - 1);
  return std::ceil(x / unit * (1 - 1e-12)) * unit;
}
}  // namespace

namespace {
// Whether a sphere (x, r) touches a plane or a cylinder, with the touch in t; false for a mesh
// (no single normal: the messages below do without it).
bool touches_analytic_wall(const WallSet::Entry& e, const Vec3& x, double r, WallTouch& t) {
  switch (e.kind) {
    case Wall::Kind::plane:
      return touch_plane(e.plane, x, r, t);
    case Wall::Kind::cylinder:
      return touch_cylinder(e.cylinder, x, r, t);
    case Wall::Kind::mesh:
      return false;
  }
  return false;
}
}  // namespace

void Simulation::describe_overlap(std::ostream& o, const WorstContact& w, double ratio) const {
  // The two bodies: particles by id (local first, then ghosts), or the wall the particle
  // overlaps most (planes and cylinders; a mesh gives no normal here, and no load).
  struct Body {
    bool found = false;
    Vec3 x = Vec3::Zero();
    double r = 0, m = 0;
    int material = 0;
    long local = -1;  // index among this rank's particles (their force is known), or -1
    Vec3 v = Vec3::Zero();
    long ghost = -1;  // index among the ghosts (their owner's force in ghost_force_), or -1
  };
  const auto find = [&](GlobalId id) {
    Body b;
    for (std::size_t i = 0; i < p_.size() && !b.found; ++i)
      if (p_.id[i] == id)
        b = {true,           p_.x[i], p_.radius[i], p_.mass[i], p_.material[i],
             static_cast<long>(i), p_.v[i]};
    for (std::size_t q = 0; q < ghosts_.id.size() && !b.found; ++q)
      if (ghosts_.id[q] == id)
        b = {true, ghosts_.position(q), ghosts_.radius[q],   ghosts_.mass[q], ghosts_.material[q],
             -1,   ghosts_.v[q],        static_cast<long>(q)};
    return b;
  };
  const Body a = find(w.a);
  const Body b = w.b >= 0 ? find(w.b) : Body{};
  const Vec3 g = scene_.gravity;
  ContactLoad c;
  c.hertz = scene_.contact.normal == NormalModel::hertz;
  c.speed = w.speed;
  c.r_star = w.r_star;
  c.m_star = w.m_star;
  c.wall = w.b < 0;
  c.r_i = a.r;
  c.r_j = b.r;
  c.r_small = c.wall ? a.r : std::min(a.r, b.r);
  c.overlap = ratio * c.r_small;
  int material_b = b.material;
  std::string wall_name;
  const WallSet::Entry* wall = nullptr;
  Vec3 n = Vec3::Zero();  // the contact normal, towards a (zero: not known, a mesh)
  if (c.wall) {
    double best = std::numeric_limits<double>::infinity();
    for (const WallSet::Entry& e : walls_.walls()) {
      WallTouch t;
      if (touches_analytic_wall(e, a.x, a.r, t) && std::abs(t.overlap - c.overlap) < best) {
        best = std::abs(t.overlap - c.overlap);
        wall = &e;
        n = t.n;
      }
    }
    if (wall == nullptr)  // a mesh: the first one the particle could touch
      for (const WallSet::Entry& e : walls_.walls())
        if (e.kind == Wall::Kind::mesh && wall == nullptr) wall = &e;
    if (wall != nullptr) {
      material_b = wall->material;
      wall_name = wall->name;
    }
  } else if (a.found && b.found) {
    n = (a.x - b.x).normalized();
  }
  const PairCoefficients& pc = table_(a.material, material_b);
  c.y_star = pc.y_star;
  if (!c.hertz) c.kn = HookeNormal::coefficients(pc, constants_, c.r_star, c.m_star, 0).kn;
  if (scene_.contact.cohesion == CohesionModel::sjkr) c.cohesion = pc.cohesion_energy_density;
  // The load pressing the contact: for a partner, every force on it but this
  // contact's (its weight, the particles and walls pressing on it, fluid forces), along n;
  // this contact's own force is taken as its elastic part less cohesion (its damping, which
  // resists the approach, is left in, so the load is if anything underestimated). A partner
  // held by another rank, or a periodic image, is a ghost: its owner's force was forwarded to
  // it (check_contacts), so the load is the same on any number of ranks.
  std::string load_by;
  const Body* pressed = nullptr;  // the body whose load that is, and the direction it is
  Vec3 into = Vec3::Zero();       // pressed in: towards its partner in the contact
  // The implicit drag K (u_f - v) acts through the velocity update, not p_.force: add it.
  const auto force_on = [&](long i) {
    Vec3 f = p_.force[i];
    if (static_cast<std::size_t>(i) < drag_.coefficient.size())
      f += drag_.coefficient[i] * (drag_.fluid_velocity[i] - p_.v[i]);
    return f;
  };
  // A body's force when it is known (held here, or a ghost given its owner's force).
  const auto known_force = [&](long local, long ghost, Vec3& f) {
    if (local >= 0) {
      f = force_on(local);
      return true;
    }
    if (ghost < 0 || static_cast<std::size_t>(3 * ghost + 2) >= ghost_force_.size()) return false;
    f = Vec3(ghost_force_[3 * ghost], ghost_force_[3 * ghost + 1], ghost_force_[3 * ghost + 2]);
    return true;
  };
  if (n.squaredNorm() > 0) {
    const double own = elastic_force(c, c.overlap) - cohesion_force(c, c.overlap);
    const auto pressing = [&](const Body& body, double sign, GlobalId id) {
      Vec3 f;
      const double load = known_force(body.local, body.ghost, f) ? own - sign * f.dot(n)
                                                                 : -sign * body.m * g.dot(n);
      if (load > c.load) {
        c.load = load;
        load_by = "particle " + std::to_string(id);
        pressed = &body;
        into = -sign * n;
      }
    };
    pressing(a, 1, w.a);  // a is pushed along +n by the contact
    if (!c.wall && b.found) pressing(b, -1, w.b);
  }
  // A chain: a heavier particle D drives a lighter one P into a body X behind it (a wall or
  // a particle), through the contacts D-P and P-X, which carry one force when P is light.
  // The force D passes on grows with the stiffness, so a fixed load understates it: the two
  // contacts are judged together (ContactLoad::series), with D's mass and approach speed
  // towards X and every other force on D and P as the load. Either contact may be the one
  // that passed the limit: D a heavier neighbour pushing the loaded body into this contact,
  // or this contact's heavier partner with the loaded body's backing (a wall or particle
  // within 60 degrees of the line) as X. Of the chains found, the one that stops deepest.
  std::optional<ContactLoad> chain;
  GlobalId driver_id = 0, middle_id = 0;
  double driver_mass = 0, middle_mass = 0, chain_stop = 0, group_mass = 0;
  std::size_t group_size = 0;
  std::string backing;  // X: "wall 'floor'" or "particle 7"
  int driver_material = 0;
  {
    struct Ball {
      GlobalId id = 0;
      Vec3 x = Vec3::Zero(), v = Vec3::Zero();
      double r = 0, m = 0;
      int material = 0;
      long local = -1, ghost = -1;
    };
    const auto ball = [](GlobalId id, const Body& body) {
      return Ball{id, body.x, body.v, body.r, body.m, body.material, body.local, body.ghost};
    };
    // The contact of sphere p with a sphere (or, with q == nullptr, a wall of `wall_material`)
    // at `overlap`: its coefficients and elastic force.
    const auto contact_of = [&](const Ball& p, const Ball* q, int wall_material, double overlap) {
      ContactLoad k = c;
      k.wall = q == nullptr;
      k.r_star = q ? p.r * q->r / (p.r + q->r) : p.r;
      k.m_star = q ? p.m * q->m / (p.m + q->m) : p.m;
      const PairCoefficients& pq = table_(p.material, q ? q->material : wall_material);
      k.y_star = pq.y_star;
      if (!c.hertz) k.kn = HookeNormal::coefficients(pq, constants_, k.r_star, k.m_star, 0).kn;
      k.overlap = overlap;
      return k;
    };
    const auto stiffness = [&](const ContactLoad& k) {
      return c.hertz ? std::pow(k.y_star * std::sqrt(k.r_star), 2.0 / 3.0) : k.kn;
    };
    const auto others = [&](const Ball& body, const Vec3& u) {
      Vec3 f;
      return known_force(body.local, body.ghost, f) ? f.dot(u) : body.m * g.dot(u);
    };
    // Each sphere touching p (not `skip1`, `skip2`) whose push on p lies within 60 degrees
    // of `dir`: f(ball, unit push direction, overlap).
    const auto touching = [&](const Ball& p, GlobalId skip1, GlobalId skip2, const Vec3& dir,
                              const auto& f) {
      const auto one = [&](const Ball& q) {
        if (q.id == p.id || q.id == skip1 || q.id == skip2) return;
        const double dist = (p.x - q.x).norm(), overlap = p.r + q.r - dist;
        if (!(overlap > 0) || !(dist > 0)) return;
        const Vec3 e = (p.x - q.x) / dist;
        if (e.dot(dir) >= 0.5) f(q, e, overlap);
      };
      for (std::size_t i = 0; i < p_.size(); ++i)
        one(Ball{p_.id[i], p_.x[i], p_.v[i], p_.radius[i], p_.mass[i], p_.material[i],
                 static_cast<long>(i)});
      for (std::size_t q = 0; q < ghosts_.id.size(); ++q)
        one(Ball{ghosts_.id[q], ghosts_.position(q), ghosts_.v[q], ghosts_.radius[q],
                 ghosts_.mass[q], ghosts_.material[q], -1, static_cast<long>(q)});
    };
    // D drives P towards X along u; `dp` and `px` are the two contacts, `dp_checked` whether
    // D-P is the contact that passed the limit (else P-X is). For a wall, x == nullptr.
    const auto offer = [&](const Ball& d, const Ball& p, const Ball* x, const std::string& x_name,
                           const Vec3& u, const ContactLoad& dp, const ContactLoad& px,
                           bool dp_checked) {
      if (!(d.m > p.m)) return;
      const ContactLoad& checked = dp_checked ? dp : px;
      const ContactLoad& other = dp_checked ? px : dp;
      // The driving group: D, and the spheres pressing D (and those pressing them, two layers)
      // along u: a heavy stack drives as one. Its mass, its kinetic energy towards X (each
      // member's own, an upper bound on what the stack can deliver), and the sum of the
      // members' forces along u, in which their contacts with one another cancel.
      std::vector<Ball> group{d};
      for (std::size_t layer = 0, from = 0; layer < 2; ++layer) {
        const std::size_t to = group.size();
        for (std::size_t i = from; i < to; ++i)
          touching(group[i], p.id, x != nullptr ? x->id : p.id, u,
                   [&](const Ball& q, const Vec3&, double) {
                     for (const Ball& m : group)
                       if (m.id == q.id) return;
                     group.push_back(q);
                   });
        from = to;
      }
      const Vec3 v_x = x != nullptr ? x->v : Vec3::Zero();
      // The contacts' elastic forces (this one's less its cohesion, as for a single contact).
      const double f_dp =
          elastic_force(dp, dp.overlap) - (dp_checked ? cohesion_force(dp, dp.overlap) : 0);
      const double f_px =
          elastic_force(px, px.overlap) - (dp_checked ? 0 : cohesion_force(px, px.overlap));
      // Every force on the group and on P along u but the two contacts' (for a sphere whose
      // force is not known here, its weight).
      const auto known = [](const Ball& s) { return s.local >= 0 || s.ghost >= 0; };
      double mass = p.m, kinetic = 0;
      double load = known(p) ? others(p, u) - f_dp + f_px : others(p, u);
      for (const Ball& m : group) {
        mass += m.m;
        load += others(m, u) + (m.id == d.id && known(m) ? f_dp : 0.0);
      }
      const auto approach = [&](const Ball& m) { return std::max(0.0, (m.v - v_x).dot(u)); };
      kinetic += 0.5 * p.m * approach(p) * approach(p);
      for (const Ball& m : group) kinetic += 0.5 * m.m * approach(m) * approach(m);
      ContactLoad k = c;
      // At equal force the other contact's overlap per overlap of this one: k/k₂ (Hooke) or
      // (K/K₂)^{2/3} (Hertz, K = (4/3) Y* √R*), which `stiffness` gives to the power 1.
      k.series = stiffness(checked) / stiffness(other);
      k.series_overlap = other.overlap;
      k.m_star = x != nullptr ? mass * x->m / (mass + x->m) : mass;
      // The group's approach speed towards X: its kinetic energy in X's frame is that of its
      // whole mass at this speed (mass-weighted rms). The energy the contacts can take is then
      // ½ m* v² (X recoils: a light X takes little); dividing the kinetic energy by m* had
      // made a heavy group pressing a light particle approach at 19.9 m/s in a box whose
      // fastest particle moved at 3.3 m/s, and asked for a contact 57 times stiffer.
      k.speed = std::sqrt(2 * kinetic / mass);
      k.load = std::max(0.0, load);
      const double st = stopping_overlap(k);
      if (chain && !(st > chain_stop)) return;
      chain = k;
      chain_stop = st;
      driver_id = d.id;
      driver_mass = d.m;
      driver_material = d.material;
      group_size = group.size();
      group_mass = mass - p.m;
      middle_mass = p.m;
      middle_id = p.id;
      backing = x != nullptr ? "particle " + std::to_string(x->id) : x_name;
    };
    // This contact between P and X, driven by a heavier neighbour D of the loaded body P.
    if (pressed != nullptr) {
      const Ball p = ball(pressed == &a ? w.a : w.b, *pressed);
      const Body* far = c.wall ? nullptr : (pressed == &a ? &b : &a);
      const std::optional<Ball> x = far != nullptr
                                        ? std::optional<Ball>(ball(pressed == &a ? w.b : w.a, *far))
                                        : std::nullopt;
      const ContactLoad px = contact_of(p, x ? &*x : nullptr, material_b, c.overlap);
      touching(p, w.a, w.b, into, [&](const Ball& d, const Vec3& e, double overlap) {
        offer(d, p, x ? &*x : nullptr, wall_name.empty() ? "a wall" : "wall '" + wall_name + "'",
              into, contact_of(p, &d, 0, overlap), px, false);
        (void)e;
      });
    }
    // This contact between a heavier D and P, P backed by a wall or a particle X.
    if (!c.wall && a.found && b.found) {
      const bool a_heavier = a.m > b.m;
      const Ball d = a_heavier ? ball(w.a, a) : ball(w.b, b);
      const Ball p = a_heavier ? ball(w.b, b) : ball(w.a, a);
      const Vec3 u = (p.x - d.x).normalized();  // D's drive, through P, towards X
      const ContactLoad dp = contact_of(p, &d, 0, c.overlap);
      for (const WallSet::Entry& e : walls_.walls()) {
        WallTouch t;
        if (touches_analytic_wall(e, p.x, p.r, t) && t.n.dot(-u) >= 0.5)
          offer(d, p, nullptr, "wall '" + e.name + "'", u, dp,
                contact_of(p, nullptr, e.material, t.overlap), true);
      }
      touching(p, d.id, d.id, -u, [&](const Ball& x, const Vec3& e, double overlap) {
        offer(d, p, &x, "", u, dp, contact_of(p, &x, 0, overlap), true);
        (void)e;
      });
    }
  }
  const double limit = scene_.time.max_overlap, at_limit = limit * c.r_small;
  // The contact lasts as long as its impact, not as the speed left near its deepest point
  // gives (Hertz t_c ~ v^(-1/5)). A free contact (its load under 1 % of the spring's force,
  // no cohesion, no chain) lies on the path of one damped head-on impact, whose speed at first
  // touch damped_impact_speed finds; a loaded one gets the speed its energy now implies (kinetic
  // plus elastic, less the load's and cohesion's work: undamped, so a lower bound).
  // A 16 m/s impact at e = 0.5, stopped approaching at 5.1 m/s: 16.0 and 12.1 m/s
  // (tests/dem/engine/overload_guard_test.cpp).
  // The state is on that path only when the steps resolve the contact: below
  // kRefuseStepsPerContact steps (counted at the speed left, so at most that many at the
  // impact's) a step's travel, not the contact, set it, and the speed left is the one known.
  const bool free_impact = c.load <= 0.01 * elastic_force(c, c.overlap) && c.cohesion <= 0;
  const bool on_path = w.speed > -1e-9 &&
                       pair_contact_time(scene_.contact, pc, constants_, c.r_star, c.m_star,
                                         std::max(w.speed, 1e-12)) >= kRefuseStepsPerContact * dt_;
  const double impact = !on_path      ? std::max(w.speed, 0.0)
                        : free_impact ? damped_impact_speed(scene_.contact, pc, constants_,
                                                            c.r_star, c.m_star, c.overlap, w.speed)
                                      : std::max(at_first_touch(c).speed, w.speed);
  const double tc = pair_contact_time(scene_.contact, pc, constants_, c.r_star, c.m_star,
                                      std::max(std::max(std::abs(w.speed), impact), 1e-12));
  const double steps = tc / dt_;
  const char* remedy =
      " s would resolve it (1/20 of the contact time at that speed); lower time.step or "
      "time.rayleigh_fraction, or raise time.expected_max_speed so that grain check warns "
      "about it";
  if (w.speed < -1e-9) {
    // Deep and already separating at its first sight: the bodies went deep within one step
    // (the centre past a two-sided mesh or another particle's centre, a thin rod through a
    // sphere, a glancing blow). Its speed then is that of the whole relative motion, not the
    // normal speed left now: at most |v_a| + |v_b|, or |v_a| + the fastest wall's sweep speed.
    double v_rel = a.v.norm();
    if (c.wall) {
      double sweep = 0;
      for (std::size_t k = 0; k < scene_.walls.size(); ++k)
        sweep = std::max(sweep, wall_sweep_speed(scene_, walls_, k));
      v_rel += sweep;
    } else {
      v_rel += b.v.norm();
    }
    v_rel = std::max(v_rel, -w.speed);
    // A step in which that motion covers at most the limit overlap, and resolves an impact
    // at that speed (1/20 of its contact time): the smaller.
    const double tc_rel = pair_contact_time(scene_.contact, pc, constants_, c.r_star, c.m_star,
                                            v_rel);
    const double travel_step = at_limit / v_rel;
    const double step = std::min(tc_rel / kResolvingSteps, travel_step);
    o << ", moving apart at " << -w.speed << " m/s: it went this deep within one step of dt = "
      << dt_ << " s (tunnelled: the centre across the other surface, a thin body through the "
      << "sphere, or a "
      << "glancing blow; or the two were placed overlapping), at a relative speed of up to "
      << v_rel << " m/s";
    if (step < dt_) {
      o << ". A step of at most " << step << " s would resolve it (at that speed, a step's "
        << "travel within the limit overlap of " << at_limit << " m, and 1/20 of the contact "
        << "time, " << tc_rel << " s); lower time.step or time.rayleigh_fraction";
    } else {
      o << ", which dt already keeps within the limit: check the initial positions, or what "
           "pressed the particle in (a moving wall, a load); a larger time.max_overlap lets a "
           "deeper contact push it back out";
    }
    return;
  }
  if (counters_.steps == 0 && w.speed <= 1e-9) {
    o << " at the start, before any step: check the initial positions (insertion, CSV, "
         "snapshot)";
    return;
  }
  const double stop = stopping_overlap(c);
  const auto stop_text = [&] {
    std::ostringstream t;
    t.precision(4);
    if (stop < kNoStop)
      t << "undamped, it stops at " << 100 * stop / c.r_small << " %";
    else
      t << "it does not stop before the overlap reaches the whole smaller radius";
    return t.str();
  };
  if (w.speed > 1e-9)
    o << ", approaching at " << w.speed << " m/s";
  else
    o << ", at rest";
  if (impact > 1.01 * std::max(w.speed, 0.0))
    o << (free_impact ? " (an impact at " : " (an impact at least at ") << impact
      << " m/s, by its overlap and speed now)";
  // The step is to blame only when it does not resolve the contact and the contact, resolved,
  // would stop within the limit: the undamped stop predicted from its energy and load now
  // bounds a resolved run's deepest overlap (overload.hpp). But that energy is the integrated
  // one, and velocity Verlet at N steps per contact overstates it: measured on Hertz impacts,
  // the predicted stop exceeds the closed form by about 5/N^2 (4.3 % at 10.2 steps, 5.5 % at
  // 8.5; docs/stability.md). Within that margin of the limit the step may still be the cause;
  // beyond it, no step helps. Below kRefuseStepsPerContact (5) steps, where the start-up
  // check refuses a step outright, the integrated energy is not evidence at all.
  // The overstatement is of the contact's oscillation about its equilibrium under the load
  // (the whole stop for an impact, nothing for a contact pressed slowly to its limit).
  // Below kRefuseStepsPerContact, only a load the spring cannot carry within the limit
  // (the equilibrium beyond it) acquits the step.
  const double integration_error = steps < kRefuseStepsPerContact ? 1.0 : 5 / (steps * steps);
  const double equilibrium = equilibrium_overlap(c);
  const bool step_is_the_cause =
      steps < kRefuseStepsPerContact
          ? equilibrium <= at_limit
          : steps < kResolvingSteps && stop < kNoStop &&
                stop - integration_error * (stop - std::min(equilibrium, stop)) <= at_limit;
  if (step_is_the_cause) {
    o << ": the time step dt = " << dt_ << " s is too large to resolve this contact (it lasts "
      << tc << " s at that speed, " << steps << " steps; " << kResolvingSteps
      << " resolve it). Resolved, the contact stops ";
    if (stop <= at_limit)
      o << "within the limit (by its energy and load now, " << stop_text() << ")";
    else
      o << "near the limit, or within it (by its energy and load now, " << stop_text()
        << ", an energy that at " << steps << " steps per contact "
        << (integration_error < 1 ? "may be overstated by about " +
                                        significant(100 * integration_error, 2) + " %"
                                  : std::string("is no evidence"))
        << "; if a finer step stops again, the message will say what carries the contact)";
    o << ". A step of at most " << tc / kResolvingSteps << remedy;
    if (restored_)
      o << " (this run is a restart, which keeps its run's step: start the scene afresh from "
           "the last snapshot, with `type: snapshot`, to use another)";
    return;
  }
  std::vector<const WallSet::Entry*> moving;
  for (const WallSet::Entry& e : walls_.walls())
    if (e.pose.moving()) moving.push_back(&e);
  o << ". No time step prevents this: ";
  if (steps >= kResolvingSteps)
    o << "dt = " << dt_ << " s already resolves the contact (it lasts " << tc << " s at that speed, "
      << steps << " steps; " << kResolvingSteps << " resolve it)";
  else
    o << "a finer step changes how the contact is integrated, not where it stops (it lasts " << tc
      << " s at that speed, " << steps << " steps of dt = " << dt_ << " s; " << kResolvingSteps
      << " resolve it: once the contact is carried, grain check's contact-time line says which "
         "step does)";
  o << ". The contact is overloaded: the spring carries " << elastic_force(c, at_limit)
    << " N at the limit";
  if (w.speed > 1e-9) o << "; the approach brings " << 0.5 * c.m_star * w.speed * w.speed << " J";
  if (c.load > 0)
    o << "; the other forces on " << load_by << " (weight, fluid, neighbours, walls) press it with "
      << c.load << " N";
  if (c.cohesion > 0)
    o << "; cohesion (cohesion_energy_density " << c.cohesion << " J/m^3) pulls it in with "
      << cohesion_force(c, at_limit) << " N at the limit";
  const double r_large = std::max(a.r, b.r);
  if (!c.wall && r_large > 3 * c.r_small)
    o << "; a radius ratio of " << r_large / c.r_small << ": the smaller radius, " << c.r_small
      << " m, sets the limit of " << at_limit << " m";
  for (const WallSet::Entry* e : moving)
    o << "; wall '" << e->name << "' moves by its prescribed motion whatever resists it, so "
      << "particles it presses against others are squeezed by its travel";
  o << ". By its energy and load now, " << stop_text();
  // Driven by a heavier neighbour: the chain's stop when it is deeper, and the advice for
  // both (the larger stiffness, the smaller cohesion).
  const bool driven = chain && chain_stop > stop;
  if (driven) {
    o << "; but particle " << middle_id << " is pressed against " << backing << " by particle "
      << driver_id << " (" << driver_mass << " kg, " << significant(driver_mass / middle_mass, 3)
      << " times its mass";
    if (group_size > 1)
      o << "; with the " << group_size - 1 << " pressing on it, " << group_mass << " kg";
    o << "; approaching at " << chain->speed << " m/s, with a load of " << chain->load
      << " N), whose push grows with the stiffness: the two contacts in series, with particle "
      << middle_id << " between them, ";
    if (chain_stop < kNoStop)
      o << "stop it at " << significant(100 * chain_stop / c.r_small, 4) << " %";
    else
      o << "do not stop it before the overlap reaches the whole smaller radius";
  }
  o << ". What changes it:";
  const double target = 0.9 * at_limit;
  const double deepest = driven ? chain_stop : stop;
  if (deepest < kNoStop) {
    const double need = round_up(1.1 * deepest / c.r_small);
    if (need <= 1) {
      o << " set time.max_overlap to at least " << need;
      // With mesh walls a larger limit needs a smaller travel per step (check_mesh_tunnelling).
      const double travel = scene_.time.max_step_travel;
      if (mesh_walls_ && travel > 0 && travel + mesh_wall_travel_ >= 2 * (1 - need)) {
        const double fit = round_down_3(0.999 * (2 * (1 - need) - mesh_wall_travel_));
        if (fit > 0)
          o << " and, with mesh walls, time.max_step_travel to at most " << fit;
        else
          o << " (with mesh walls it needs time.max_step_travel below "
            << 2 * (1 - need) - mesh_wall_travel_ << ", which a moving mesh's own travel leaves "
            << "no room for: lower time.step first)";
      }
      o << " (knowingly: the overlap then "
        << "stands for that much deformation"
        << (moving.empty() ? ""
                           : "; with a moving wall "
                             "pressing, this only moves the stop later")
        << ");";
    } else
      o << " no time.max_overlap (at most 1) carries it;";
  } else {
    o << " no time.max_overlap (at most 1) carries it;";
  }
  if (moving.empty()) {
    const ContactLoad touch = at_first_touch(c);
    const std::optional<ContactLoad> chain_touch =
        driven ? std::optional<ContactLoad>(at_first_touch(*chain)) : std::nullopt;
    const double s = std::max(stiffness_factor_for(touch, target),
                              chain_touch ? stiffness_factor_for(*chain_touch, target) : 0.0);
    // A stiffer contact is shorter (Hertz t_c ~ Y^(-2/5), Hooke ~ k^(-1/2)): the step that
    // resolves it then, and that the start-up check accepts for the scene's expected impacts,
    // so that the advice runs as given.
    const auto shorter_step = [&](double duration_factor) {
      const double step =
          round_down_3(duration_factor *
                       std::min(tc / kResolvingSteps, report_.contact_time / kWarnStepsPerContact));
      if (dt_ > step)
        o << " (a stiffer contact is shorter: with it, time.step at most " << step << " s)";
    };
    if (s < kNoStop && s > 1) {
      if (c.hertz) {
        // A parcel class (glass[k=4]) takes the modulus of its listed material, the key to set.
        const auto listed = [&](int material) {
          const int real = scene_.materials[static_cast<std::size_t>(material)].real_material;
          return real < 0 ? material : real;
        };
        const auto scaled = [&](int material) {
          const Material& m = scene_.materials[static_cast<std::size_t>(material)];
          return "material '" + m.name + "': " + significant(round_up(s) * m.youngs_modulus, 6) +
                 " Pa";
        };
        const int la = listed(a.material), lb = listed(material_b), ld = listed(driver_material);
        o << " scale the Young's modulus by at least " << round_up(s) << " (" << scaled(la)
          << (lb != la ? ", " + scaled(lb) : "")
          << (driven && ld != la && ld != lb
                  ? ", and of particle " + std::to_string(driver_id) + ", " + scaled(ld)
                  : "")
          << ")";
        shorter_step(std::pow(round_up(s), -0.4));
        o << ";";
      } else if (const auto& v = scene_.contact.hooke_characteristic_velocity) {
        // k_n from the characteristic velocity grows as v^(2/5) for every pair alike
        // (normal_hooke.hpp), and keeps growing with the parcels' size, which a fixed
        // stiffness would not (refused with parcels).
        o << " raise contact.hooke.characteristic_velocity to at least "
          << round_up(*v * std::pow(round_up(s), 2.5)) << " m/s (k_n grows as its 2/5 power: "
          << "at least " << round_up(s) << " times stiffer)";
        shorter_step(std::pow(round_up(s), -0.5));
        o << ";";
      } else {
        o << " set contact.hooke.stiffness.normal to at least " << round_up(s) * c.kn << " N/m";
        shorter_step(std::pow(round_up(s), -0.5));
        o << ";";
      }
    }
    if (c.cohesion > 0) {
      double f = cohesion_factor_for(touch, target);
      if (chain_touch && f >= 0) {
        const double f_chain = cohesion_factor_for(*chain_touch, target);
        f = f_chain < 0 ? f_chain : std::min(f, f_chain);
      }
      if (f >= 0 && f < 1)
        o << " lower cohesion_energy_density to at most " << f * c.cohesion << " J/m^3;";
      else if (f < 0)
        o << " (without cohesion it is still overloaded);";
    }
    // The load and the impact where they are a tenth of what the spring holds at the limit.
    const double spring = elastic_force(c, at_limit);
    if (c.load > 0.1 * spring) o << " a smaller load on the contact;";
    if (0.5 * c.m_star * w.speed * w.speed > 0.1 * 0.4 * spring * at_limit)
      o << " a slower impact;";
    if (driven) o << " a lighter or slower particle " << driver_id << ";";
    // A parcel weighs k^3 real particles: a lower coarse_grain lightens it by that much.
    double k_max = 1;
    for (int m : {a.material, material_b, driven ? driver_material : a.material})
      k_max = std::max(k_max, scene_.materials[static_cast<std::size_t>(m)].coarse_grain);
    if (k_max > 1)
      o << " a lower coarse_grain (parcels of k = " << significant(k_max) << " take part, each "
        << significant(k_max * k_max * k_max) << " real particles' mass);";
  }
  for (const WallSet::Entry* e : moving)
    o << " stop or slow wall '" << e->name << "' before it squeezes the particles this far;";
  // A restart keeps its run's model (materials, contact, walls): those changes need a new run.
  if (restored_)
    o << " (this run is a restart, which keeps its run's model and insertions: a changed "
         "material, contact or wall needs the changed scene started afresh, from the last "
         "snapshot with `type: snapshot`; time.max_overlap may change at a restart)";
  o << " (docs/stability.md, the overlap guard)";
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
  refresh_spin_drag();
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
    bool spin = false;
    for (const auto& term : terms_) spin |= term->implicit_spin();
    if (spin) {
      drag_.spin_coefficient.assign(p_.size(), 0.0);
      drag_.fluid_spin.assign(p_.size(), Vec3::Zero());
    }
    for (auto& term : terms_) term->add(p_, time_, drag_);
  }
}

namespace {
// One half kick of velocity Verlet over n particles: v += h/m F (implicit in v where drag
// is set), and w += h/I T when the law has torques (implicit in w with a spin drag). Written
// on the arrays' addresses, one loop per case, so that the loops hold no branch and no
// reload of an address. With Guard, returns whether every x, v and w is finite after it:
// x - x is 0 for a finite x and NaN for an infinite or NaN one, and NaN stays in a sum.
template <bool Guard, bool Drag, SpinKick Spin>
bool kick(std::size_t n, double h, const Vec3* x, Vec3* v, Vec3* w, const Vec3* force,
          const Vec3* torque, const double* mass, const double* inertia, const double* drag_k,
          const Vec3* fluid_u, const double* spin_k, const Vec3* fluid_w) {
  double nan_if_any = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = h / mass[i];
    const Triple vi = Drag ? implicit_kick(load(v[i]), a, force[i], drag_k[i], fluid_u[i])
                           : add_scaled(load(v[i]), a, force[i]);
    store(vi, v[i]);
    Triple wi = load(w[i]);
    if constexpr (Spin != kNoSpin) {
      const double b = h / inertia[i];
      wi = Spin == kImplicitSpin ? implicit_kick(wi, b, torque[i], spin_k[i], fluid_w[i])
                                 : add_scaled(wi, b, torque[i]);
      store(wi, w[i]);
    }
    if constexpr (Guard) {
      const Triple xi = load(x[i]);
      nan_if_any += ((xi.x - xi.x) + (vi.x - vi.x) + (wi.x - wi.x)) +
                    ((xi.y - xi.y) + (vi.y - vi.y) + (wi.y - wi.y)) +
                    ((xi.z - xi.z) + (vi.z - vi.z) + (wi.z - wi.z));
    }
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
  const double* kr = drag_.spin_coefficient.data();
  const Vec3* uw = drag_.fluid_spin.data();
  Particles& p = p_;
  const auto run = [&]<bool Drag, SpinKick Spin>() {
    return kick<Guard, Drag, Spin>(n, h, p.x.data(), p.v.data(), p.omega.data(), p.force.data(),
                                   p.torque.data(), p.mass.data(), p.inertia.data(), k, u, kr, uw);
  };
  const bool drag = !drag_.coefficient.empty();
  const SpinKick spin = spin_kick(drag_, sweep_.needs_spin);
  if (drag) {
    if (spin == kImplicitSpin) return run.template operator()<true, kImplicitSpin>();
    return spin == kSpin ? run.template operator()<true, kSpin>()
                         : run.template operator()<true, kNoSpin>();
  }
  return spin == kSpin ? run.template operator()<false, kSpin>()
                       : run.template operator()<false, kNoSpin>();
}

void Simulation::step() {
  if (!initialised_) initialise();
  // Velocity Verlet: half kick, drift, new forces, half kick.
  kick_and_drift();
  // Stream insertion (dem/insert/stream_insertion.hpp); new particles force a rebuild.
  const bool inserted =
      !streams_.empty() && streams_.insert(time_ + dt_, p_, walls_, *decomp_, next_id_, comm_) > 0;
  if (sweep_.has_history)  // inserted particles: a spring in the columns of every particle
    for (std::size_t col = 0; col < wall_history_.size(); ++col)
      if (wall_neighbours_.list_of_column(col).all) wall_history_[col].resize(p_.size());
  if (inserted) mark_leaving();  // the new particles too
  if (inserted || needs_rebuild()) {
    rebuild();
    fresh_from_kick_ = false;  // particles came, left or arrived from other ranks
  } else {
    exchange_->forward_begin(p_, ghosts_);  // ended by compute_forces (finish_forward)
    forward_pending_ = true;
  }
  time_ += dt_;
  walls_.move_to(time_);
  const ContactGuards guards = compute_forces();
  bool temperatures_ok = true;
  if (heat_) {
    advance_temperatures();
    temperatures_ok = temperatures_positive(p_);  // the guard's, with the step's one reduction
  }
  state_finite_ = half_kick<true>() && temperatures_ok;
  finite_everywhere_ = check_contacts(guards, state_finite_);
  ++counters_.steps;
}

Simulation::WallLoads Simulation::take_wall_loads(bool reset) {
  WallLoads out;
  if (wall_impulse_.empty()) return out;
  const std::size_t n = wall_impulse_.size();
  std::vector<double> sum(3 * n);
  for (std::size_t w = 0; w < n; ++w)
    for (int a = 0; a < 3; ++a) sum[3 * w + a] = wall_impulse_[w][a];
  MPI_Allreduce(MPI_IN_PLACE, sum.data(), static_cast<int>(sum.size()), MPI_DOUBLE, MPI_SUM, comm_);
  out.interval = wall_load_time_;
  out.force.assign(n, Vec3::Zero());
  if (wall_load_time_ > 0)  // the load: the reaction to the walls' forces on the particles
    for (std::size_t w = 0; w < n; ++w)
      out.force[w] = -Vec3(sum[3 * w], sum[3 * w + 1], sum[3 * w + 2]) / wall_load_time_;
  if (!reset) return out;
  std::fill(wall_impulse_.begin(), wall_impulse_.end(), Vec3::Zero());
  wall_load_time_ = 0;
  return out;
}

void Simulation::advance_to(double t_end) {
  if (!initialised_) initialise();
  while (time_ < t_end - 0.5 * dt_) step();
}

void Simulation::add_force_term(std::unique_ptr<ForceTerm> term) {
  if (heat_ && term->void_fraction_grid()) heat_->use_void_fraction(term->void_fraction_grid());
  terms_.push_back(std::move(term));
}

void Simulation::advance_temperatures() {
  exchange_->forward_values(p_.temperature, 1, ghost_temperature_);
  heat_->step(p_, ghosts_, ghost_temperature_, local_list_, ghost_list_, walls_, wall_neighbours_,
              dt_, scene_.parallel.reproducible ? &canonical_ : nullptr);
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

SnapshotExtras Simulation::snapshot_extras(SnapshotFieldSet fields) const {
  SnapshotExtras e;
  const std::size_t n = p_.size();
  const auto wants = [&](const char* name) { return (fields & snapshot_field_bit(name)) != 0; };
  const bool drag = !drag_.coefficient.empty();
  const bool spin_drag = !drag_.spin_coefficient.empty();
  // The implicit drag at the present velocity: the half kick that ended the step solved
  // v' = v + h/m (F + K (u - v')), so K (u - v') is the drag it applied, and the next one
  // starts from it.
  const auto drag_on = [&](std::size_t i) {
    return drag ? Vec3(drag_.coefficient[i] * (drag_.fluid_velocity[i] - p_.v[i])) : Vec3::Zero();
  };
  if (wants("force")) {
    e.force.resize(n);
    for (std::size_t i = 0; i < n; ++i) e.force[i] = p_.force[i] + drag_on(i);
  }
  if (wants("torque")) {
    e.torque.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      e.torque[i] =
          spin_drag
              ? Vec3(p_.torque[i] + drag_.spin_coefficient[i] * (drag_.fluid_spin[i] - p_.omega[i]))
              : p_.torque[i];
  }
  if (wants("fluid_force")) {
    if (!terms_.empty() && fluid_explicit_.size() != n)
      throw std::logic_error(
          "Simulation::snapshot_extras: fluid_force asked without record_fluid_force() on for "
          "the step's force evaluation");
    e.fluid_force.assign(n, Vec3::Zero());
    for (std::size_t i = 0; i < n; ++i)
      e.fluid_force[i] = (terms_.empty() ? Vec3::Zero() : fluid_explicit_[i]) + drag_on(i);
  }
  if (wants("coordination") || wants("overlap_max")) {
    std::vector<int> count;
    std::vector<double> overlap;
    tally_contacts(p_, ghosts_, local_list_, ghost_list_, walls_, wall_neighbours_, count, overlap);
    if (wants("coordination")) e.coordination = std::move(count);
    if (wants("overlap_max")) e.overlap_max = std::move(overlap);
  }
  return e;
}

const ContactNetwork& Simulation::contact_network() const {
  if (!network_recorded_)
    throw std::logic_error(
        "Simulation::contact_network: the last force evaluation did not record the contacts "
        "(record_contacts() off, or the forces were restored from a checkpoint)");
  return network_;
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
