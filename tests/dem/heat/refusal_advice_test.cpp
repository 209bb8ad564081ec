// A step that several start-up limits refuse (docs/models/contact-models.md, "Time-step limits"):
// each error line proposes the step its own limit allows, and the final refusal proposes the
// smallest of them. Reference: the advice itself, rerun. Found by the thermal family of the
// hard-scene generator: a step refused for the contacts and for heat conduction at once, whose
// first error's proposal (the contacts') was refused again for conduction.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/dem/support/run_scene_text.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

// Two touching beads (r = 1 mm, Y = 5 MPa: t_R = 1.22e-4 s) on a floor, and a conductivity
// (1e6 W/(m K), no real solid's) that puts the conduction limit, tau / 12 = m c / (24 k a) =
// 1.04e-6 s, far below the contacts' t_R.
std::string scene(const std::string& step) {
  return R"(domain: {min: [-0.005, -0.005, 0], max: [0.005, 0.005, 0.01]}
gravity: [0, 0, -9.81]
time: {step: )" +
         step + R"(, end: 2e-6}
materials:
  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500, heat_capacity: 840,
     conductivity: 1e6}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
heat: {}
walls:
  - {type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}
insert:
  - {type: csv, file: beads.csv, material: glass, temperature: 300}
output: {progress: false}
)";
}

using Outcome = test::SceneOutcome;

Outcome run(const std::string& step, const std::string& name) {
  return test::run_scene_text(scene(step), "refusal_advice", name,
                              "x,y,z,radius\n0,0,0.001,0.001\n0.002,0,0.001,0.001\n");
}

std::vector<double> proposals(const std::string& text) {
  std::vector<double> out;
  const std::regex use("use dt <= ([0-9.eE+-]+) s");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), use); it != std::sregex_iterator();
       ++it)
    out.push_back(std::stod((*it)[1].str()));
  return out;
}

TEST(RefusalAdvice, TheFinalRefusalProposesAStepEveryLimitAllows) {
  // 1e-4 s = 0.82 t_R, 2.7 steps per impact: refused for the contacts and, far more, for
  // conduction.
  const Outcome refused = run("1e-4", "refused");
  ASSERT_NE(refused.error.find("refusing to run with this time step"), std::string::npos)
      << refused.error;
  ASSERT_NE(refused.log.find("error: dt is too large to resolve contacts"), std::string::npos);
  ASSERT_NE(refused.log.find("beyond the stability limit of heat conduction"), std::string::npos);
  const std::vector<double> each = proposals(refused.log);
  ASSERT_EQ(each.size(), 2u) << refused.log;
  const std::vector<double> final_advice = proposals(refused.error);
  ASSERT_EQ(final_advice.size(), 1u) << refused.error;
  const double smallest = std::min(each[0], each[1]);
  std::printf("[ measured ] proposals %.4g s (contacts), %.4g s (conduction); final %.4g s\n",
              each[0], each[1], final_advice[0]);
  EXPECT_LE(final_advice[0], smallest);
  EXPECT_GE(final_advice[0], 0.99 * smallest);  // rounded down to 3 digits, no further

  // The first error's proposal alone is refused again (the case this test is about) ...
  std::ostringstream first;
  first.precision(17);
  first << each[0];
  const Outcome again = run(first.str(), "first_proposal");
  EXPECT_NE(again.error.find("refusing to run"), std::string::npos);
  // ... and the final one runs to the end.
  std::ostringstream final_step;
  final_step.precision(17);
  final_step << final_advice[0];
  const Outcome ran = run(final_step.str(), "final_proposal");
  EXPECT_EQ(ran.error, "");
  EXPECT_NE(ran.log.find("done: "), std::string::npos) << ran.log;
}

// The steps-per-contact guard in a run that passed the start-up refusal (--allow-large-dt):
// two stiff beads (Y = 5e10 Pa) touching and closing at 2 x 10 m/s, a Hertz contact of
// about 1.5e-6 s against dt = 1e-5 s. Its own proposal, t_c / 20, is far above what heat
// conduction allows at k = 1e9 W/(m K) (about 1e-9 s): the proposal must be a step every
// start-up limit allows, and that step must run without --allow-large-dt. Reference: the advice
// rerun (found by the same reasoning as the travel guard's fault, hard-scene generator thermal seed
// 717).
TEST(RefusalAdvice, TheFirstStepsContactGuardProposesAStepEveryLimitAllows) {
  const auto colliding = [](const std::string& step, const std::string& end,
                            const std::string& name, bool allow_large_step) {
    const std::string text = R"(domain: {min: [-0.005, -0.005, 0], max: [0.005, 0.005, 0.01]}
gravity: [0, 0, 0]
time: {step: )" + step + R"(, end: )" +
                             end +
                             R"(, expected_max_speed: 0.1}
materials:
  - {name: glass, youngs_modulus: 5e10, poisson_ratio: 0.3, density: 2500, heat_capacity: 840,
     conductivity: 1e9}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
heat: {}
insert:
  - {type: csv, file: beads.csv, material: glass, temperature: 300}
output: {progress: false}
)";
    return test::run_scene_text(text, "refusal_advice", name,
                                "x,y,z,radius,vx,vy,vz\n-0.001,0,0.005,0.001,10,0,0\n"
                                "0.001,0,0.005,0.001,-10,0,0\n",
                                allow_large_step);
  };
  // --allow-large-dt: past the start-up refusal (which a plain run reports first), to the
  // guard in the first step.
  const Outcome stopped = colliding("1e-5", "1e-4", "contact_guard", true);
  ASSERT_NE(stopped.error.find("key time.min_steps_per_contact"), std::string::npos)
      << stopped.error;
  const std::regex at_most("A step of at most ([0-9.eE+-]+) s would");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(stopped.error, m, at_most)) << stopped.error;
  const double proposed = std::stod(m[1].str());
  std::printf("[ measured ] the guard proposes %.4g s\n", proposed);
  EXPECT_NE(stopped.error.find("heat conduction"), std::string::npos) << stopped.error;
  // The proposal, rerun for ten steps: past the start-up checks and the first steps.
  std::ostringstream step, end;
  step.precision(17);
  step << proposed;
  end.precision(17);
  end << 10 * proposed;
  const Outcome ran = colliding(step.str(), end.str(), "contact_guard_advised", false);
  EXPECT_EQ(ran.error, "");
  EXPECT_NE(ran.log.find("done: "), std::string::npos) << ran.log;
}

}  // namespace
}  // namespace grainflow
