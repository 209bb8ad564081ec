#include "dem/insert/insertion.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <unordered_map>

#include "dem/core/number_format.hpp"
#include "dem/engine/restored_state.hpp"
#include "dem/io/snapshot_reader.hpp"
#include "dem/walls/wall_contact.hpp"

namespace grainflow {

double sample_radius(const SizeDistribution& d, std::mt19937_64& rng) {
  switch (d.kind) {
    case SizeDistribution::Kind::constant: return d.value;
    case SizeDistribution::Kind::uniform:
      return std::uniform_real_distribution<double>(d.min, d.max)(rng);
    case SizeDistribution::Kind::normal: {
      // The normal truncated to [min, max], exactly, by rejection from the better of two
      // proposals. The parser keeps the mean within [min, max], so the density's peak is in
      // the window. A normal draw is kept with the probability P that it falls in the window;
      // a uniform draw in the window, kept with probability exp(-z^2/2), is kept with
      // probability P sigma sqrt(2 pi) / (max - min): the uniform is the better proposal for a
      // window narrow against sigma. The normal is used while it keeps a quarter of its draws
      // (the same draws as ever for such windows, e.g. the default mean +- 3 sigma), else the
      // uniform, which then keeps more than 0.9 of them (P < 1/4 with the mean in the window
      // needs a window narrower than 0.68 sigma).
      if (!(d.max > d.min)) return d.min;
      const double z_lo = (d.min - d.mean) / d.stddev, z_hi = (d.max - d.mean) / d.stddev;
      const double p_window =
          0.5 * (std::erf(z_hi / std::numbers::sqrt2) - std::erf(z_lo / std::numbers::sqrt2));
      const double p_uniform =
          p_window * d.stddev * std::sqrt(2 * std::numbers::pi) / (d.max - d.min);
      if (p_window >= 0.25 || p_window >= p_uniform) {
        std::normal_distribution<double> g(d.mean, d.stddev);
        while (true) {
          const double r = g(rng);
          if (r >= d.min && r <= d.max) return r;
        }
      }
      std::uniform_real_distribution<double> window(d.min, d.max), keep(0.0, 1.0);
      while (true) {
        const double r = window(rng);
        const double z = (r - d.mean) / d.stddev;
        if (keep(rng) < std::exp(-0.5 * z * z)) return r;
      }
    }
    case SizeDistribution::Kind::discrete: {
      std::discrete_distribution<std::size_t> pick(d.weights.begin(), d.weights.end());
      return d.values[pick(rng)];
    }
  }
  return d.value;
}

double min_radius(const SizeDistribution& d) {
  switch (d.kind) {
    case SizeDistribution::Kind::constant:
      return d.value;
    case SizeDistribution::Kind::uniform:
    case SizeDistribution::Kind::normal:
      return d.min;
    case SizeDistribution::Kind::discrete:
      return *std::min_element(d.values.begin(), d.values.end());
  }
  return d.value;
}

double max_radius(const SizeDistribution& d) {
  switch (d.kind) {
    case SizeDistribution::Kind::constant: return d.value;
    case SizeDistribution::Kind::uniform:
    case SizeDistribution::Kind::normal: return d.max;
    case SizeDistribution::Kind::discrete:
      return *std::max_element(d.values.begin(), d.values.end());
  }
  return d.value;
}

namespace {

// Overlap below this many units in the last place of the coordinates is round-off.
constexpr double kTouchUlps = 8;

// Hash grid over existing spheres for the no-overlap test.
class OverlapGrid {
 public:
  explicit OverlapGrid(double edge) : edge_(edge), inv_(1.0 / edge) {}
  void add(const Vec3& x, double r) {
    cells_[key(cell(x))].push_back(static_cast<int>(xs_.size()));
    xs_.push_back(x);
    rs_.push_back(r);
    r_max_ = std::max(r_max_, r);
  }
  // The index of a stored sphere that overlaps the sphere (x, r), or -1.
  int overlapping(const Vec3& x, double r) const {
    // Spheres that touch, written with every digit (17), may overlap by the round-off of
    // their coordinates: kTouchUlps units in the last place of the largest coordinate (or
    // of the radii's sum) are no overlap (docs/scene-reference.md, `csv`).
    auto overlap = [&](int k) {
      const double s = r + rs_[k];
      const double scale = std::max({x.cwiseAbs().maxCoeff(), xs_[k].cwiseAbs().maxCoeff(), s});
      const double reach = s - kTouchUlps * std::numeric_limits<double>::epsilon() * scale;
      return (x - xs_[k]).squaredNorm() < reach * reach;
    };
    // A sphere much larger than the cells (a hostile CSV radius) would visit more
    // cells than there are spheres: then checking every sphere is cheaper.
    const double reach_cells = std::ceil((r + r_max_) / edge_);
    if (!(std::pow(2 * reach_cells + 1, 3) < static_cast<double>(xs_.size()))) {
      for (int k = 0; k < static_cast<int>(xs_.size()); ++k)
        if (overlap(k)) return k;
      return -1;
    }
    const auto c = cell(x);
    const long reach = static_cast<long>(reach_cells);
    for (long dz = -reach; dz <= reach; ++dz)
      for (long dy = -reach; dy <= reach; ++dy)
        for (long dx = -reach; dx <= reach; ++dx) {
          auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (int k : it->second)
            if (overlap(k)) return k;
        }
    return -1;
  }
  const Vec3& position(int k) const { return xs_[k]; }
  double radius(int k) const { return rs_[k]; }

