#pragma once
// Where a coupled run's settings sit on the measured accuracy-versus-cost curves
// (docs/accuracy-vs-cost-coupled.md), for grainFoam's start-up report. The numbers are copied
// from benchmarks/accuracy_cost/coupled/coupled_results.csv (measured 2026-12-07, main; the
// test tests/coupling/accuracy_table_test.cpp fails if the two disagree).
// Each table holds for the case it was measured on (regime, drag law, and the settings it
// kept fixed); a run is quoted a table only when it matches all of them. C++17.
#include <string>

namespace grainflow::coupling {

// The measured cases: a packed bed (3300 beads, eps = 0.41, drag gidaspow) and a lone sphere
// settling in water (drag schiller_naumann).
enum class Regime { packed_bed, single_particle, other };

// A packed bed: more than one particle and a mean void fraction at the particles up to
// 0.5. The bed of the tables has 0.41; random loose packing is about 0.44, so a mean above
// 0.5 is an expanded (fluidised) or dilute suspension, which no table measured.
inline constexpr double kPackedBedMaxVoidFraction = 0.5;
Regime classify_regime(long particles, double mean_void_fraction_at_particles);
const char* regime_name(Regime r);

struct FootprintAccuracy {
  const char* method;
  const char* sampling;
  double cell_over_d;     // cell edge / particle diameter
  double dp_error;        // fixed-bed pressure drop against Ergun, relative
  double coupling_share;  // coupling CPU / total CPU
};

struct IntervalAccuracy {
  int steps_per_fluid;  // DEM steps per fluid step
  double error;         // relative: bed pressure drop vs Ergun, or settling speed vs terminal
  double cpu_per_second;  // total CPU seconds per simulated second of that case
};

// Packed bed, drag gidaspow, 20 DEM steps per fluid step.
inline constexpr const char* kFootprintDrag = "gidaspow";
inline constexpr int kFootprintSteps = 20;
inline constexpr FootprintAccuracy kFootprintAccuracy[] = {
    {"centre", "cell", 2, -0.1224, 0.051},
    {"centre", "cell", 3, -0.1192, 0.060},
    {"centre", "cell", 4, -0.1060, 0.066},
    {"centre", "cellPoint", 2, -0.1552, 0.051},
    {"centre", "cellPoint", 3, -0.1387, 0.045},
    {"centre", "cellPoint", 4, -0.1396, 0.042},
    {"divided", "cell", 2, -0.0656, 0.088},
    {"divided", "cell", 3, -0.1200, 0.108},
    {"divided", "cell", 4, -0.1091, 0.107},
    {"divided", "cellPoint", 2, -0.0829, 0.101},
    {"divided", "cellPoint", 3, -0.1355, 0.089},
    {"divided", "cellPoint", 4, -0.1392, 0.088},
    {"smoothed", "cell", 2, -0.0749, 0.222},
    {"smoothed", "cell", 3, -0.1206, 0.272},
    {"smoothed", "cell", 4, -0.1169, 0.274},
    {"smoothed", "cellPoint", 2, -0.0871, 0.232},
    {"smoothed", "cellPoint", 3, -0.1354, 0.262},
    {"smoothed", "cellPoint", 4, -0.1451, 0.276},
};

// A coupling-interval sweep: the case and the settings it kept fixed.
struct IntervalSweep {
  const char* name;  // for messages
  Regime regime;
  const char* drag;
  const char* method;
  const char* sampling;
  double cell_over_d;
  const char* quantity;  // what the error measures
  const IntervalAccuracy* rows;
  int size;
};

// Packed bed (error: pressure drop vs Ergun).
inline constexpr IntervalAccuracy kIntervalAccuracy[] = {
    {2, -0.0468, 277}, {5, -0.0541, 140}, {10, -0.0599, 100},
    {20, -0.0656, 67}, {50, -0.0728, 55}, {100, -0.0775, 46},
};
// The settlingParticle tutorial (error: mean settling speed vs Schiller-Naumann terminal).
inline constexpr IntervalAccuracy kSettlingIntervalAccuracy[] = {
    {1, 0.01103, 720}, {5, 0.01104, 159}, {10, 0.01106, 85},
    {20, 0.01108, 48}, {50, 0.01119, 21}, {100, 0.01142, 14},
};
inline constexpr IntervalSweep kIntervalSweeps[] = {
    {"packed-bed", Regime::packed_bed, "gidaspow", "divided", "cell", 2, "packed-bed pressure drop vs Ergun",
     kIntervalAccuracy, 6},
    {"settling-sphere", Regime::single_particle, "schiller_naumann", "divided", "cell", 10,
     "settling speed vs Schiller-Naumann terminal", kSettlingIntervalAccuracy, 6},
};

// Cell sizes and ranges are compared with this relative tolerance: a mesh whose cells are
// 4 d up to round-off (4.00000000000002) is at the measured 4 d.
inline constexpr double kRelativeTolerance = 1e-6;

struct CoupledSettings {
  Regime regime = Regime::other;
  double mean_void_fraction = 1;  // at the particles, for the report
  std::string drag;
  std::string method;    // void-fraction footprint
  std::string sampling;  // cell or cellPoint
  double cell_over_d = 0;
  int steps_per_fluid = 1;
  std::string drag_void_fraction = "cell";  // couplingProperties dragVoidFraction
  double diffusion_bandwidth_over_d = 0;    // couplingProperties diffusionBandwidth / mean d
};

// Lines (the first without indentation, the others indented by two spaces) saying what the
// measured tables give for these settings, interpolated within the measured ranges only
// (cell size linearly within 2-4 d, the interval in log N), and plainly when no table
// matches the case and why.
std::string describe_coupled_accuracy(const CoupledSettings& s);

}  // namespace grainflow::coupling
