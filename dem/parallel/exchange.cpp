#include "dem/parallel/exchange.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <sstream>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace grainflow {
namespace {

// Buffers are doubles; integers travel bit-exactly through std::bit_cast.
struct Writer {
  std::vector<double>& b;
  void put(double v) { b.push_back(v); }
  void put_id(GlobalId id) { b.push_back(std::bit_cast<double>(id)); }
  void put(const Vec3& v) { b.insert(b.end(), {v[0], v[1], v[2]}); }
  void put(const ContactHistory& h) {
    put(h.tangential);
    put(h.rolling);
  }
};
struct Reader {
  const std::vector<double>& b;
  std::size_t k = 0;
  double get() { return b[k++]; }
  GlobalId get_id() { return std::bit_cast<GlobalId>(b[k++]); }
  Vec3 get_vec() {
    const Vec3 v(b[k], b[k + 1], b[k + 2]);
    k += 3;
    return v;
  }
  ContactHistory get_history() {
    ContactHistory h;
    h.tangential = get_vec();
    h.rolling = get_vec();
    return h;
  }
};

// Sends `out` to rank `to` and receives from rank `from` (either may be MPI_PROC_NULL).
std::vector<double> sendrecv(MPI_Comm comm, const std::vector<double>& out, int to, int from,
                             int tag) {
  long n_out = static_cast<long>(out.size()), n_in = 0;
  MPI_Sendrecv(&n_out, 1, MPI_LONG, to, tag, &n_in, 1, MPI_LONG, from, tag, comm,
               MPI_STATUS_IGNORE);
  std::vector<double> in(static_cast<std::size_t>(n_in));
  MPI_Sendrecv(out.data(), static_cast<int>(n_out), MPI_DOUBLE, to, tag + 1, in.data(),
               static_cast<int>(n_in), MPI_DOUBLE, from, tag + 1, comm, MPI_STATUS_IGNORE);
  return in;
}

}  // namespace

void agree_on_error(MPI_Comm comm, const std::string& local_message) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int mine = local_message.empty() ? size : rank, first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return;
  int length = rank == first ? static_cast<int>(local_message.size()) : 0;
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  std::string text = rank == first ? local_message : std::string(length, ' ');
  MPI_Bcast(text.data(), length, MPI_CHAR, first, comm);
  throw ParallelError(text);
}