 private:
  std::array<long, 3> cell(const Vec3& x) const {
    return {static_cast<long>(std::floor(x[0] * inv_)), static_cast<long>(std::floor(x[1] * inv_)),
            static_cast<long>(std::floor(x[2] * inv_))};
  }
  static std::uint64_t key(const std::array<long, 3>& c) {
    return (static_cast<std::uint64_t>(c[0] & 0x1fffff) << 42) |
           (static_cast<std::uint64_t>(c[1] & 0x1fffff) << 21) |
           static_cast<std::uint64_t>(c[2] & 0x1fffff);
  }
  double edge_, inv_, r_max_ = 0;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
  std::vector<Vec3> xs_;
  std::vector<double> rs_;
};

double region_volume(const Region& r) {
  if (r.kind == Region::Kind::box) return (r.hi - r.lo).prod();
  return std::numbers::pi * r.radius * r.radius * r.height;
}

// A centre uniformly distributed over the region shrunk by the radius, so the
// whole sphere lies inside the region; false if the region is thinner than 2r.
bool sample_centre(const Region& reg, double r, std::mt19937_64& rng, Vec3& x) {
  std::uniform_real_distribution<double> u(0, 1);
  if (reg.kind == Region::Kind::box) {
    for (int a = 0; a < 3; ++a) {
      const double lo = reg.lo[a] + r, hi = reg.hi[a] - r;
      // A region as wide as the sphere up to round-off (the scene's check allows 1e-9 of the
      // diameter) takes it at its middle.
      if (hi < lo - kRegionFitTolerance * 2 * r) return false;
      x[a] = hi < lo ? 0.5 * (lo + hi) : lo + (hi - lo) * u(rng);
    }
    return true;
  }
  const double slack = kRegionFitTolerance * 2 * r;
  if (reg.radius - r < -slack || reg.height - 2 * r < -slack) return false;
  const double rad = std::max(0.0, reg.radius - r), h = std::max(0.0, reg.height - 2 * r);
  // Orthonormal frame (e1, e2, axis).
  const Vec3 a = reg.axis;
  const Vec3 e1 = (std::abs(a[0]) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(a).normalized();
  const Vec3 e2 = a.cross(e1);
  const double rho = rad * std::sqrt(u(rng)), phi = 2 * std::numbers::pi * u(rng);
  x = reg.base + (r + h * u(rng)) * a + rho * std::cos(phi) * e1 + rho * std::sin(phi) * e2;
  return true;
}

// Whether the point x lies in the region (a sphere's centre: the sphere may reach out).
bool inside_region(const Region& reg, const Vec3& x) {
  if (reg.kind == Region::Kind::box)
    return (x.array() >= reg.lo.array()).all() && (x.array() <= reg.hi.array()).all();
  const Vec3 d = x - reg.base;
  const double along = d.dot(reg.axis);
  return along >= 0 && along <= reg.height && (d - along * reg.axis).norm() <= reg.radius;
}

// `tolerance`: how far a sphere may poke through a bounded side (a settled particle overlaps
// a wall that lies on that side by a little).
bool inside_domain(const Domain& d, const Vec3& x, double r, double tolerance = 0) {
  for (int a = 0; a < 3; ++a) {
    if (d.periodic[a]) {
      if (x[a] < d.lo[a] || x[a] >= d.hi[a]) return false;
    } else if (x[a] - r + tolerance < d.lo[a] || x[a] + r - tolerance > d.hi[a]) {
      return false;
    }
  }
  return true;
}

// Overlap test that also sees periodic images of earlier particles: the index of an
// earlier particle (x, r) overlaps, or -1.
int overlapping_with_images(const OverlapGrid& grid, const Domain& d, const Vec3& x, double r) {
  const Vec3 length = d.hi - d.lo;
  for (int sz = -1; sz <= 1; ++sz)
    for (int sy = -1; sy <= 1; ++sy)
      for (int sx = -1; sx <= 1; ++sx) {
        const int s[3] = {sx, sy, sz};
        bool valid = true;
        Vec3 shifted = x;
        for (int a = 0; a < 3; ++a) {
          if (s[a] != 0 && !d.periodic[a]) valid = false;
          shifted[a] += s[a] * length[a];
        }
        if (!valid) continue;
        if (const int k = grid.overlapping(shifted, r); k >= 0) return k;
      }
  return -1;
}

bool overlaps_with_images(const OverlapGrid& grid, const Domain& d, const Vec3& x, double r) {
  return overlapping_with_images(grid, d, x, r) >= 0;
}

bool touches_a_wall(const Scene& s, const WallSet* walls, const Vec3& x, double r) {
  if (walls) return walls->touches_any(x, r);
  WallTouch t;
  for (const Wall& w : s.walls)
    if (touch_wall(w, x, r, t)) return true;
  return false;
}

// Why a particle given by a file (x, r) may not start where it is, or "" if it may: it
// overlaps a wall by more than time.max_overlap of its radius (more than a run allows; a
// settled bed touches its walls by less), or its centre is on the wall's far side (an
// overlap above r). Planes and cylinders at t = 0 when `walls` is not given.
std::string inside_a_wall(const Scene& s, const WallSet* walls, const Vec3& x, double r) {
  int wall = -1;
  double overlap = 0;
  if (walls) {
    const WallSet::Overlap o = walls->deepest_overlap(x, r);
    wall = o.wall;
    overlap = o.overlap;
  } else {
    WallTouch t;
    for (std::size_t k = 0; k < s.walls.size(); ++k)
      if (touch_wall(s.walls[k], x, r, t) && t.overlap > overlap) {
        wall = static_cast<int>(k);
        overlap = t.overlap;
      }
  }
  if (wall < 0 || overlap <= s.time.max_overlap * r) return {};
  std::ostringstream o;
  o.precision(4);
  o << "lies inside wall '" << s.walls[wall].name << "': it overlaps it by " << overlap << " m, "
    << 100 * overlap / r << " % of its radius";
  if (overlap > r) o << " (its centre is on the wall's far side)";
  o << "; at insertion a particle may overlap a wall by at most time.max_overlap = "
    << 100 * s.time.max_overlap
    << " % of its radius (the most a run allows); move the particle out of the wall";
  return o.str();
}

namespace {
// A fill draws all its radii and holds every particle it places on each rank before they
// are shared out: at least this many bytes per particle (a run of 1e6 beads peaked at
// 340 bytes each), so a fill of more than physical memory / kFillBytesPerParticle surely
// cannot be held.
constexpr double kFillBytesPerParticle = 200;

double physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page)
                               : std::numeric_limits<double>::infinity();
}

// The error for a fill of at least `n` particles that memory cannot hold.
[[noreturn]] void refuse_fill_size(const Insertion& ins, double n, double memory) {
  std::ostringstream msg;
  msg.precision(3);
  msg << ins.source << ": error: this fill would insert " << (ins.count ? "" : "about ") << n
      << " particles";
  if (ins.volume_fraction)
    msg << " (volume_fraction " << *ins.volume_fraction << " of its region with these radii)";
  msg << ", at least " << kFillBytesPerParticle << " bytes each in memory ("
      << n * kFillBytesPerParticle / 1e9 << " GB), more than this machine's " << memory / 1e9
      << " GB (each rank holds the whole fill while it is placed): at most "
      << std::floor(memory / kFillBytesPerParticle) << " fit";
  const double k = ins.coarse_grain;
  const std::string here = k != 1 ? " (here k = " + exact_number(k) + ")" : std::string();
  if (ins.count)
    msg << "; give fewer particles, or coarse-grained parcels: `count` counts parcels, so with "
           "`coarse_grain: k` (each parcel standing for k^3 particles) give count / k^3"
        << here;
  else
    msg << "; give larger particles, or coarse-grained parcels (`coarse_grain: k`: each parcel "
           "stands for k^3 particles, and the fill draws k^3 times fewer)"
        << here;
  msg << " (docs/models/coarse-graining.md)";
  throw InsertionError(msg.str());
}
}  // namespace

void fill_region(const Scene& scene, const WallSet* walls, const Insertion& ins, Particles& p,
                 GlobalId& next_id, OverlapGrid& grid, std::vector<std::string>* notes) {
  std::mt19937_64 rng(ins.seed);
  const double density = scene.materials[ins.material].density;
  const double target_volume =
      ins.volume_fraction ? *ins.volume_fraction * region_volume(ins.region) : 0.0;
  const long target_count = ins.count ? *ins.count : 0;
  long placed = 0, attempts = 0;
  double volume = 0;
  // Why attempts failed, for the message: a wall (counted per wall), the domain, an earlier
  // particle.
  std::vector<long> by_wall(scene.walls.size(), 0);
  long sampled = 0, outside = 0, walled = 0;
  const std::size_t earlier = p.size();  // the particles of earlier insertions
  const auto wall_of = [&](const Vec3& x, double r) {
    if (walls) return walls->deepest_overlap(x, r).wall;
    int wall = -1;
    double deepest = -1;
    WallTouch t;
    for (std::size_t k = 0; k < scene.walls.size(); ++k)
      if (touch_wall(scene.walls[k], x, r, t) && t.overlap > deepest) {
        wall = static_cast<int>(k);
        deepest = t.overlap;
      }
    return wall;
  };
  // The radii are drawn first, all of them (for a volume fraction, until their volume reaches
  // it), and placed largest first. Drawing a radius at every attempt would place small
  // particles more readily than large ones, so that a dense fill held fewer large ones than
  // the distribution asks for; largest first, the small ones fill the gaps the large ones
  // leave, and dense fills reach the packing they would in any order or more.
  std::vector<double> radii;
  const double memory = physical_memory_bytes();
  const double most = memory / kFillBytesPerParticle;
  if (ins.count) {
    if (static_cast<double>(target_count) > most)
      refuse_fill_size(ins, static_cast<double>(target_count), memory);
    radii.reserve(static_cast<std::size_t>(target_count));
    for (long k = 0; k < target_count; ++k) radii.push_back(sample_radius(ins.radius, rng));
  } else {
    // The count a volume fraction asks, from the mean volume of 10 000 radii drawn from a
    // copy of the generator (the fill's own draws stay as they were).
    std::mt19937_64 probe = rng;
    double drawn = 0;
    for (int k = 0; k < 10000; ++k) drawn += sphere_volume(sample_radius(ins.radius, probe));
    if (const double n = target_volume / (drawn / 10000); n > most)
      refuse_fill_size(ins, n, memory);
    for (double v = 0; v < target_volume;) {
      if (static_cast<double>(radii.size()) > most)
        refuse_fill_size(ins, static_cast<double>(radii.size()), memory);
      radii.push_back(sample_radius(ins.radius, rng));
      v += sphere_volume(radii.back());
    }
  }
  std::stable_sort(radii.begin(), radii.end(), std::greater<>());
  // Random sequential addition saturates near 38 % solids for equal spheres; the
  // attempt budget (2000 per particle drawn, for a count and a volume fraction alike) turns
  // an impossible request into a clear error, not a hang. (In double: a count near the
  // parser's limit of 9e15 would overflow a long here.)
  const long budget = static_cast<long>(
      std::min(2000.0 * std::max(1000.0, static_cast<double>(radii.size())) + 2e6, 9e18));
  while (static_cast<std::size_t>(placed) < radii.size()) {
    if (++attempts > budget) {
      std::ostringstream msg;
      msg.precision(4);
      msg << ins.source << ": error: could place only " << placed << " particles ("
          << volume / region_volume(ins.region) << " solid fraction) without overlap in the fill "
          << "region after " << budget << " attempts";
      // Most attempts on a wall: the walls, not the region's size or the count, are the cause.
      const double usable =
          sampled > 0 ? 1 - static_cast<double>(walled + outside) / static_cast<double>(sampled)
                      : 1.0;
      // What earlier insertions already hold of the region (their centres inside it).
      double before = 0;
      for (std::size_t i = 0; i < earlier; ++i)
        if (inside_region(ins.region, p.x[i])) before += sphere_volume(p.radius[i]);
      const double taken = before / region_volume(ins.region);
      const double reached = volume / region_volume(ins.region);
      if (walled > 0 && 2 * walled >= sampled) {
        const auto worst = std::max_element(by_wall.begin(), by_wall.end()) - by_wall.begin();
        msg << "; " << walled << " of the " << sampled << " centres drawn in the region touched "
            << "a wall or lay behind it (" << by_wall[worst] << " wall '" << scene.walls[worst].name
            << "'): the walls leave " << 100 * usable << " % of the region to the particles";
        if (ins.volume_fraction)
          msg << ". `volume_fraction` counts the whole region, so " << *ins.volume_fraction
              << " of it is " << *ins.volume_fraction / usable
              << " of the space the walls leave, where random insertion saturates near 0.35";
        msg << (usable < 0.05 ? ". Check" : ". If the particles should have more room, check")
            << " that wall (a plane's normal points to the side the particles live on, a "
               "cylinder's `side`), or move the region to the walls' inner side";
      } else {
        msg << "; enlarge the region, or lower `count` / `volume_fraction` (random insertion "
               "saturates near 0.35";
        if (usable < 0.99)
          msg << " of the space it can use: the walls and the domain leave " << 100 * usable
              << " % of the region, so that is about " << 0.35 * usable
              << " of the region's volume";
        msg << ")";
      }
      if (taken > 0.01)
        msg << "; earlier insertions already fill " << taken
            << " of the region (their particles count against this fill's room)";
      // What this fill reached is the surer figure where walls are near: beds pack less
      // densely against them than in the open (0.2749 estimated, 0.2403 reached in a drum
      // 6.7 bead diameters wide), so an estimate-based request was refused again. The
      // particles placed are the largest drawn (largest first), so the figure is a safe
      // one, not the most that fits: a whole draw of the distribution, smaller on average,
      // packs at least as well. A count is the volume reached over the mean volume drawn.
      if (ins.volume_fraction && placed > 1) {
        msg << "; this fill reached " << reached << " before its attempts ran out: a "
            << "`volume_fraction` of " << round_down_3(0.95 * reached) << " fits";
      } else if (ins.count && placed > 1) {
        double drawn = 0;
        for (double r : radii) drawn += sphere_volume(r);
        const double mean = drawn / static_cast<double>(radii.size());
        const long fits = std::max<long>(static_cast<long>(0.95 * volume / mean),
                                         static_cast<long>(0.95 * static_cast<double>(placed)));
        msg << "; this fill placed " << placed << " (its largest) before its attempts ran "
            << "out, " << reached << " of the region: a `count` of " << fits << " fits";
      }
      if (ins.coarse_grain != 1)
        msg << "; the particles are parcels of radius up to " << max_radius(ins.radius)
            << " m, coarse_grain " << ins.coarse_grain
            << " times the real radius: a lower coarse_grain fits more of them";
      throw InsertionError(msg.str());
    }
    const double r = radii[static_cast<std::size_t>(placed)];
    Vec3 x;
    if (!sample_centre(ins.region, r, rng, x)) continue;
    ++sampled;
    if (!inside_domain(scene.domain, x, r)) {
      ++outside;
      continue;
    }
    if (touches_a_wall(scene, walls, x, r)) {
      ++walled;
      if (const int w = wall_of(x, r); w >= 0) ++by_wall[w];
      continue;
    }
    if (overlaps_with_images(grid, scene.domain, x, r)) continue;
    grid.add(x, r);
    p.add(next_id++, x, ins.velocity, Vec3::Zero(), r, ins.material, density);
    p.temperature.back() = ins.temperature.value_or(0.0);
    ++placed;
    volume += sphere_volume(r);
  }
  // Radii are drawn until their volume reaches the fraction, so the last one overshoots it:
  // by little in a large region, by much where one particle is a sizeable part of it.
  const double reached = volume / region_volume(ins.region);
  // volume_fraction counts the whole region: where walls or the domain's sides take a part of
  // it, the particles stand denser in the rest than the fraction reads (a drum in a box region:
  // 0.1 asked, 0.354 in the drum). Said, with the share of the region's volume they left, from
  // 20 000 points drawn in the region (their own generator: the fill's draws stay as they
  // were). Not the centres' share: a centre keeps a radius from the walls, and in a drum five
  // radii wide that share (15 %) is well below the drum's (19.6 %).
  if (ins.volume_fraction && notes && sampled > 0 && walled + outside > 0) {
    std::mt19937_64 points(ins.seed ^ 0x9e3779b97f4a7c15ULL);
    constexpr int kPoints = 20000;
    int free = 0;
    for (int k = 0; k < kPoints; ++k) {
      Vec3 x;
      if (sample_centre(ins.region, 0.0, points, x) && inside_domain(scene.domain, x, 0.0) &&
          !touches_a_wall(scene, walls, x, 0.0))
        ++free;
    }
    const double space = static_cast<double>(free) / kPoints;
    if (space < 0.9 && space > 0) {
      std::ostringstream o;
      o.precision(3);
      o << "note: " << ins.source << ": the walls" << (outside > 0 ? " and the domain's sides" : "")
        << " leave about " << 100 * space << " % of the fill's region to the particles (of "
        << kPoints << " points drawn in it); volume_fraction counts the whole region, so its "
        << reached << " is about " << reached / space << " solid fraction in the space left; for "
        << reached << " there, ask volume_fraction " << round_down_3(reached * space)
        << " or fit the region to that space";
      notes->push_back(o.str());
    }
  }
  if (ins.volume_fraction && notes && reached > 1.05 * *ins.volume_fraction) {
    std::ostringstream o;
    o.precision(4);
    o << "note: " << ins.source << ": the fill placed " << placed << " particle"
      << (placed == 1 ? "" : "s") << ", a volume fraction of " << reached
      << " of its region, where "
      << "volume_fraction asks " << *ins.volume_fraction
      << ": radii are drawn until their volume reaches the fraction, and the last one, up to "
      << sphere_volume(max_radius(ins.radius)) / region_volume(ins.region)
      << " of the region, overshoots it; a larger region or a `count` comes closer";
    notes->push_back(o.str());
  }
}

std::vector<std::string> split_csv(const std::string& line) {
  // Every comma separates two cells, a trailing one too: "1,2," has three (the last empty).
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::string cell =
        line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto b = cell.find_first_not_of(" \t\r");
    const auto e = cell.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// Every digit of a value read from a file (dem/core/number_format.hpp): a message that
// compares it with a limit must show how it differs.
std::string format_number(double x) { return exact_number(x); }

std::string format_vec(const Vec3& x) {
  return '(' + exact_number(x[0]) + ", " + exact_number(x[1]) + ", " + exact_number(x[2]) + ')';
}

// Why a particle (x, r) is not inside the domain (inside_domain() is false), for messages.
std::string outside_domain_reason(const Domain& d, const Vec3& x, double r) {
  const char* axis = "xyz";
  std::ostringstream s;
  auto num = [](double v) { return exact_number(v); };
  for (int a = 0; a < 3; ++a) {
    if (d.periodic[a]) {
      if (x[a] < d.lo[a] || x[a] >= d.hi[a]) {
        s << "its centre " << axis[a] << " = " << num(x[a]) << " is outside the periodic range ["
          << num(d.lo[a]) << ", " << num(d.hi[a]) << ")";
        return s.str();
      }
    } else if (x[a] - r < d.lo[a] || x[a] + r > d.hi[a]) {
      const double beyond = std::max(d.lo[a] - (x[a] - r), x[a] + r - d.hi[a]);
      s << "it spans " << axis[a] << " from " << num(x[a] - r) << " to " << num(x[a] + r)
        << ", beyond the domain's " << num(d.lo[a]) << " to " << num(d.hi[a]) << " by "
        << significant(beyond) << " m (a sphere must lie wholly inside a bounded side)";
      return s.str();
    }
  }
  return "it lies outside the domain";
}

// The columns a particle file may have; x, y, z and radius are required, vx, vy, vz
// come together, and so do wx, wy, wz.
const std::vector<std::string> kCsvColumns = {"x",  "y",  "z",  "radius",   "vx", "vy",
                                              "vz", "wx", "wy", "wz", "material", "T"};

void read_csv(const Scene& scene, const WallSet* walls, const Insertion& ins, Particles& p,
              GlobalId& next_id, OverlapGrid& grid) {
  std::ifstream in(ins.csv_file);
  if (!in)
    throw InsertionError(ins.source + ": error: cannot open particle file '" + ins.csv_file + "'");
  auto fail = [&](long line, const std::string& what) {
    std::string where = ins.csv_file;
    if (line > 0) {
      where += ':';  // (not ":" + to_string: GCC 12 false -Wrestrict)
      where += std::to_string(line);
    }
    throw InsertionError(where + ": error: " + what + " (particle file of the insertion at " +
                         ins.source + ")");
  };
  const std::string allowed =
      "columns: x,y,z,radius (required), vx,vy,vz, wx,wy,wz, material, T (optional; T needs "
      "heat on)";
  std::string line;
  long lineno = 0, header_line = 0;
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++lineno;
    // A UTF-8 byte-order mark (Excel's "CSV UTF-8") before the header: not part of a name.
    if (lineno == 1 && line.starts_with("\xEF\xBB\xBF")) line.erase(0, 3);
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    header = split_csv(line);
    header_line = lineno;
  }
  if (header.empty())
    fail(0, "the file is empty (no header line); its first line must name the " + allowed);
  std::unordered_map<std::string, int> col;
  for (std::size_t k = 0; k < header.size(); ++k) {
    const std::string& name = header[k];
    if (name.empty())
      fail(header_line, "column " + std::to_string(k + 1) +
                            " of the header has no name (two "
                            "commas in a row, or one at the end of the line); allowed " +
                            allowed);
    if (std::find(kCsvColumns.begin(), kCsvColumns.end(), name) == kCsvColumns.end())
      fail(header_line, "unknown column '" + name + "' in the header; allowed " + allowed);
    if (!col.emplace(name, static_cast<int>(k)).second)
      fail(header_line, "column '" + name + "' appears twice in the header");
  }
  for (const char* need : {"x", "y", "z", "radius"})
    if (!col.count(need))
      fail(header_line, std::string("header lacks column '") + need + "'; " + allowed);
  const int velocity_columns =
      static_cast<int>(col.count("vx") + col.count("vy") + col.count("vz"));
  if (velocity_columns != 0 && velocity_columns != 3)
    fail(header_line, "the header has only " + std::to_string(velocity_columns) +
                          " of the velocity columns vx,vy,vz; give all three or none");
  const bool has_v = velocity_columns == 3;
  const int spin_columns = static_cast<int>(col.count("wx") + col.count("wy") + col.count("wz"));
  if (spin_columns != 0 && spin_columns != 3)
    fail(header_line, "the header has only " + std::to_string(spin_columns) +
                          " of the angular velocity columns wx,wy,wz; give all three or none");
  const bool has_w = spin_columns == 3;
  // The temperature column T [K]: with heat on, it or the entry's `temperature` is needed.
  const bool has_t = col.count("T") > 0;
  if (has_t && !scene.heat)
    fail(header_line, "column 'T' (temperature) is given, but heat transfer is off; add a "
                      "top-level `heat: {}` block to the scene, or remove the column");
  if (has_t && ins.temperature)
    fail(header_line,
         "column 'T' gives each row's temperature, and the insertion entry gives "
         "`temperature: " +
             format_number(*ins.temperature) +
             "`; give one of them (the entry's is for a file without a 'T' column)");
  if (scene.heat && !has_t && !ins.temperature)
    fail(header_line, "heat is on, but the file has no column 'T' and the insertion entry no "
                      "`temperature: <K>`; give one of them");
  long particles = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    const auto cells = split_csv(line);
    if (cells.size() != header.size())
      fail(lineno, "expected " + std::to_string(header.size()) + " columns, found " +
                       std::to_string(cells.size()));
    auto number = [&](const char* name) {
      const std::string& s = cells[col[name]];
      char* end = nullptr;
      const double v = std::strtod(s.c_str(), &end);
      if (s.empty()) fail(lineno, std::string("column '") + name + "' is empty; give a number");
      if (*end != '\0' || !std::isfinite(v))
        fail(lineno, std::string("column '") + name + "' is not a finite number: '" +
                         s.substr(0, 40) + (s.size() > 40 ? "..." : "") + "'");
      return v;
    };
    const Vec3 x(number("x"), number("y"), number("z"));
    const double r = number("radius");
    if (r <= 0) fail(lineno, "radius must be > 0, got " + cells[col["radius"]]);
    const Vec3 v = has_v ? Vec3(number("vx"), number("vy"), number("vz")) : ins.velocity;
    const Vec3 w = has_w ? Vec3(number("wx"), number("wy"), number("wz")) : Vec3::Zero();
    int mat = ins.material;
    if (col.count("material")) {
      const std::string& name = cells[col["material"]];
      mat = scene.material_index(name);
      // A parcel class (glass[k=2], made by a fill or stream with coarse_grain) is a material
      // index, not a material a file may name: its rows would be parcels of that class.
      if (mat < 0 || scene.materials[mat].real_material >= 0) {
        std::string known;
        for (const Material& m : scene.materials)
          if (m.real_material < 0) known += (known.empty() ? "" : ", ") + m.name;
        fail(lineno, "unknown material '" + name + "'; known materials: " + known +
                         (mat >= 0 ? " (a parcel class of `coarse_grain`, which a csv file "
                                     "cannot insert: csv rows are real particles)"
                                   : ""));
      }
    }
    // A sphere that touches a bounded side, written with every digit, may cross it by the
    // round-off of its coordinates, as two touching spheres may overlap (kTouchUlps).
    const double touch = kTouchUlps * std::numeric_limits<double>::epsilon() *
                         std::max({x.cwiseAbs().maxCoeff(), scene.domain.lo.cwiseAbs().maxCoeff(),
                                   scene.domain.hi.cwiseAbs().maxCoeff(), r});
    if (!inside_domain(scene.domain, x, r, touch))
      fail(lineno, "the particle at " + format_vec(x) + " with radius " + format_number(r) +
                       " is outside the domain: " + outside_domain_reason(scene.domain, x, r));
    if (const std::string why = inside_a_wall(scene, walls, x, r); !why.empty())
      fail(lineno,
           "the particle at " + format_vec(x) + " with radius " + format_number(r) + " " + why);
    if (const int k = overlapping_with_images(grid, scene.domain, x, r); k >= 0)
      fail(lineno, "the particle at " + format_vec(x) + " with radius " + format_number(r) +
                       " overlaps an earlier particle at " + format_vec(grid.position(k)) +
                       " with radius " + format_number(grid.radius(k)) +
                       "; particles must not overlap at insertion (move one or shrink it)");
    grid.add(x, r);
    p.add(next_id++, x, v, w, r, mat, scene.materials[mat].density);
    if (has_t) {
      const double t = number("T");
      if (!(t > 0)) fail(lineno, "temperature T must be > 0 K, got " + cells[col["T"]]);
      p.temperature.back() = t;
    } else {
      p.temperature.back() = ins.temperature.value_or(0.0);
    }
    ++particles;
  }
  if (particles == 0)
    fail(header_line, "the file has a header but no particle rows; add one line per particle "
                      "or remove the insertion");
}

