#pragma once
// Stream insertion: particles enter through a planar face (rectangle or disc) at a
// prescribed mass or number rate during [start, stop), with the entry's size
// distribution, never overlapping existing particles or walls.
//
// The radii are drawn in sequence from their own random stream, so the delivered
// size distribution is the requested one: a particle that finds no free spot keeps
// its radius and is placed at a later step (the delivery then lags, and the lag is
// reported by lag()). The count due by time t is the largest n with
// m_1 + ... + m_{n-1} + m_n/2 <= rate (t - start) (mass rate) or n <= rate (t - start)
// + 1/2 (number rate), so the delivered amount stays within half a particle of the
// target.
//
// With several MPI ranks, every rank draws the same candidates; each checks them
// against its own particles and ghosts, one reduction combines the verdicts, and
// the rank owning a candidate's position adds it: the result does not depend on the
// rank count.
#include <mpi.h>

#include <random>
#include <string>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/parallel/decomposition.hpp"
#include "dem/parallel/ghosts.hpp"
#include "dem/scene/scene.hpp"
#include "dem/walls/wall_set.hpp"

namespace grainflow {

class StreamInsertion {
 public:
  StreamInsertion() = default;
  explicit StreamInsertion(const Scene& scene);

  bool empty() const { return streams_.empty(); }

  // InsertionError when the walls that do not move leave no room anywhere on a stream's face
  // for its largest particle: that particle would wait for room for ever, and the stream,
  // which places its particles in order, would deliver nothing more (the run ended "done"
  // with the stream's particles "behind"). Tried over a grid of positions across the face.
  void check_faces(const Scene& scene, const WallSet& walls) const;
  double max_radius() const { return r_max_; }

  // Inserts what is due by time t; returns how many particles were inserted over
  // all ranks (the same number on every rank). Collective when comm has > 1 rank.
  long insert(double t, Particles& p, const WallSet& walls, const Decomposition& decomp,
              GlobalId& next_id, MPI_Comm comm);

  // Totals of stream k over all ranks (the same on every rank).
  double mass_inserted(std::size_t k) const { return streams_[k].mass; }
  long count_inserted(std::size_t k) const { return streams_[k].count; }
  // How far stream k is behind its target at the last insert(), in particles: exact for a
  // count rate; for a mass rate, a lower bound when lag_is_lower_bound(k) (the radii of a
  // backlog are drawn only as far as one step's most, kMaxPerStep).
  long lag(std::size_t k) const { return streams_[k].lag; }
  bool lag_is_lower_bound(std::size_t k) const { return streams_[k].lag_lower_bound; }
  // For a mass rate: the mass [kg] stream k is behind its target (0 for a count rate).
  double lag_mass(std::size_t k) const { return streams_[k].lag_mass; }
  std::size_t size() const { return streams_.size(); }
  const std::string& source(std::size_t k) const { return streams_[k].entry.source; }
  // Stream k's coarse-graining factor (1: real particles; k: parcels of k^3 real ones).
  double coarse_grain(std::size_t k) const { return streams_[k].entry.coarse_grain; }

  // The streams' progress (delivered totals, radii drawn but not placed, generator
  // states) as text, for checkpoints: a run restored with restore_state() inserts
  // exactly what the uninterrupted run would have. The scene must be the same.
  std::string save_state() const;
  void restore_state(const std::string& state);  // std::invalid_argument if malformed

 private:
  struct Stream {
    Insertion entry;
    double density;
    Vec3 v_dir;  // rectangle: normal x u
    std::mt19937_64 radius_rng, place_rng;
    std::vector<double> pending;  // radii drawn and not yet placed, in order
    double mass = 0;
    long count = 0;
    long lag = 0;
    double lag_mass = 0;
    bool lag_lower_bound = false;
    // The most particles the face can hold at once: their discs on the face lie inside it
    // and do not overlap, so at most its area over the smallest disc's. A blocked stream's
    // backlog is tried only up to it per step (its cost had grown with the backlog).
    long capacity = 1;
  };
  static Vec3 sample(Stream& s, double r);
  // A face that reaches across a periodic side: candidates are wrapped into the domain and
  // compared by their nearest periodic images.
  Vec3 wrap(Vec3 x) const;
  Vec3 nearest_offset(const Vec3& a, const Vec3& b) const;  // a - b's nearest periodic image
  Domain domain_;
  static double pending_radius(Stream& s, std::size_t k);
  static long due(Stream& s, double t);

  std::vector<Stream> streams_;
  double r_max_ = 0;
};

}  // namespace grainflow
