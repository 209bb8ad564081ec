#pragma once
// Where a coupled run's settings sit on the measured accuracy-versus-cost curves
// (docs/accuracy-vs-cost-coupled.md), for grainFoam's start-up report. The numbers are copied
// from benchmarks/accuracy_cost/coupled/coupled_results.csv (measured 2026-11-23; the test
// tests/coupling/accuracy_table_test.cpp fails if the two disagree). C++17.
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
    {"centre", "cell", 2, -0.1408, 0.053},
    {"centre", "cell", 3, -0.1230, 0.055},
    {"centre", "cell", 4, -0.1120, 0.046},
    {"centre", "cellPoint", 2, -0.1713, 0.367},
    {"centre", "cellPoint", 3, -0.1398, 0.476},
    {"centre", "cellPoint", 4, -0.1414, 0.453},
    {"divided", "cell", 2, -0.0726, 0.200},
    {"divided", "cell", 3, -0.1249, 0.201},
    {"divided", "cell", 4, -0.1169, 0.177},
    {"divided", "cellPoint", 2, -0.0888, 0.437},
    {"divided", "cellPoint", 3, -0.1374, 0.430},
    {"divided", "cellPoint", 4, -0.1425, 0.402},
    {"smoothed", "cell", 2, -0.0812, 0.505},
    {"smoothed", "cell", 3, -0.1264, 0.576},
    {"smoothed", "cell", 4, -0.1213, 0.678},
    {"smoothed", "cellPoint", 2, -0.0926, 0.705},
    {"smoothed", "cellPoint", 3, -0.1375, 0.770},
    {"smoothed", "cellPoint", 4, -0.1451, 0.759},
};

inline constexpr IntervalAccuracy kIntervalAccuracy[] = {
    {2, -0.0553, 344},
    {5, -0.0617, 183},
    {10, -0.0670, 126},
    {20, -0.0726, 100},
    {50, -0.0799, 82},
    {100, -0.0847, 72},
};

// One or two lines: the measured packed-bed error and cost share of this footprint and
// sampling at this cell size (interpolated in cell_over_d within the measured 2-4 d, nothing
// outside it), and of this coupling interval (interpolated in log N within 2-100).
std::string describe_coupled_accuracy(const std::string& method, const std::string& sampling,
                                      double cell_over_d, int steps_per_fluid);

}  // namespace grainflow::coupling