// The rules of a state file (dem/engine/restored_state.hpp) for a snapshot's particles, before
// they are used: finite positions, radii > 0, material indices of this scene, masses rho V of
// their material, unique ids. Throws StateError naming the file, dataset, index and rule.
void check_snapshot_records(const Scene& scene, const Insertion& ins, const Particles& q) {
  check_particle_records(
      q, scene,
      {ins.snapshot_file, "/",
       "the snapshot (insertion at " + ins.source +
           ") was changed or damaged after it was written, or belongs to a scene with other "
           "materials; list the materials in the order of the scene that wrote it, or insert "
           "from another snapshot"},
      false);
}

// A snapshot's particle is inside the domain when its centre is: a run keeps a particle until
// its centre leaves a bounded side (Simulation::mark_leaving), so a particle on its way out
// through a side without a wall may cross it by up to its radius in a snapshot the run wrote.
// A wall on that side is checked separately (inside_a_wall).
bool snapshot_centre_inside(const Domain& d, const Vec3& x) {
  for (int a = 0; a < 3; ++a)
    if (d.periodic[a] ? (x[a] < d.lo[a] || x[a] >= d.hi[a]) : !(x[a] >= d.lo[a] && x[a] <= d.hi[a]))
      return false;
  return true;
}

// The snapshot's particle i is not inside the domain: a StateError naming the dataset.
[[noreturn]] void snapshot_outside_domain(const Scene& scene, const Insertion& ins,
                                          const Particles& q, std::size_t i) {
  const Domain& d = scene.domain;
  std::string why = "it lies outside the domain";
  for (int a = 0; a < 3; ++a) {
    const double c = q.x[i][a];
    const std::string axis(1, "xyz"[a]);
    const std::string range = exact_number(d.lo[a]) + ", " + exact_number(d.hi[a]);
    if (d.periodic[a] && (c < d.lo[a] || c >= d.hi[a])) {
      why = "its centre " + axis + " = " + exact_number(c) + " is outside the periodic range [" +
            range +
            ") by more than the larger of the radius and half the skin (the most a run "
            "lets a centre leave it between two wraps)";
      break;
    }
    if (!d.periodic[a] && !(c >= d.lo[a] && c <= d.hi[a])) {
      why = "its centre " + axis + " = " + exact_number(c) + " is outside the bounded range [" +
            range + "] (a run removes a particle once its centre leaves a bounded side, so no " +
            "snapshot it writes holds one)";
      break;
    }
  }
  throw StateError(ins.snapshot_file + ": error: dataset '/position', index " + std::to_string(i) +
                   " (particle id " + std::to_string(q.id[i]) +
                   "): the particle lies outside the domain: " + why +
                   "; the snapshot (insertion at " + ins.source +
                   ") belongs to another domain, or was changed or damaged after it was written");
}

