#include "dem/engine/finite_guard.hpp"

#include <cmath>
#include <cstddef>
#include <sstream>

#include "dem/engine/simulation.hpp"
#include "dem/io/snapshot_writer.hpp"
#include "dem/parallel/exchange.hpp"

namespace grainflow {
namespace {

bool finite(const Vec3& a) {
  return std::isfinite(a.x()) && std::isfinite(a.y()) && std::isfinite(a.z());
}

bool positive(double temperature) { return temperature > 0 && std::isfinite(temperature); }

// Index of the first particle with a non-finite state (or, with `temperatures`, a
// temperature not above 0 K), or p.size().
std::size_t first_bad(const Particles& p, bool temperatures) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!finite(p.x[i]) || !finite(p.v[i]) || !finite(p.omega[i]) ||
        (temperatures && !positive(p.temperature[i])))
      return i;
  return p.size();
}

std::string text(const Vec3& a) {
  std::ostringstream s;
  s.precision(9);
  s << "(" << a.x() << ", " << a.y() << ", " << a.z() << ")";
  return s.str();
}

}  // namespace

bool has_non_finite(const Particles& p, bool temperatures) {
  return first_bad(p, temperatures) < p.size();
}

bool temperatures_positive(const Particles& p) {
  bool all = true;
  for (const double t : p.temperature) all &= positive(t);
  return all;
}

bool non_finite_anywhere(bool local_bad, MPI_Comm comm) {
  int bad = local_bad ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT, MPI_MAX, comm);
  return bad != 0;
}

bool non_finite_anywhere(const Particles& p, MPI_Comm comm) {
  return non_finite_anywhere(has_non_finite(p), comm);
}

std::string describe_first_non_finite(const Particles& p, long step, double time, int rank,
                                      const std::string& force_terms, bool temperatures) {
  const std::size_t i = first_bad(p, temperatures);
  if (i == p.size()) return {};
  if (finite(p.x[i]) && finite(p.v[i]) && finite(p.omega[i])) {  // its temperature
    std::ostringstream s;
    s.precision(9);
    s << "error: step " << step << " (t = " << time << " s): particle " << p.id[i] << " (rank "
      << rank << ") has a temperature of " << p.temperature[i] << " K, not above 0 K; position "
      << text(p.x[i]) << " m, velocity " << text(p.v[i])
      << " m/s. The run stops here. A fixed heat flow out of a particle takes heat at its rate "
         "whatever the particle's temperature: a wall's negative `heat_flux` (W/m^2 over the "
         "contact area) or a material's negative `heat_source` (W/kg). Lower it, or give the "
         "wall a `temperature` instead, which cools a particle no further than to the wall's "
         "(docs/models/heat-transfer.md). Without such a flow: the conduction step was beyond "
         "its stability limit (a run with --allow-large-dt); use the time step `grain check` "
         "gives";
    return s.str();
  }
  const char* what = !finite(p.x[i])   ? "position"
                     : !finite(p.v[i]) ? "velocity"
                                       : "angular velocity";
  std::ostringstream s;
  s.precision(9);
  s << "error: step " << step << " (t = " << time << " s): particle " << p.id[i] << " (rank "
    << rank << ") has a non-finite " << what << "; position " << text(p.x[i]) << " m, velocity "
    << text(p.v[i]) << " m/s, angular velocity " << text(p.omega[i]) << " rad/s, force "
    << text(p.force[i]) << " N, torque " << text(p.torque[i]) << " N m. The run stops here. ";
  if (!force_terms.empty())
    s << force_terms
      << ". A ratio dt/limit above 1 is a force term beyond its stability limit; implicit terms "
         "are stable at any dt. ";
  s << "Other causes: a time step too large for the contact stiffness (see `grain check`), "
       "particles inserted deeply overlapping, or a NaN in an input file";
  return s.str();
}

void guard_finite(const Simulation& sim, bool local_bad, const std::string& directory,
                  MPI_Comm comm) {
  if (!non_finite_anywhere(local_bad, comm)) return;
  std::string where;
  try {
    prepare_output_directory(directory);  // a coupled run may not have written any yet
    SnapshotWriter diagnostic(comm, directory, "diagnostic");
    diagnostic.set_material_names(sim.scene().material_names());
    where = "; every particle of this step is in " +
            diagnostic.write(sim.particles(), sim.time(), sim.counters().steps);
  } catch (const OutputError& e) {
    where = std::string("; the diagnostic snapshot could not be written: ") + e.what();
  }
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const std::string mine =
      describe_first_non_finite(sim.particles(), sim.counters().steps, sim.time(), rank,
                                sim.force_limits_summary(), sim.heat() != nullptr);
  agree_on_error(comm, mine.empty() ? mine : mine + where);
}

void guard_finite_after_step(const Simulation& sim, const std::string& directory, MPI_Comm comm) {
  if (sim.state_finite_everywhere()) return;  // the same answer on every rank
  guard_finite(sim, !sim.state_finite(), directory, comm);
}

}  // namespace grainflow
