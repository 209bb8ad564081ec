// The accuracy table grainFoam prints at start-up must be the one the coupled sweeps measured
// (benchmarks/accuracy_cost/coupled/coupled_results.csv), and its interpolation must
// reproduce the measured points.
#include "coupling/accuracy_table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace grainflow::coupling {
namespace {

// Python's csv module ends lines with \r\n.
bool next_line(std::istream& in, std::string& line) {
  if (!std::getline(in, line)) return false;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

std::vector<std::map<std::string, std::string>> read_csv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  next_line(in, line);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string cell; std::getline(hs, cell, ',');) header.push_back(cell);
  std::vector<std::map<std::string, std::string>> rows;
  while (next_line(in, line)) {
    std::stringstream ls(line);
    std::map<std::string, std::string> row;
    std::size_t k = 0;
    for (std::string cell; std::getline(ls, cell, ',') && k < header.size(); ++k) row[header[k]] = cell;
    rows.push_back(row);
  }
  return rows;
}

const std::string kCsv =
    std::string(GRAINFLOW_SOURCE_DIR) + "/benchmarks/accuracy_cost/coupled/coupled_results.csv";

TEST(AccuracyTable, FootprintRowsMatchTheMeasuredCsv) {
  int matched = 0;
  for (const auto& row : read_csv(kCsv)) {
    if (row.at("sweep") != "void_fraction") continue;
    const double ratio = std::stod(row.at("cell_over_d"));
    bool found = false;
    for (const FootprintAccuracy& a : kFootprintAccuracy)
      if (row.at("method") == a.method && row.at("sampling") == a.sampling &&
          std::abs(a.cell_over_d - ratio) < 1e-3) {
        EXPECT_NEAR(a.dp_error, std::stod(row.at("error")), 5e-5) << row.at("case");
        EXPECT_NEAR(a.coupling_share, std::stod(row.at("coupling_s")) / std::stod(row.at("cpu_s")), 5e-4)
            << row.at("case");
        found = true;
      }
    EXPECT_TRUE(found) << row.at("case") << " is missing from kFootprintAccuracy";
    ++matched;
  }
  EXPECT_EQ(matched, static_cast<int>(std::size(kFootprintAccuracy)));
}

TEST(AccuracyTable, IntervalRowsMatchTheMeasuredCsv) {
  int matched = 0;
  for (const auto& row : read_csv(kCsv)) {
    if (row.at("sweep") != "interval_bed") continue;
    const int n = static_cast<int>(std::stod(row.at("steps_per_fluid")));
    for (const IntervalAccuracy& a : kIntervalAccuracy)
      if (a.steps_per_fluid == n) {
        EXPECT_NEAR(a.dp_error, std::stod(row.at("error")), 5e-5);
        ++matched;
      }
  }
  EXPECT_EQ(matched, static_cast<int>(std::size(kIntervalAccuracy)));
}

TEST(AccuracyTable, DescribesMeasuredPointsAndRefusesToExtrapolate) {
  const std::string at = describe_coupled_accuracy("divided", "cell", 2, 20);
  EXPECT_NE(at.find("vs Ergun -7.3 %"), std::string::npos) << at;
  EXPECT_NE(at.find("20 DEM steps per fluid step: packed-bed pressure drop vs Ergun -7.3 %"),
            std::string::npos)
      << at;
  // Half-way between 2 d (-7.26 %) and 3 d (-12.49 %).
  EXPECT_NE(describe_coupled_accuracy("divided", "cell", 2.5, 20).find("-9.9 %"), std::string::npos);
  EXPECT_NE(describe_coupled_accuracy("centre", "cell", 10, 200).find("outside the measured 2-4 d"),
            std::string::npos);
  EXPECT_NE(describe_coupled_accuracy("centre", "cell", 10, 200).find("outside the measured 2-100"),
            std::string::npos);
}

}  // namespace
}  // namespace grainflow::coupling