// `grid_needed`: whether a later entry checks overlaps against this one's particles.
void read_snapshot_entry(const Scene& scene, const WallSet* walls, const Insertion& ins,
                         Particles& p, GlobalId& next_id, OverlapGrid& grid, bool grid_needed) {
  Snapshot snap;
  try {
    snap = read_snapshot(ins.snapshot_file);
  } catch (const SnapshotDamagedError& e) {  // e.g. a checksum that does not match
    throw StateError(std::string(e.what()) + " (snapshot insertion at " + ins.source + ")");
  } catch (const SnapshotReadError& e) {  // not a grainflow snapshot
    throw InsertionError(std::string(e.what()) + " (snapshot insertion at " + ins.source + ")");
  }
  // Between neighbour-list rebuilds a periodic run lets centres drift past a periodic side
  // (they are moved back to [lo, hi) at the next rebuild), so its snapshots may hold centres
  // up to half a skin outside that range: such a centre is the same sphere as its image
  // inside, and is moved there. Farther out (a snapshot of another domain) is an error.
  Particles& q = snap.particles;
  // Its material indices are those of the scene that wrote it. The parser mapped them to this
  // scene's materials by name (root attribute material_names) and gave this scene the same
  // parcel classes (Insertion::material_map).
  if (!ins.material_map.empty())
    for (std::size_t i = 0; i < q.size(); ++i) {
      const int m = q.material[i];
      if (m < 0 || static_cast<std::size_t>(m) >= ins.material_map.size())
        throw StateError(ins.snapshot_file + ": error: dataset '/material', index " +
                         std::to_string(i) + " (particle id " + std::to_string(q.id[i]) +
                         "): the material index " + std::to_string(m) + " is not one of the " +
                         std::to_string(ins.material_map.size()) +
                         " materials of the scene that wrote it (root attributes "
                         "material_names, material_coarse_grain); the snapshot (insertion at " +
                         ins.source + ") was changed or damaged after it was written");
      const int here = ins.material_map[static_cast<std::size_t>(m)];
      if (here < 0) {
        std::string listed;
        for (std::size_t k = 0; k < scene.materials.size(); ++k)
          if (scene.materials[k].real_material < 0)
            listed += (listed.empty() ? "" : ", ") + scene.materials[k].name;
        throw InsertionError(
            ins.source + ": error: snapshot '" + ins.snapshot_file + "' holds particles of " +
            "material '" + ins.snapshot_material_names[static_cast<std::size_t>(m)] +
            "' (particle id " + std::to_string(q.id[i]) + "), and this scene lists no material " +
            "of that name (it lists " + listed + "); add it to `materials`");
      }
      q.material[i] = here;
    }
  // Masses the writing scene left out (output.fields) follow from the radius and the
  // material, as they would be checked: rho (4/3) pi r^3.
  if (!snap.has_mass)
    for (std::size_t i = 0; i < q.size(); ++i) {
      const int m = q.material[i];
      if (m < 0 || m >= static_cast<int>(scene.materials.size())) continue;  // reported next
      q.mass[i] = scene.materials[static_cast<std::size_t>(m)].density * sphere_volume(q.radius[i]);
      q.inertia[i] = 0.4 * q.mass[i] * q.radius[i] * q.radius[i];
    }
  check_snapshot_records(scene, ins, q);
  if (ins.keep_velocity && !(snap.has_velocity && snap.has_angular_velocity))
    throw InsertionError(
        ins.snapshot_file + ": error: no dataset '/" +
        (snap.has_velocity ? "angular_velocity" : "velocity") +
        "': the scene that wrote this snapshot left it out of output.fields, so the particles' "
        "motion is not known; start them at rest with `keep_velocity: false` (insertion at " +
        ins.source + "), or list velocity and angular_velocity in that scene's output.fields");
  // Each particle's k, when the file lists it, is its class's.
  for (std::size_t i = 0; i < snap.coarse_grain.size(); ++i) {
    const Material& m = scene.materials[static_cast<std::size_t>(q.material[i])];
    if (snap.coarse_grain[i] != m.coarse_grain)
      throw StateError(ins.snapshot_file + ": error: dataset '/coarse_grain', index " +
                       std::to_string(i) + " (particle id " + std::to_string(q.id[i]) +
                       "): k = " + format_number(snap.coarse_grain[i]) + ", but its material '" +
                       m.name + "' has k = " + format_number(m.coarse_grain) +
                       "; the snapshot (insertion at " + ins.source +
                       ") was changed or damaged after it was written");
  }
  // Temperatures: the entry's `temperature` for all, else the file's (heat on).
  if (scene.heat) {
    if (ins.temperature)
      q.temperature.assign(q.size(), *ins.temperature);
    else if (!snap.has_temperature)
      throw InsertionError(ins.source + ": error: heat is on, but snapshot '" + ins.snapshot_file +
                           "' holds no temperatures (dataset '/temperature'); give the entry "
                           "`temperature: <K>`");
    for (std::size_t i = 0; i < q.size(); ++i)
      if (!(q.temperature[i] > 0) || !std::isfinite(q.temperature[i]))
        throw StateError(ins.snapshot_file + ": error: dataset '/temperature', index " +
                         std::to_string(i) + ": temperature " + std::to_string(q.temperature[i]) +
                         " K is not a finite positive number");
  } else {
    q.temperature.assign(q.size(), 0.0);
  }
  const Domain& dom = scene.domain;
  const double drift = scene.neighbour.skin ? 0.5 * *scene.neighbour.skin : 0.0;
  for (std::size_t i = 0; i < q.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      if (!dom.periodic[a]) continue;
      const double period = dom.hi[a] - dom.lo[a];
      const double reach = std::max(q.radius[i], drift);
      double& c = q.x[i][a];
      if (c < dom.lo[a] && c >= dom.lo[a] - reach) {
        c += period;
        if (c >= dom.hi[a]) c = dom.lo[a];  // lo - 1e-20 + period rounds to hi
      } else if (c >= dom.hi[a] && c < dom.hi[a] + reach) {
        c -= period;
      }
    }
  for (std::size_t i = 0; i < q.size(); ++i) {
    auto fail = [&](const std::string& what) {
      throw InsertionError(ins.source + ": error: particle id " + std::to_string(q.id[i]) +
                           " of snapshot '" + ins.snapshot_file + "' " + what);
    };
    // The run's own rule (snapshot_centre_inside); a settled bed's overlaps with walls on the
    // domain's sides, up to the overlap the run allowed, are inside_a_wall's to check.
    if (!snapshot_centre_inside(scene.domain, q.x[i])) snapshot_outside_domain(scene, ins, q, i);
    if (const std::string why = inside_a_wall(scene, walls, q.x[i], q.radius[i]); !why.empty())
      fail(why);
    // Touching neighbours of a settled bed overlap slightly: only particles of
    // earlier entries are checked (the grid holds this snapshot's only afterwards).
    if (overlaps_with_images(grid, scene.domain, q.x[i], q.radius[i]))
      fail("overlaps a particle of an earlier insertion entry");
  }
  if (grid_needed)
    for (std::size_t i = 0; i < q.size(); ++i) grid.add(q.x[i], q.radius[i]);
  if (p.size() == 0) {
    // The first entry: the snapshot's arrays become the particles' (no second copy of a
    // large bed at start-up, on every rank), with new ids and the velocities asked for.
    p = std::move(snap.particles);
    for (std::size_t i = 0; i < p.size(); ++i) {
      p.id[i] = next_id++;
      if (!ins.keep_velocity) {
        p.v[i] = Vec3::Zero();
        p.omega[i] = Vec3::Zero();
      }
    }
    return;
  }
  p.reserve(p.size() + q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    const Vec3 v = ins.keep_velocity ? q.v[i] : Vec3::Zero();
    const Vec3 w = ins.keep_velocity ? q.omega[i] : Vec3::Zero();
    p.add_raw(next_id++, q.x[i], v, w, q.radius[i], q.mass[i], q.inertia[i], q.material[i]);
    p.temperature.back() = q.temperature[i];
  }
}

}  // namespace