void Exchange::migrate(Particles& p, CarriedState& carried) {
  const Domain& dom = d_.domain();
  const Vec3 length = d_.length();
  // With one rank along a periodic axis, wrapping is all there is to do. With several,
  // the direction is chosen from the unwrapped position (a particle past the upper
  // periodic side goes to the +x neighbour, across the side) and the period is
  // subtracted as it crosses.
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (dom.periodic[a] && d_.dims()[a] == 1) {
        if (p.x[i][a] < dom.lo[a]) p.x[i][a] += length[a];
        else if (p.x[i][a] >= dom.hi[a]) p.x[i][a] -= length[a];
      }

  std::string error;
  CarriedSprings& springs = carried.springs;
  const bool tangential = springs.keeps_tangential(), rolling = springs.keeps_rolling();
  for (int a = 0; a < 3; ++a) {
    if (d_.dims()[a] == 1) continue;  // after wrapping, this rank spans the whole axis
    for (int dir = 0; dir < 2; ++dir) {
      const int to = d_.neighbour(a, dir), from = d_.neighbour(a, 1 - dir);
      Vec3 shift = Vec3::Zero();  // across the periodic side: back into the domain
      if (dom.periodic[a] && dir == 0 && d_.coords()[a] == 0) shift[a] = length[a];
      if (dom.periodic[a] && dir == 1 && d_.coords()[a] == d_.dims()[a] - 1) shift[a] = -length[a];
      // The message: the particles, then the pair springs naming one of them, then their
      // wall springs, each part preceded by its count.
      std::vector<double> out;
      Writer w{out};
      std::vector<char> leaving(p.size(), 0);
      std::vector<GlobalId> gone;  // ids of the leaving particles, sorted below
      out.push_back(0);
      for (std::size_t i = 0; i < p.size(); ++i) {
        const bool outside = dir == 0 ? p.x[i][a] < d_.lo()[a] : p.x[i][a] >= d_.hi()[a];
        // The last box along a bounded axis keeps x == hi; beyond it particles were removed.
        if (!outside || to == MPI_PROC_NULL) continue;
        leaving[i] = 1;
        gone.push_back(p.id[i]);
        w.put_id(p.id[i]);
        w.put(Vec3(p.x[i] + shift));
        w.put(p.v[i]);
        w.put(p.omega[i]);
        if (predicted_) {  // migration comes between the prediction and the forces
          w.put(p.v_pred[i]);
          w.put(p.omega_pred[i]);
        }
        w.put(p.force[i]);  // the next half kick uses them (e.g. right after a checkpoint)
        w.put(p.torque[i]);
        w.put(p.radius[i]);
        w.put(p.mass[i]);
        w.put(p.inertia[i]);
        w.put(static_cast<double>(p.material[i]));
        w.put(p.temperature[i]);
        if (carried.carries_drag)
          for (double x : carried.drag[i]) w.put(x);
      }
      out[0] = static_cast<double>(gone.size());
      std::sort(gone.begin(), gone.end());
      const auto is_gone = [&gone](GlobalId id) {
        return std::binary_search(gone.begin(), gone.end(), id);
      };
      // A pair spring goes along with either partner; this rank keeps it unless both left
      // (the other partner may stay here, or be a ghost here: then it is simply not used).
      {
        const std::size_t count_at = out.size();
        out.push_back(0);
        std::vector<char> drop(gone.empty() ? 0 : springs.pairs(), 0);
        long sent = 0;
        for (std::size_t r = 0; r < springs.pairs() && !gone.empty(); ++r) {
          const CarriedSprings::PairKey& key = springs.pair_key(r);
          const bool lo_gone = is_gone(key.lo), hi_gone = is_gone(key.hi);
          if (!lo_gone && !hi_gone) continue;
          drop[r] = lo_gone && hi_gone;
          const ContactHistory h = springs.pair(r);
          w.put_id(key.lo);
          w.put_id(key.hi);
          if (tangential) w.put(h.tangential);
          if (rolling) w.put(h.rolling);
          ++sent;
        }
        out[count_at] = static_cast<double>(sent);
        if (!gone.empty()) springs.drop_pairs(drop);
      }
      {
        const std::size_t count_at = out.size();
        out.push_back(0);
        std::vector<char> drop(gone.empty() ? 0 : springs.walls(), 0);
        long sent = 0;
        for (std::size_t r = 0; r < springs.walls() && !gone.empty(); ++r) {
          const CarriedSprings::WallKey& key = springs.wall_key(r);
          if (!is_gone(key.particle)) continue;
          drop[r] = 1;
          w.put_id(key.particle);
          w.put(static_cast<double>(key.column));
          w.put(springs.wall(r));
          ++sent;
        }
        out[count_at] = static_cast<double>(sent);
        if (!gone.empty()) springs.drop_walls(drop);
      }
      p.remove_if(leaving);
      if (carried.carries_drag) {
        std::size_t keep = 0;
        for (std::size_t r = 0; r < carried.drag.size(); ++r)
          if (!leaving[r]) carried.drag[keep++] = carried.drag[r];
        carried.drag.resize(keep);
      }
      const std::vector<double> in = sendrecv(d_.comm(), out, to, from, 100 + 2 * a + dir);
      if (in.empty()) continue;  // from MPI_PROC_NULL
      Reader r{in};
      for (auto n = static_cast<std::size_t>(r.get()); n > 0; --n) {
        const GlobalId id = r.get_id();
        const Vec3 x = r.get_vec(), v = r.get_vec(), w_spin = r.get_vec();
        const Vec3 v_pred = predicted_ ? r.get_vec() : v, w_pred = predicted_ ? r.get_vec() : w_spin;
        const Vec3 force = r.get_vec(), torque = r.get_vec();
        const double radius = r.get(), mass = r.get(), inertia = r.get();
        const int mat = static_cast<int>(r.get());
        const double temperature = r.get();
        p.add_raw(id, x, v, w_spin, radius, mass, inertia, mat);
        p.temperature.back() = temperature;
        p.v_pred.back() = v_pred;
        p.omega_pred.back() = w_pred;
        p.force.back() = force;
        p.torque.back() = torque;
        if (carried.carries_drag) carried.drag.push_back({r.get(), r.get(), r.get(), r.get()});
      }
      for (auto n = static_cast<std::size_t>(r.get()); n > 0; --n) {
        const GlobalId lo = r.get_id(), hi = r.get_id();
        const Vec3 t = tangential ? r.get_vec() : Vec3::Zero();
        const Vec3 roll = rolling ? r.get_vec() : Vec3::Zero();
        springs.add_pair(lo, hi, t, roll);
      }
      for (auto n = static_cast<std::size_t>(r.get()); n > 0; --n) {
        const GlobalId id = r.get_id();
        const int column = static_cast<int>(r.get());
        springs.add_wall(id, column, r.get_history());
      }
    }
    // Everything this rank now holds must lie in its slab along this axis.
    for (std::size_t i = 0; i < p.size() && error.empty(); ++i)
      if (d_.coordinate_of(a, p.x[i][a]) != d_.coords()[a]) {
        std::ostringstream msg;
        msg << "error: particle " << p.id[i] << " at (" << p.x[i][0] << ", " << p.x[i][1] << ", "
            << p.x[i][2] << ") m, moving at " << p.v[i].norm() << " m/s, crossed more than one "
            << "subdomain along " << "xyz"[a] << " between two neighbour-list rebuilds (this "
            << "rank's box is " << d_.hi()[a] - d_.lo()[a] << " m wide); reduce the time step, "
            << "or use fewer ranks along " << "xyz"[a] << " (rank " << d_.rank() << ")";
        error = msg.str();
      }
  }
  agree_on_error(d_.comm(), error);
}

