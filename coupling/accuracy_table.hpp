#pragma once
// Where a coupled run's settings sit on the measured accuracy-versus-cost curves
// (docs/accuracy-vs-cost-coupled.md), for grainFoam's start-up report. The numbers are copied
// from benchmarks/accuracy_cost/coupled/coupled_results.csv (measured 2026-12-01, branch
// h-coupling; the test tests/coupling/accuracy_table_test.cpp fails if the two disagree).
// C++17.
#include <optional>
#include <string>

namespace grainflow::coupling {

struct FootprintAccuracy {
  const char* method;
  const char* sampling;
  double cell_over_d;     // cell edge / particle diameter
  double dp_error;        // fixed-bed pressure drop against Ergun, relative
  double coupling_share;  // coupling CPU / total CPU
};

struct IntervalAccuracy {
  int steps_per_fluid;  // DEM steps per fluid step
  double dp_error;      // fixed-bed pressure drop against Ergun, relative (2 d cells, divided)
  double cpu_per_second;  // total CPU seconds per simulated second of that bed
};

inline constexpr FootprintAccuracy kFootprintAccuracy[] = {
    {"centre", "cell", 2, -0.1253, 0.040},
    {"centre", "cell", 3, -0.1202, 0.046},
    {"centre", "cell", 4, -0.1123, 0.038},
    {"centre", "cellPoint", 2, -0.1540, 0.039},
    {"centre", "cellPoint", 3, -0.1377, 0.032},
    {"centre", "cellPoint", 4, -0.1428, 0.028},
    {"divided", "cell", 2, -0.0726, 0.103},
    {"divided", "cell", 3, -0.1256, 0.117},
    {"divided", "cell", 4, -0.1163, 0.116},
    {"divided", "cellPoint", 2, -0.0882, 0.105},
    {"divided", "cellPoint", 3, -0.1379, 0.126},
    {"divided", "cellPoint", 4, -0.1424, 0.110},
    {"smoothed", "cell", 2, -0.0807, 0.617},
    {"smoothed", "cell", 3, -0.1262, 0.439},
    {"smoothed", "cell", 4, -0.1205, 0.439},
    {"smoothed", "cellPoint", 2, -0.0926, 0.345},
    {"smoothed", "cellPoint", 3, -0.1378, 0.375},
    {"smoothed", "cellPoint", 4, -0.1444, 0.381},
};

inline constexpr IntervalAccuracy kIntervalAccuracy[] = {
    {2, -0.0555, 301},
    {5, -0.0617, 153},
    {10, -0.0671, 106},
    {20, -0.0726, 81},
    {50, -0.0797, 65},
    {100, -0.0845, 61},
};

// One or two lines: the measured packed-bed error and cost share of this footprint and
// sampling at this cell size (interpolated in cell_over_d within the measured 2-4 d, nothing
// outside it), and of this coupling interval (interpolated in log N within 2-100).
std::string describe_coupled_accuracy(const std::string& method, const std::string& sampling,
                                      double cell_over_d, int steps_per_fluid);

}  // namespace grainflow::coupling
