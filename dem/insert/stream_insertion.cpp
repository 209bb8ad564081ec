#include "dem/insert/stream_insertion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "dem/core/number_format.hpp"
#include "dem/insert/insertion.hpp"

namespace grainflow {
namespace {
constexpr long kMaxPerStep = 100000;  // particles one stream inserts in one step, at most
}  // namespace

StreamInsertion::StreamInsertion(const Scene& scene) : domain_(scene.domain) {
  for (const Insertion& ins : scene.insertions) {
    if (ins.kind != Insertion::Kind::stream) continue;
    Stream s;
    s.entry = ins;
    if (!s.entry.stop) s.entry.stop = scene.time.end;
    s.density = scene.materials[ins.material].density;
    s.v_dir = ins.face.normal.cross(ins.face.u);
    // Two generators: the radius sequence must not depend on how many placement
    // attempts failed.
    s.radius_rng.seed(ins.seed);
    s.place_rng.seed(ins.seed ^ 0x5bd1e995u);
    r_max_ = std::max(r_max_, grainflow::max_radius(ins.radius));
    const double area = ins.face.kind == InsertionFace::Kind::rectangle
                            ? ins.face.length_u * ins.face.length_v
                            : std::numbers::pi * ins.face.radius * ins.face.radius;
    const double r_min = grainflow::min_radius(ins.radius);
    const double most = std::floor(area / (std::numbers::pi * r_min * r_min)) + 1;
    s.capacity = most < 1e9 ? static_cast<long>(most) : 1000000000L;
    streams_.push_back(std::move(s));
  }
}

void StreamInsertion::check_faces(const Scene& scene, const WallSet& walls) const {
  constexpr int kGrid = 64;  // positions per side of the face
  for (const Stream& s : streams_) {
    const Insertion& e = s.entry;
    const InsertionFace& f = e.face;
    const double r = grainflow::max_radius(e.radius);
    // Where sample() may put a centre: the face shrunk by r (a grid over the rectangle, or
    // rings over the disc), each position wrapped into the domain as the candidates are.
    const Vec3 e1 = f.kind == InsertionFace::Kind::rectangle
                        ? f.u
                        : (std::abs(f.normal[0]) < 0.9 ? Vec3::UnitX() : Vec3::UnitY())
                              .cross(f.normal)
                              .normalized();
    const Vec3 e2 = f.kind == InsertionFace::Kind::rectangle ? s.v_dir : f.normal.cross(e1);
    bool room = false;
    int blocking = -1;  // the wall at the face's centre
    for (int i = 0; i <= kGrid && !room; ++i)
      for (int j = 0; j <= kGrid && !room; ++j) {
        const double a = static_cast<double>(i) / kGrid - 0.5,
                     b = static_cast<double>(j) / kGrid - 0.5;
        Vec3 x;
        if (f.kind == InsertionFace::Kind::rectangle) {
          x = f.centre + a * std::max(0.0, f.length_u - 2 * r) * e1 +
              b * std::max(0.0, f.length_v - 2 * r) * e2;
        } else {
          const double rho = std::max(0.0, f.radius - r) * std::sqrt(a + 0.5);
          const double phi = 2 * std::numbers::pi * (b + 0.5);
          x = f.centre + rho * (std::cos(phi) * e1 + std::sin(phi) * e2);
        }
        x = wrap(x);
        room = !walls.touches_any(x, r, /*still_only=*/true);
        if (i == kGrid / 2 && j == kGrid / 2) blocking = walls.deepest_overlap(x, r).wall;
      }
    if (room) continue;
    std::ostringstream o;
    o << e.source << ": error: insert: the walls leave no room on the stream's face for its "
      << "largest particles (radius " << significant(r) << " m): at each of "
      << (kGrid + 1) * (kGrid + 1) << " positions across the face such a particle touches a wall";
    if (blocking >= 0)
      o << " (at the face's centre, wall '" << scene.walls[static_cast<std::size_t>(blocking)].name
        << "')";
    o << ", so it would wait for room for ever and the stream deliver nothing. Move the face "
         "away from the walls or widen the gap between them, or check the walls (a plane's "
         "normal points to the side the particles live on, a cylinder's `side`)";
    if (e.coarse_grain != 1)
      o << "; the particles are parcels, coarse_grain " << significant(e.coarse_grain)
        << " times the real radius: a lower coarse_grain fits";
    throw InsertionError(o.str());
  }
}

double StreamInsertion::pending_radius(Stream& s, std::size_t k) {
  while (s.pending.size() <= k) s.pending.push_back(sample_radius(s.entry.radius, s.radius_rng));
  return s.pending[k];
}

long StreamInsertion::due(Stream& s, double t) {
  const Insertion& e = s.entry;
  if (t < e.start) return 0;
  const double elapsed = std::min(t, *e.stop) - e.start;
  long n = 0;
  if (e.mass_rate) {
    double mass = s.mass;
    const double target = *e.mass_rate * elapsed;
    while (n < kMaxPerStep) {
      const double m = s.density * sphere_volume(pending_radius(s, static_cast<std::size_t>(n)));
      if (mass + 0.5 * m > target) break;
      mass += m;
      ++n;
    }
  } else {
    n = std::clamp(static_cast<long>(std::floor(*e.count_rate * elapsed + 0.5)) - s.count, 0L,
                   kMaxPerStep);
  }
  return n;
}

Vec3 StreamInsertion::sample(Stream& s, double r) {
  const InsertionFace& f = s.entry.face;
  std::uniform_real_distribution<double> u(0, 1);
  if (f.kind == InsertionFace::Kind::rectangle) {
    const double a = std::max(0.0, f.length_u - 2 * r), b = std::max(0.0, f.length_v - 2 * r);
    return f.centre + (u(s.place_rng) - 0.5) * a * f.u + (u(s.place_rng) - 0.5) * b * s.v_dir;
  }
  const Vec3 e1 =
      (std::abs(f.normal[0]) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(f.normal).normalized();
  const Vec3 e2 = f.normal.cross(e1);
  const double rho = std::max(0.0, f.radius - r) * std::sqrt(u(s.place_rng));
  const double phi = 2 * std::numbers::pi * u(s.place_rng);
  return f.centre + rho * (std::cos(phi) * e1 + std::sin(phi) * e2);
}

Vec3 StreamInsertion::wrap(Vec3 x) const {
  for (int a = 0; a < 3; ++a) {
    if (!domain_.periodic[a]) continue;
    const double length = domain_.hi[a] - domain_.lo[a];
    x[a] -= length * std::floor((x[a] - domain_.lo[a]) / length);
    if (x[a] >= domain_.hi[a]) x[a] = domain_.lo[a];  // round-off just below lo
  }
  return x;
}

Vec3 StreamInsertion::nearest_offset(const Vec3& a, const Vec3& b) const {
  Vec3 d = a - b;
  for (int k = 0; k < 3; ++k) {
    if (!domain_.periodic[k]) continue;
    const double length = domain_.hi[k] - domain_.lo[k];
    d[k] -= length * std::round(d[k] / length);
  }
  return d;
}

long StreamInsertion::insert(double t, Particles& p, const WallSet& walls,
                             const Decomposition& decomp, GlobalId& next_id, MPI_Comm comm) {
  constexpr int kAttempts = 12;  // placement tries per particle and step
  long total = 0;
  for (Stream& s : streams_) {
    const long due_now = due(s, t);
    s.lag = due_now;
    s.lag_mass = 0;
    s.lag_lower_bound = false;
    if (due_now == 0) continue;
    // No more than the face holds can be placed in one step: the rest of a backlog waits.
    const long need = std::min(due_now, s.capacity);
    // Existing bodies near the face: this rank's particles within reach (periodic images by
    // the nearest offset). Every particle is some rank's own, so the OR over the ranks below
    // sees each once, at its position now. Not the ghosts: insertion runs after the drift and
    // before the ghosts are refreshed, so their positions are a step old, and a candidate
    // they blocked on some rank counts but not on another (a stream particle landed 3 mm
    // elsewhere on 3 ranks than on 1, with `reproducible: true`).
    const InsertionFace& f = s.entry.face;
    std::vector<Vec3> near_x;
    std::vector<double> near_r;
    auto consider = [&](const Vec3& x, double r) {
      if (std::abs(nearest_offset(x, f.centre).dot(f.normal)) < r + r_max_) {
        near_x.push_back(x);
        near_r.push_back(r);
      }
    };
    for (std::size_t i = 0; i < p.size(); ++i) consider(p.x[i], p.radius[i]);
    // Candidates for each due particle; `blocked` = overlaps an existing body here.
    std::vector<Vec3> cand(static_cast<std::size_t>(need) * kAttempts);
    std::vector<int> blocked(cand.size(), 0);
    for (long j = 0; j < need; ++j) {
      const double r = pending_radius(s, static_cast<std::size_t>(j));
      for (int a = 0; a < kAttempts; ++a) {
        const std::size_t c = static_cast<std::size_t>(j) * kAttempts + a;
        cand[c] = wrap(sample(s, r));
        bool hit = walls.touches_any(cand[c], r);
        for (std::size_t k = 0; k < near_x.size() && !hit; ++k) {
          const double reach = r + near_r[k];
          hit = nearest_offset(cand[c], near_x[k]).squaredNorm() < reach * reach;
        }
        blocked[c] = hit;
      }
    }
    if (decomp.size() > 1)
      MPI_Allreduce(MPI_IN_PLACE, blocked.data(), static_cast<int>(blocked.size()), MPI_INT,
                    MPI_LOR, comm);
    // In order: each particle takes its first free candidate; the first particle
    // without one waits (with its radius) for a later step.
    std::vector<Vec3> placed_x;
    std::vector<double> placed_r;
    long placed = 0;
    for (long j = 0; j < need; ++j) {
      const double r = s.pending[static_cast<std::size_t>(j)];
      int found = -1;
      for (int a = 0; a < kAttempts && found < 0; ++a) {
        const std::size_t c = static_cast<std::size_t>(j) * kAttempts + a;
        bool hit = blocked[c] != 0;
        for (std::size_t k = 0; k < placed_x.size() && !hit; ++k) {
          const double reach = r + placed_r[k];
          hit = nearest_offset(cand[c], placed_x[k]).squaredNorm() < reach * reach;
        }
        if (!hit) found = a;
      }
      if (found < 0) break;
      const Vec3 x = cand[static_cast<std::size_t>(j) * kAttempts + found];
      if (decomp.owns(x)) {
        p.add(next_id, x, s.entry.velocity, Vec3::Zero(), r, s.entry.material, s.density);
        p.temperature.back() = s.entry.temperature.value_or(0.0);
      }
      ++next_id;
      placed_x.push_back(x);
      placed_r.push_back(r);
      s.mass += s.density * sphere_volume(r);
      ++s.count;
      ++placed;
    }
    s.pending.erase(s.pending.begin(), s.pending.begin() + placed);
    s.lag = due_now - placed;
    // due() counts at most kMaxPerStep: the backlog beyond it, from the target itself.
    const Insertion& e = s.entry;
    const double elapsed = std::min(t, *e.stop) - e.start;
    if (e.mass_rate) {
      if (s.lag > 0) s.lag_mass = std::max(0.0, *e.mass_rate * elapsed - s.mass);
      s.lag_lower_bound = due_now == kMaxPerStep;
    } else {
      s.lag = std::max(0L, static_cast<long>(std::floor(*e.count_rate * elapsed + 0.5)) - s.count);
    }
    total += placed;
  }
  return total;
}

std::string StreamInsertion::save_state() const {
  std::ostringstream out;
  out.precision(17);
  out << streams_.size() << '\n';
  for (const Stream& s : streams_) {
    out << s.mass << ' ' << s.count << ' ' << s.pending.size();
    for (double r : s.pending) out << ' ' << r;
    out << '\n' << s.radius_rng << '\n' << s.place_rng << '\n';
  }
  return out.str();
}

void StreamInsertion::restore_state(const std::string& state) {
  std::istringstream in(state);
  std::size_t n = 0;
  if (!(in >> n) || n != streams_.size())
    throw std::invalid_argument("stream insertion state is for " + std::to_string(n) +
                                " streams, the scene has " + std::to_string(streams_.size()));
  for (Stream& s : streams_) {
    std::size_t pending = 0;
    in >> s.mass >> s.count >> pending;
    // due() draws at most one radius beyond a step's worth ahead.
    if (!in || pending > static_cast<std::size_t>(kMaxPerStep) + 1)
      throw std::invalid_argument("stream insertion state is malformed");
    s.pending.assign(pending, 0.0);
    for (double& r : s.pending) in >> r;
    in >> s.radius_rng >> s.place_rng;
  }
  if (!in) throw std::invalid_argument("stream insertion state is malformed");
}

}  // namespace grainflow