void Exchange::borders(const Particles& p, double cutoff, Ghosts& g) {
  complete_sends();  // their buffers and lists are about to change
  g.clear();
  swaps_.clear();
  nlocal_ = p.size();
  sent_ = 0;
  const Vec3 length = d_.length();
  for (int a = 0; a < 3; ++a) {
    const std::size_t ghosts_before = g.size();  // ghosts from earlier axes are forwarded
    for (int dir = 0; dir < 2; ++dir) {
      Swap s;
      s.axis = a;
      s.dir = dir;
      s.shift = Vec3::Zero();
      const int to = d_.neighbour(a, dir), from = d_.neighbour(a, 1 - dir);
      // What crosses a periodic side appears one period away on the receiver.
      if (d_.domain().periodic[a]) {
        if (dir == 0 && d_.coords()[a] == 0) s.shift[a] = length[a];
        if (dir == 1 && d_.coords()[a] == d_.dims()[a] - 1) s.shift[a] = -length[a];
      }
      auto near = [&](double x) {
        return dir == 0 ? x < d_.lo()[a] + cutoff : x >= d_.hi()[a] - cutoff;
      };
      std::vector<double> out;
      Writer w{out};
      if (to != MPI_PROC_NULL) {
        for (std::size_t i = 0; i < nlocal_; ++i)
          if (near(p.x[i][a])) s.send.push_back(static_cast<int>(i));
        for (std::size_t k = 0; k < ghosts_before; ++k)
          if (near(g.position(k)[a])) s.send.push_back(static_cast<int>(nlocal_ + k));
        for (int idx : s.send) {
          const bool local = static_cast<std::size_t>(idx) < nlocal_;
          const std::size_t k = local ? idx : idx - nlocal_;
          w.put_id(local ? p.id[k] : g.id[k]);
          w.put(local ? p.x[k] : g.x[k]);
          w.put(Vec3((local ? Vec3::Zero() : g.shift[k]) + s.shift));
          w.put(local ? p.v[k] : g.v[k]);
          w.put(local ? p.omega[k] : g.omega[k]);
          if (predicted_) {
            w.put(local ? p.v_pred[k] : g.v_pred[k]);
            w.put(local ? p.omega_pred[k] : g.omega_pred[k]);
          }
          w.put(local ? p.radius[k] : g.radius[k]);
          w.put(local ? p.mass[k] : g.mass[k]);
          w.put(local ? p.inertia[k] : g.inertia[k]);
          w.put(static_cast<double>(local ? p.material[k] : g.material[k]));
        }
      }
      sent_ += static_cast<long>(s.send.size());
      const std::vector<double> in = sendrecv(d_.comm(), out, to, from, 200 + 2 * a + dir);
      Reader r{in};
      s.recv_first = g.size();
      while (r.k < in.size()) {
        g.id.push_back(r.get_id());
        g.x.push_back(r.get_vec());
        g.shift.push_back(r.get_vec());
        g.v.push_back(r.get_vec());
        g.omega.push_back(r.get_vec());
        if (predicted_) {
          g.v_pred.push_back(r.get_vec());
          g.omega_pred.push_back(r.get_vec());
        }
        g.radius.push_back(r.get());
        g.mass.push_back(r.get());
        g.inertia.push_back(r.get());
        g.material.push_back(static_cast<int>(r.get()));
      }
      s.recv_count = g.size() - s.recv_first;
      swaps_.push_back(std::move(s));
    }
  }
}

