#pragma once
// Particle exchange between neighbouring ranks of the processor grid (DESIGN.md §2):
// - migrate(): at neighbour rebuilds, every particle moves to the rank whose box
//   holds it, carrying its contact springs and wall springs (CarriedSprings: the records
//   that name it);
// - borders(): at rebuilds, builds the ghosts of every face, edge and corner (axis
//   by axis: the y exchange forwards ghosts received along x, and so on) and
//   records which particles go where;
// - forward_begin() / forward_end(): every step, refresh the ghosts' positions and
//   velocities along those records.
// Periodic axes work the same way with one or more ranks: the neighbour across a
// periodic side may be this rank itself, and what crosses gets an image shift.
#include <string>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/neighbour/carried_springs.hpp"
#include "dem/parallel/decomposition.hpp"
#include "dem/parallel/ghosts.hpp"

namespace grainflow {

// A run-time failure every rank agrees on (thrown on all ranks together).
class ParallelError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// If any rank passes a non-empty message, every rank throws ParallelError with
// the message of the lowest such rank. Collective.
void agree_on_error(MPI_Comm comm, const std::string& local_message);

class Exchange {
 public:
  // predicted: the particles carry the dashpots' predicted velocities (Particles::v_pred,
  // omega_pred; contact.dashpot_velocity: predicted), which then travel with every migrating
  // particle and ghost. Without it they stay behind: ghosts have none, and a particle that
  // arrives gets its v and omega in their place.
  explicit Exchange(const Decomposition& d, bool predicted = false)
      : d_(d), predicted_(predicted) {}

  // Wraps positions along periodic axes into the domain and sends every particle
  // to its owner. A particle that crossed more than one box since the last call is
  // an error naming it, its speed and the fix (collective ParallelError).
  void migrate(Particles& p, CarriedState& carried);

  // Rebuilds `ghosts` for interaction range `cutoff` and records the send lists.
  void borders(const Particles& p, double cutoff, Ghosts& ghosts);

  // Refresh the ghosts' positions, velocities and spins (and the predicted ones) along the
  // recorded lists, in two halves, so that work on this rank's own particles runs while the
  // fields travel: forward_begin packs and sends the fields of the first axis that has
  // neighbours and posts their receives; forward_end waits for those, unpacks them, and
  // exchanges the further axes whole (they forward ghosts of the first). Between the two
  // the ghosts' fields are stale and `p`'s listed fields must not change. The sends
  // complete later (at the next exchange that reuses their buffers): a rank that has its
  // ghosts goes on without waiting for its neighbours to take theirs.
  void forward_begin(const Particles& p, const Ghosts& ghosts);
  void forward_end(const Particles& p, Ghosts& ghosts);

  ~Exchange();
  Exchange(const Exchange&) = delete;
  Exchange& operator=(const Exchange&) = delete;

  // Sends `width` doubles per particle along the same lists as forward_begin(): `local` holds
  // width values for each of this rank's particles (in local order), and `ghost` is
  // resized and filled with the values of each ghost (in ghost order). Collective. Used
  // by the coupling to give ghosts their owner's drag coefficient and exchange force.
  void forward_values(const std::vector<double>& local, std::size_t width,
                      std::vector<double>& ghost) const;
  // The reverse of forward_values: every ghost's `width` values (`ghost`, as sized by
  // forward_values) are sent back along the same lists and added to the values of the
  // particle they copy (`local`; ghosts of ghosts pass through). Collective. Used by
  // the coupling to collect what a particle's footprint sees in neighbours' cells.
  void reverse_values(std::vector<double>& local, std::size_t width,
                      std::vector<double>& ghost) const;

  long ghosts_sent_last_borders() const { return sent_; }

 private:
  struct Swap {
    int axis, dir;
    std::vector<int> send;  // < nlocal: local index; else ghost index + nlocal
    Vec3 shift;             // added to the image offset of what is sent
    std::size_t recv_first = 0, recv_count = 0;
  };
  // The forward exchange of the swaps first, first + 1 (one axis): packs and posts
  // (post_stage), then waits for the receives and unpacks (finish_stage).
  template <bool Predicted>
  void post_stage(std::size_t first, const Particles& p, const Ghosts& g);
  template <bool Predicted>
  void finish_stage(std::size_t first, Ghosts& g);
  bool stage_talks(std::size_t first) const;
  // Waits for the forward sends still in flight (before their buffers change).
  void complete_sends();

  const Decomposition& d_;
  bool predicted_;
  std::vector<Swap> swaps_;                   // per axis the swaps of dir 0 and 1, axis after axis
  std::vector<std::vector<double>>
      buffers_;  // forward_begin(): per swap, what it receives and sends
  std::vector<MPI_Request> sends_;            // forward sends not known to be complete
  std::vector<MPI_Request> receives_;         // the receives of the stage posted last
  std::size_t begun_ = 0;                     // forward_begin's stage (swaps_.size(): none)
  std::size_t nlocal_ = 0;
  long sent_ = 0;
};

}  // namespace grainflow
