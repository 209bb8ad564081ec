#pragma once
// One pass over all contacts (local pairs, local-ghost pairs, then particle-wall),
// adding forces and torques to local particles. The contact law is chosen once per
// run: select_sweep() returns the instantiation for the scene's slot choice, so the
// per-contact code holds no branch on model names and no virtual call.
//
// Every pair is evaluated in canonical orientation (the particle with the lower
// global id as "i"), with the displacement (x_a - x_b) + (shift_a - shift_b). A pair
// whose partners live on two ranks is evaluated on both, from bit-identical inputs,
// so both ranks apply exactly opposite forces (Newton's third law holds exactly
// across rank boundaries, at the price of computing those pairs twice).
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "dem/contact/contact_geometry.hpp"
#include "dem/contact/pair_coefficients.hpp"
#include "dem/core/particles.hpp"
#include "dem/engine/canonical_order.hpp"
#include "dem/io/contact_network.hpp"
#include "dem/neighbour/verlet_list.hpp"
#include "dem/neighbour/wall_neighbours.hpp"
#include "dem/parallel/ghosts.hpp"
#include "dem/scene/scene.hpp"
#include "dem/walls/wall_set.hpp"

namespace grainflow {

// The contact with the largest overlap ratio of a sweep, for the overlap guard.
struct WorstContact {
  GlobalId a = -1, b = -1;  // particle ids; b = -1 for a wall
  double speed = 0;         // normal approach speed [m/s]
  double r_star = 0, m_star = 0, y_star = 0;
  // Records the contact if it beats the current maximum of `ratio`.
  void consider(double overlap_ratio, double& ratio, GlobalId ia, GlobalId ib, double vn, double rs,
                double ms, double ys) {
    if (overlap_ratio <= ratio) return;
    ratio = overlap_ratio;
    a = ia;
    b = ib;
    speed = vn;
    r_star = rs;
    m_star = ms;
    y_star = ys;
  }
};

// The under-resolved Hertz contact with the fewest steps per contact, for the
// steps-per-contact guard. A Hertz impact at approach speed v lasts
//   t_c(v) = 2.868 (m*^2 / (R* Y*^2 v))^{1/5}       (elastic; damping lengthens it)
// and t_c(v)/dt < N_min  <=>  m*^2 < k R* Y*^2 v  with  k = (N_min dt / 2.868)^5.
// That test is a few multiplications per contact; the details (one pow) are worked out
// only for a contact that fails it.
struct UnresolvedContact {
  double k = 0;       // (N_min dt / 2.868)^5; 0 turns the test off
  double fewest = 0;  // t_c(v)/dt of the recorded contact (0: none recorded)
  double overlap_ratio = 0;
  WorstContact contact;  // ids, approach speed and pair properties
  void set(double n_min, double dt) { k = std::pow(n_min * dt / 2.868, 5); }
  // One touching contact: vn its normal approach speed (> 0 approaching; a separating
  // contact never fails), rs, ms, ys its R*, m*, Y*.
  void consider(double vn, double rs, double ms, double ys, double overlap_ratio_now, GlobalId ia,
                GlobalId ib, double dt) {
    if (ms * ms < k * rs * ys * ys * vn) [[unlikely]]
      record(vn, rs, ms, ys, overlap_ratio_now, ia, ib, dt);
  }
  // Keeps a failing contact if it has the fewest steps so far (rare; out of line).
  void record(double vn, double rs, double ms, double ys, double overlap_ratio_now, GlobalId ia,
              GlobalId ib, double dt);
};

// Whether every local and ghost particle has the same radius, mass and material (a
// monodisperse bed of one material; found at each neighbour rebuild). The pair kernel then
// takes R* and m* of every pair from here: they are computed once with the same operands and
// operations as per pair (r r / (r + r), m m / (m + m)), so they are the same to the last bit.
struct UniformPairs {
  bool all_alike = false;
  double radius = 0, mass = 0, r_star = 0, m_star = 0;
  int material = 0;
};
UniformPairs find_uniform_pairs(const Particles& p, const Ghosts& g);

struct ContactSweep {
  Particles& p;
  const Ghosts& ghosts;
  const NeighbourList& local_list;
  const NeighbourList& ghost_list;
  ListSprings& local_springs;  // parallel to local_list.j
  ListSprings& ghost_springs;  // parallel to ghost_list.j
  const WallSet& walls;        // current wall positions (dem/walls/wall_set.hpp)
  // [WallSet column][entry of the wall's neighbour list, or particle] (wall_neighbours.hpp)
  std::vector<std::vector<ContactHistory>>& wall_history;
  const WallNeighbours& wall_neighbours;                   // the particles each wall may touch
  const PairTable& table;
  const ContactConstants& constants;
  double dt;
  // The time over which the springs advance: dt, or 0 in the evaluation of the initial state
  // (Simulation::initialise), where the contacts present have not moved yet.
  double spring_dt;
  const UniformPairs& uniform;
  // results of the sweep
  long contacts = 0;             // each contact once over all ranks
  double max_overlap_ratio = 0;  // overlap / smaller radius
  WorstContact worst;            // the contact with that overlap
  UnresolvedContact unresolved;  // filled by steps_per_contact_sweep
  // parallel.reproducible: the order of the pairs (set at each neighbour rebuild), for a
  // sweep of select_sweep(..., true); unused otherwise.
  CanonicalOrder* canonical = nullptr;
  // Called before the sweep first reads a ghost (empty: the ghosts are ready). The simulation
  // completes there the exchange of the ghosts' positions and velocities, which travel while
  // the pairs of this rank's own particles are swept.
  std::function<void()> ghosts_ready = {};
  // output.wall_loads: one sum per wall (WallSet order) of the contact forces the walls
  // exert on this rank's particles in this sweep; null: not kept. `load` is the current
  // wall's entry while the wall sweep runs.
  std::vector<Vec3>* wall_forces = nullptr;
  Vec3* load = nullptr;
};

using SweepFunction = void (*)(ContactSweep&);
// The contact network (scene key output.contacts) of the state the sweep is about to
// evaluate: every touching contact the force sweep finds, with the force it will apply,
// from the same inputs and law, but with copies of the springs, so nothing changes. Run
// before the sweep, it gives the forces the sweep adds to the particles (to round-off).
// Each contact is reported once over all ranks: a pair by the rank that owns its lower id
// (a local-ghost pair whose ghost has the lower id is the other rank's), a wall contact by
// the particle's rank. Replaces `out`'s contents.
using ReportFunction = void (*)(const ContactSweep&, ContactNetwork&);

struct SweepChoice {
  SweepFunction run;
  ReportFunction report;  // for the same law
  bool has_history;       // pair/wall histories must be kept
  bool keeps_tangential;  // of which tangential springs
  bool keeps_rolling;     // and rolling springs (EPSD)
  bool needs_spin;        // torques are produced
  std::string name;       // e.g. "hertz + history + none + none"
};

// `canonical`: the sweep for parallel.reproducible, which adds each particle's pair
// contributions in canonical order (ContactSweep::canonical, canonical_order.hpp).
SweepChoice select_sweep(const ContactSettings& settings, bool canonical = false);

// The steps-per-contact test (UnresolvedContact) over every touching contact of the
// sweep's lists and walls, as the force sweep finds them, into s.unresolved. A pass of its
// own, so that the force loop holds no trace of it: the engine runs it (Hertz only) in
// the steps where some contact could fail (Simulation::contact_may_be_unresolved).
void steps_per_contact_sweep(ContactSweep& s);

// Each local particle's touching contacts (overlap > 0, the force sweep's test) with
// particles (local and ghost) and walls, as `count`, and the largest overlap / smaller radius
// among them as `overlap_max` (0 without contacts), at the present positions. A pass of its
// own over the same lists and walls as the force sweep, for snapshots that ask for it.
void tally_contacts(const Particles& p, const Ghosts& ghosts, const NeighbourList& local_list,
                    const NeighbourList& ghost_list, const WallSet& walls,
                    const WallNeighbours& wall_neighbours, std::vector<int>& count,
                    std::vector<double>& overlap_max);

}  // namespace grainflow