Exchange::~Exchange() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized) return;
  // A forward left half done (an error between its two halves) still completes, since its
  // buffers go with this object: every neighbour posted the matching sends and receives in
  // its own forward_begin.
  if (!receives_.empty())
    MPI_Waitall(static_cast<int>(receives_.size()), receives_.data(), MPI_STATUSES_IGNORE);
  complete_sends();
}

void Exchange::complete_sends() {
  if (sends_.empty()) return;
  MPI_Waitall(static_cast<int>(sends_.size()), sends_.data(), MPI_STATUSES_IGNORE);
  sends_.clear();
}

// The forward's send buffers are written with non-temporal stores. The neighbour's copy of
// the last step's message (Open MPI's single copy, on the neighbour's core) leaves their cache
// lines in that core's cache; an ordinary store must first take each line back (a request for
// ownership), which on this AMD guest costs little when the two ranks' vCPUs share a cache and
// up to 6x the whole pack when they do not, changing from run to run: post_stage's samples
// over 3000 steps of the 2-rank settled bed were 46-388 with ordinary stores and 50-75 with
// these, in 8 alternating runs each (docs/performance.md).
namespace {
void stream_store(double* to, double value) {
#if defined(__x86_64__)
  _mm_stream_si64(reinterpret_cast<long long*>(to), std::bit_cast<long long>(value));
#else
  *to = value;
#endif
}
void end_streaming() {
#if defined(__x86_64__)
  _mm_sfence();
#endif
}
}  // namespace

// Every step, so one message per swap: the sizes are those of borders(). The two swaps of an
// axis go at once (their lists hold particles and ghosts of earlier axes only), the axes one
// after the other (the y swaps forward ghosts received along x).
bool Exchange::stage_talks(std::size_t first) const {
  for (std::size_t w = first; w < first + 2 && w < swaps_.size(); ++w)
    if (d_.neighbour(swaps_[w].axis, swaps_[w].dir) != MPI_PROC_NULL ||
        d_.neighbour(swaps_[w].axis, 1 - swaps_[w].dir) != MPI_PROC_NULL)
      return true;
  return false;
}

void Exchange::forward_begin(const Particles& p, const Ghosts& g) {
  complete_sends();  // the last step's, before their buffers are filled again
  buffers_.resize(2 * swaps_.size());
  // The stages before the first that talks receive nothing, so its lists hold local particles
  // only (or ghosts of stages that have none).
  begun_ = 0;
  while (begun_ < swaps_.size() && !stage_talks(begun_)) begun_ += 2;
  if (begun_ >= swaps_.size()) return;
  if (predicted_)
    post_stage<true>(begun_, p, g);
  else
    post_stage<false>(begun_, p, g);
}

void Exchange::forward_end(const Particles& p, Ghosts& g) {
  for (std::size_t first = begun_; first < swaps_.size(); first += 2) {
    if (!stage_talks(first)) continue;
    if (predicted_) {
      if (first != begun_) post_stage<true>(first, p, g);
      finish_stage<true>(first, g);
    } else {
      if (first != begun_) post_stage<false>(first, p, g);
      finish_stage<false>(first, g);
    }
  }
  begun_ = swaps_.size();
}

