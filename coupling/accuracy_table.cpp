#include "coupling/accuracy_table.hpp"

#include <cmath>
#include <cstdio>
#include <iterator>
#include <sstream>
#include <vector>

namespace grainflow::coupling {
namespace {

std::string percent(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.1f %%", 100 * x);
  return buf;
}

}  // namespace

std::string describe_coupled_accuracy(const std::string& method, const std::string& sampling,
                                      double cell_over_d, int steps_per_fluid) {
  std::ostringstream out;
  out.precision(2);
  std::vector<FootprintAccuracy> pts;
  for (const FootprintAccuracy& a : kFootprintAccuracy)
    if (method == a.method && sampling == a.sampling) pts.push_back(a);
  out << "accuracy (docs/accuracy-vs-cost-coupled.md): footprint " << method << ", sampling "
      << sampling << ", cells of " << cell_over_d << " d: ";
  if (pts.size() >= 2 && cell_over_d >= pts.front().cell_over_d &&
      cell_over_d <= pts.back().cell_over_d) {
    for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
      const FootprintAccuracy &a = pts[k], &b = pts[k + 1];
      if (cell_over_d > b.cell_over_d) continue;
      const double s = (cell_over_d - a.cell_over_d) / (b.cell_over_d - a.cell_over_d);
      out << "packed-bed pressure drop vs Ergun " << percent(a.dp_error + s * (b.dp_error - a.dp_error))
          << ", coupling " << std::lround(100 * (a.coupling_share + s * (b.coupling_share - a.coupling_share)))
          << " % of CPU";
      break;
    }
  } else {
    out << "outside the measured 2-4 d";
  }
  out << "\n  ";
  const auto& iv = kIntervalAccuracy;
  const int n_first = iv[0].steps_per_fluid, n_last = iv[std::size(iv) - 1].steps_per_fluid;
  out << steps_per_fluid << " DEM steps per fluid step: ";
  if (steps_per_fluid >= n_first && steps_per_fluid <= n_last) {
    for (std::size_t k = 0; k + 1 < std::size(iv); ++k) {
      if (steps_per_fluid > iv[k + 1].steps_per_fluid) continue;
      const double s = std::log(double(steps_per_fluid) / iv[k].steps_per_fluid) /
                       std::log(double(iv[k + 1].steps_per_fluid) / iv[k].steps_per_fluid);
      out << "packed-bed pressure drop vs Ergun "
          << percent(iv[k].dp_error + s * (iv[k + 1].dp_error - iv[k].dp_error)) << " (measured "
          << percent(iv[0].dp_error) << " at N = " << n_first << ", " << percent(iv[std::size(iv) - 1].dp_error)
          << " at N = " << n_last << ")";
      break;
    }
  } else {
    out << "outside the measured " << n_first << "-" << n_last;
  }
  return out.str();
}

}  // namespace grainflow::coupling