void insert_particles(const Scene& scene, Particles& p, GlobalId& next_id, const WallSet* walls,
                      std::vector<std::string>* notes) {
  double r_max = 0;
  for (std::size_t i = 0; i < p.size(); ++i) r_max = std::max(r_max, p.radius[i]);
  for (const Insertion& ins : scene.insertions)
    if (ins.kind == Insertion::Kind::fill) r_max = std::max(r_max, max_radius(ins.radius));
  // The grid edge only sets the search cost; overlaps() widens its search for
  // larger spheres (e.g. from a CSV file), so correctness does not depend on it.
  OverlapGrid grid(r_max > 0 ? 2 * r_max : (scene.domain.hi - scene.domain.lo).minCoeff() / 50);
  for (std::size_t i = 0; i < p.size(); ++i) grid.add(p.x[i], p.radius[i]);
  for (std::size_t e = 0; e < scene.insertions.size(); ++e) {
    const Insertion& ins = scene.insertions[e];
    const bool later_checks = std::any_of(
        scene.insertions.begin() + static_cast<std::ptrdiff_t>(e) + 1, scene.insertions.end(),
        [](const Insertion& later) { return later.kind != Insertion::Kind::stream; });
    switch (ins.kind) {
      case Insertion::Kind::fill:
        fill_region(scene, walls, ins, p, next_id, grid, notes);
        break;
      case Insertion::Kind::csv:
        if (!ins.csv_missing.empty()) throw InsertionError(ins.csv_missing);
        read_csv(scene, walls, ins, p, next_id, grid);
        break;
      case Insertion::Kind::snapshot:
        read_snapshot_entry(scene, walls, ins, p, next_id, grid, later_checks);
        break;
      case Insertion::Kind::stream: break;  // during the run: StreamInsertion
    }
  }
}

}  // namespace grainflow