template <bool Predicted>
void Exchange::post_stage(std::size_t first, const Particles& p, const Ghosts& g) {
  // x, v, omega, and with the predicted dashpot velocities also v_pred, omega_pred.
  constexpr int kWidth = Predicted ? 15 : 9;
  receives_.clear();
  for (std::size_t w = first; w < first + 2 && w < swaps_.size(); ++w) {
    const Swap& s = swaps_[w];
    const int to = d_.neighbour(s.axis, s.dir), from = d_.neighbour(s.axis, 1 - s.dir);
    if (to == MPI_PROC_NULL && from == MPI_PROC_NULL) continue;
    std::vector<double>& in = buffers_[2 * w];
    std::vector<double>& out = buffers_[2 * w + 1];
    in.resize(kWidth * s.recv_count);
    out.resize(kWidth * s.send.size());
    double* o = out.data();
    for (int idx : s.send) {
      const bool local = static_cast<std::size_t>(idx) < nlocal_;
      const std::size_t k = local ? idx : idx - nlocal_;
      for (const Vec3* q : {local ? &p.x[k] : &g.x[k], local ? &p.v[k] : &g.v[k],
                            local ? &p.omega[k] : &g.omega[k]})
        for (int c = 0; c < 3; ++c) stream_store(o++, (*q)[c]);
      if constexpr (Predicted)
        for (const Vec3* q :
             {local ? &p.v_pred[k] : &g.v_pred[k], local ? &p.omega_pred[k] : &g.omega_pred[k]})
          for (int c = 0; c < 3; ++c) stream_store(o++, (*q)[c]);
    }
    end_streaming();  // the stores reach memory before the send may read them
    const int tag = 300 + 2 * s.axis + s.dir;
    MPI_Request r;
    MPI_Irecv(in.data(), static_cast<int>(in.size()), MPI_DOUBLE, from, tag, d_.comm(), &r);
    receives_.push_back(r);
    MPI_Isend(out.data(), static_cast<int>(out.size()), MPI_DOUBLE, to, tag, d_.comm(), &r);
    sends_.push_back(r);
  }
}

template <bool Predicted>
void Exchange::finish_stage(std::size_t first, Ghosts& g) {
  constexpr int kWidth = Predicted ? 15 : 9;
  MPI_Waitall(static_cast<int>(receives_.size()), receives_.data(), MPI_STATUSES_IGNORE);
  receives_.clear();
  for (std::size_t w = first; w < first + 2 && w < swaps_.size(); ++w) {
    const Swap& s = swaps_[w];
    const double* q = buffers_[2 * w].data();
    for (std::size_t k = s.recv_first; k < s.recv_first + s.recv_count; ++k, q += kWidth) {
      g.x[k] = Vec3(q[0], q[1], q[2]);
      g.v[k] = Vec3(q[3], q[4], q[5]);
      g.omega[k] = Vec3(q[6], q[7], q[8]);
      if constexpr (Predicted) {
        g.v_pred[k] = Vec3(q[9], q[10], q[11]);
        g.omega_pred[k] = Vec3(q[12], q[13], q[14]);
      }
    }
  }
}

void Exchange::forward_values(const std::vector<double>& local, std::size_t width,
                              std::vector<double>& ghost) const {
  std::size_t ghosts = 0;
  for (const Swap& s : swaps_) ghosts = std::max(ghosts, s.recv_first + s.recv_count);
  ghost.assign(ghosts * width, 0.0);
  for (const Swap& s : swaps_) {
    const int to = d_.neighbour(s.axis, s.dir), from = d_.neighbour(s.axis, 1 - s.dir);
    if (to == MPI_PROC_NULL && from == MPI_PROC_NULL) continue;
    std::vector<double> out;
    out.reserve(width * s.send.size());
    for (int idx : s.send) {
      const bool is_local = static_cast<std::size_t>(idx) < nlocal_;
      const double* v = is_local ? &local[idx * width] : &ghost[(idx - nlocal_) * width];
      out.insert(out.end(), v, v + width);
    }
    const std::vector<double> in = sendrecv(d_.comm(), out, to, from, 400 + 2 * s.axis + s.dir);
    std::copy(in.begin(), in.end(), ghost.begin() + static_cast<std::ptrdiff_t>(s.recv_first * width));
  }
}

void Exchange::reverse_values(std::vector<double>& local, std::size_t width,
                              std::vector<double>& ghost) const {
  for (auto it = swaps_.rbegin(); it != swaps_.rend(); ++it) {
    const Swap& s = *it;
    const int to = d_.neighbour(s.axis, s.dir), from = d_.neighbour(s.axis, 1 - s.dir);
    if (to == MPI_PROC_NULL && from == MPI_PROC_NULL) continue;
    const auto first = ghost.begin() + static_cast<std::ptrdiff_t>(s.recv_first * width);
    const std::vector<double> out(first, first + static_cast<std::ptrdiff_t>(s.recv_count * width));
    const std::vector<double> in = sendrecv(d_.comm(), out, from, to, 500 + 2 * s.axis + s.dir);
    std::size_t k = 0;
    for (int idx : s.send) {
      const bool is_local = static_cast<std::size_t>(idx) < nlocal_;
      double* v = is_local ? &local[idx * width] : &ghost[(idx - nlocal_) * width];
      for (std::size_t c = 0; c < width; ++c) v[c] += in[k++];
    }
  }
}

}  // namespace grainflow
