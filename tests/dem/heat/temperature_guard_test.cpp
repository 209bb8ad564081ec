// The temperature guard (dem/engine/finite_guard.hpp): a fixed heat flow out of a particle is
// not bounded by its temperature, and a run went on to "done" with beads at -16 700 K (a
// floor's heat_flux of -1e13 W/m^2, found by hand). The guard stops the step where a
// temperature is no longer above 0 K, naming the particle and the keys that cause it.
// Reference: the closed form of a constant heat_source, T(t) = T0 + s t / c.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "tests/dem/support/run_scene_text.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

// One bead at 300 K at rest in an empty box, c = 840 J/(kg K), with a heat_source of
// `source` W/kg: dT/dt = source / c exactly (no contact, no fluid), dt = 1e-5 s.
std::string bead(const std::string& source, const std::string& end) {
  return R"(domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.01]}
gravity: [0, 0, 0]
time: {step: 1e-5, end: )" +
         end + R"(}
materials:
  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500, heat_capacity: 840,
     conductivity: 1, heat_source: )" +
         source + R"(}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
heat: {}
insert:
  - {type: csv, file: beads.csv, material: glass, temperature: 300}
output: {progress: false, snapshot_interval: 1e-3}
)";
}

// Twenty beads dropped onto a floor that draws 1e13 W/m^2 out of each contact.
std::string cooled_floor() {
  return R"(domain: {min: [0, 0, 0], max: [0.02, 0.02, 0.04], periodic: [true, true, false]}
gravity: [0, 0, -9.81]
time: {step: 2e-6, end: 0.05, expected_max_speed: 1}
heat: {}
materials:
  - {name: glass, youngs_modulus: 5e7, poisson_ratio: 0.25, density: 2500,
     heat_capacity: 840, conductivity: 1.1}
interaction_defaults: {restitution: 0.5, friction: 0.5}
contact: {normal: hertz, tangential: history}
walls:
  - {type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass,
     heat_flux: -1e13}
insert:
  - {type: fill, region: {box: {min: [0, 0, 0.001], max: [0.02, 0.02, 0.004]}}, count: 20,
     material: glass, radius: {distribution: constant, value: 1e-3}, temperature: 300}
output: {progress: false, snapshot_interval: 0.01}
)";
}

using Outcome = test::SceneOutcome;

Outcome run(const std::string& text, const std::string& name) {
  return test::run_scene_text(text, "temperature_guard", name,
                              "x,y,z,radius\n0.005,0.005,0.005,0.001\n");
}

// s = -8.4e7 W/kg, c = 840: -1e5 K/s, so 300 K is gone after 3 ms, at step 300 (301 when the
// sum of 300 steps of -1 K rounds above 0).
TEST(TemperatureGuard, StopsWhereAHeatSinkTakesTheLastKelvin) {
  const Outcome o = run(bead("-8.4e7", "0.01"), "sink");
  const std::regex stop(R"(error: step (\d+) \(t = [0-9.e-]+ s\): particle 1 \(rank 0\) has a )"
                        R"(temperature of ([-0-9.e]+) K, not above 0 K)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.error, m, stop)) << o.error;
  const long step = std::stol(m[1].str());
  const double temperature = std::stod(m[2].str());
  std::printf("[ measured ] stopped at step %ld with T = %.3g K (closed form: step 300, 0 K)\n",
              step, temperature);
  EXPECT_TRUE(step == 300 || step == 301) << step;
  EXPECT_LE(temperature, 0.0);
  EXPECT_GT(temperature, -1.0 - 1e-9);  // one step's -1 K past 0 at most
  EXPECT_NE(o.error.find("a material's negative `heat_source`"), std::string::npos);
  EXPECT_NE(o.error.find("diagnostic_000000.h5"), std::string::npos) << o.error;
  EXPECT_TRUE(fs::exists(o.out / "diagnostic_000000.h5"));
}

// The advice, "lower it": a tenth of the sink runs 3 ms to the end (the bead at 270 K).
TEST(TemperatureGuard, ALowerSinkRuns) {
  const Outcome o = run(bead("-8.4e6", "0.003"), "lower_sink");
  EXPECT_EQ(o.error, "");
  EXPECT_NE(o.log.find("done: 300 steps"), std::string::npos) << o.log;
}

// The case that ran to "done" at -16 700 K: stopped, naming the wall's heat_flux.
TEST(TemperatureGuard, StopsACooledFloor) {
  const Outcome o = run(cooled_floor(), "cooled_floor");
  EXPECT_NE(o.error.find("K, not above 0 K"), std::string::npos) << o.error;
  EXPECT_NE(o.error.find("a wall's negative `heat_flux`"), std::string::npos);
  EXPECT_EQ(o.log.find("done: "), std::string::npos);
}

}  // namespace
}  // namespace grainflow
