// Scene parser: every valid key lands in the Scene, and every category of user
// mistake is reported once, as a SceneError whose file:line:column points at the
// offending key or value and whose text says what was wrong and what is allowed.
#include "dem/scene/scene_parser.hpp"
#include "dem/io/xdmf_index.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace grainflow {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

const std::string kScenes = std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes";
// A label inside tests/data/scenes so relative CSV names resolve to real files.
const std::string kLabel = kScenes + "/inline.yaml";

// A valid scene; each error test breaks one thing in it. Line numbers below are
// 1-based lines of this text.
const std::string kBase =
    "domain:\n"                        // 1
    "  min: [0, 0, 0]\n"               // 2
    "  max: [1, 1, 1]\n"               // 3
    "time:\n"                          // 4
    "  step: 1e-6\n"                   // 5
    "  end: 0.5\n"                     // 6
    "materials:\n"                     // 7
    "  - name: glass\n"                // 8
    "    youngs_modulus: 5e6\n"        // 9
    "    poisson_ratio: 0.3\n"         // 10
    "    density: 2500\n"              // 11
    "interactions:\n"                  // 12
    "  - materials: [glass, glass]\n"  // 13
    "    restitution: 0.9\n"           // 14
    "contact:\n"                       // 15
    "  normal: hertz\n";               // 16

// kBase with the first occurrence of `from` replaced by `to` (which must exist).
std::string with(const std::string& from, const std::string& to, std::string text = kBase) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the base scene";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Parses `text`, expecting a SceneError; returns it (or a marker error if none came).
SceneError error_of(const std::string& text) {
  try {
    parse_scene(text, kLabel);
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "expected a SceneError for:\n" << text;
  return SceneError("none", -1, -1, "no error thrown");
}

// Checks position and the start of what(), returns the message for substring checks.
std::string expect_at(const SceneError& e, int line, int column) {
  EXPECT_EQ(e.file(), kLabel);
  EXPECT_EQ(e.line(), line) << e.what();
  EXPECT_EQ(e.column(), column) << e.what();
  const std::string prefix =
      kLabel + ":" + std::to_string(line) + ":" + std::to_string(column) + ": error: ";
  EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << e.what();
  return e.what();
}

// ---------------------------------------------------------------------------
// Valid scenes

TEST(SceneParser, BaseSceneIsValidAndTakesDefaults) {
  const Scene s = parse_scene(kBase, kLabel);
  EXPECT_EQ(s.file, kLabel);
  EXPECT_EQ(s.domain.lo, Vec3(0, 0, 0));
  EXPECT_EQ(s.domain.hi, Vec3(1, 1, 1));
  EXPECT_EQ(s.domain.periodic, (std::array<bool, 3>{false, false, false}));
  EXPECT_EQ(s.gravity, Vec3::Zero());
  ASSERT_TRUE(s.time.step.has_value());
  EXPECT_DOUBLE_EQ(*s.time.step, 1e-6);
  EXPECT_FALSE(s.time.rayleigh_fraction.has_value());
  EXPECT_DOUBLE_EQ(s.time.end, 0.5);
  EXPECT_DOUBLE_EQ(s.time.expected_max_speed, 1.0);
  EXPECT_DOUBLE_EQ(s.time.max_overlap, 0.25);
  EXPECT_DOUBLE_EQ(s.time.min_steps_per_contact, 5.0);  // grain check's refusal threshold
  EXPECT_DOUBLE_EQ(s.time.max_step_travel, 1.0);        // radii per step (docs/stability.md)
  ASSERT_EQ(s.pairs.size(), 1u);
  EXPECT_DOUBLE_EQ(s.pairs[0].restitution, 0.9);
  EXPECT_DOUBLE_EQ(s.pairs[0].friction, 0.5);
  EXPECT_DOUBLE_EQ(s.pairs[0].rolling_friction, 0.0);
  EXPECT_DOUBLE_EQ(s.pairs[0].cohesion_energy_density, 0.0);
  EXPECT_EQ(s.contact.normal, NormalModel::hertz);
  EXPECT_EQ(s.contact.tangential, TangentialModel::history);
  EXPECT_EQ(s.contact.rolling, RollingModel::none);
  EXPECT_EQ(s.contact.cohesion, CohesionModel::none);
  EXPECT_FALSE(s.contact.hooke_characteristic_velocity || s.contact.hooke_kn || s.contact.hooke_kt);
  EXPECT_DOUBLE_EQ(s.contact.epsd_damping_ratio, 0.3);
  EXPECT_FALSE(s.neighbour.skin.has_value());
  EXPECT_TRUE(s.walls.empty());
  EXPECT_TRUE(s.insertions.empty());
  EXPECT_EQ(s.output.directory, "output");
  EXPECT_FALSE(s.output.snapshot_interval || s.output.log_interval);
  EXPECT_TRUE(s.output.progress);
}

TEST(SceneParser, CompleteSceneFillsEveryField) {
  const std::string path = kScenes + "/complete.yaml";
  const Scene s = load_scene(path);
  EXPECT_EQ(s.file, path);

  EXPECT_EQ(s.domain.lo, Vec3(-0.06, -0.06, -0.06));
  EXPECT_EQ(s.domain.hi, Vec3(0.06, 0.06, 0.06));
  EXPECT_EQ(s.domain.periodic, (std::array<bool, 3>{true, false, false}));
  EXPECT_EQ(s.gravity, Vec3(0, 0, -9.81));

  EXPECT_FALSE(s.time.step.has_value());
  ASSERT_TRUE(s.time.rayleigh_fraction.has_value());
  EXPECT_DOUBLE_EQ(*s.time.rayleigh_fraction, 0.005);
  EXPECT_DOUBLE_EQ(s.time.end, 0.05);
  EXPECT_DOUBLE_EQ(s.time.expected_max_speed, 2.0);

  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[0].name, "glass");
  EXPECT_DOUBLE_EQ(s.materials[0].youngs_modulus, 5e6);
  EXPECT_DOUBLE_EQ(s.materials[0].poisson_ratio, 0.3);
  EXPECT_DOUBLE_EQ(s.materials[0].density, 2500);
  EXPECT_EQ(s.materials[1].name, "steel");
  EXPECT_DOUBLE_EQ(s.materials[1].youngs_modulus, 2e8);
  EXPECT_DOUBLE_EQ(s.materials[1].poisson_ratio, 0.29);
  EXPECT_DOUBLE_EQ(s.materials[1].density, 7800);
  EXPECT_EQ(s.materials[2].name, "rubber");
  EXPECT_EQ(s.material_index("steel"), 1);
  EXPECT_EQ(s.material_index("rubber"), 2);
  EXPECT_EQ(s.material_index("wood"), -1);

  // Complete table: 3 materials -> 6 unordered pairs, each a <= b, each once.
  ASSERT_EQ(s.pairs.size(), 6u);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const MaterialPair& p = s.pair(a, b);
      EXPECT_EQ(p.a, std::min(a, b));
      EXPECT_EQ(p.b, std::max(a, b));
      EXPECT_EQ(&p, &s.pair(b, a)) << "lookup must be symmetric";
    }
  for (const MaterialPair& p : s.pairs) EXPECT_LE(p.a, p.b);
  const MaterialPair& gg = s.pair(0, 0);
  EXPECT_DOUBLE_EQ(gg.restitution, 0.9);
  EXPECT_DOUBLE_EQ(gg.friction, 0.4);
  EXPECT_DOUBLE_EQ(gg.rolling_friction, 0.01);
  EXPECT_DOUBLE_EQ(gg.cohesion_energy_density, 1000);
  const MaterialPair& gs = s.pair(1, 0);  // listed as [steel, glass]
  EXPECT_DOUBLE_EQ(gs.restitution, 0.8);
  EXPECT_DOUBLE_EQ(gs.friction, 0.3);
  EXPECT_DOUBLE_EQ(gs.rolling_friction, 0.0);  // entry default, not interaction_defaults
  for (const auto& [a, b] : {std::pair{0, 2}, std::pair{1, 1}, std::pair{1, 2}, std::pair{2, 2}}) {
    const MaterialPair& d = s.pair(a, b);  // unlisted: interaction_defaults
    EXPECT_DOUBLE_EQ(d.restitution, 0.5);
    EXPECT_DOUBLE_EQ(d.friction, 0.6);
    EXPECT_DOUBLE_EQ(d.rolling_friction, 0.02);
    EXPECT_DOUBLE_EQ(d.cohesion_energy_density, 0.0);
  }

  EXPECT_EQ(s.contact.normal, NormalModel::hooke);
  EXPECT_EQ(s.contact.tangential, TangentialModel::history);
  EXPECT_EQ(s.contact.rolling, RollingModel::epsd);
  EXPECT_EQ(s.contact.cohesion, CohesionModel::sjkr);
  EXPECT_FALSE(s.contact.hooke_characteristic_velocity.has_value());
  EXPECT_EQ(s.contact.hooke_kn, 1e4);
  EXPECT_EQ(s.contact.hooke_kt, 8e3);
  EXPECT_DOUBLE_EQ(s.contact.epsd_damping_ratio, 0.25);
  EXPECT_EQ(s.neighbour.skin, 0.0005);

  ASSERT_EQ(s.walls.size(), 2u);
  const Wall& floor = s.walls[0];
  EXPECT_EQ(floor.kind, Wall::Kind::plane);
  EXPECT_EQ(floor.name, "floor");
  EXPECT_EQ(floor.material, 1);
  EXPECT_EQ(floor.plane.point, Vec3(0, 0, -0.045));
  EXPECT_EQ(floor.plane.normal, Vec3(0, 0, 1)) << "normal [0, 0, 2] is normalised";
  const Wall& drum = s.walls[1];
  EXPECT_EQ(drum.kind, Wall::Kind::cylinder);
  EXPECT_EQ(drum.name, "drum");
  EXPECT_EQ(drum.material, 1);
  EXPECT_EQ(drum.cylinder.axis_point, Vec3::Zero());
  EXPECT_EQ(drum.cylinder.axis, Vec3(1, 0, 0)) << "axis [3, 0, 0] is normalised";
  EXPECT_DOUBLE_EQ(drum.cylinder.radius, 0.05);
  EXPECT_TRUE(drum.cylinder.inside);
  EXPECT_DOUBLE_EQ(drum.cylinder.angular_velocity, 3.0);

  ASSERT_EQ(s.insertions.size(), 3u);
  const Insertion& box = s.insertions[0];
  EXPECT_EQ(box.kind, Insertion::Kind::fill);
  EXPECT_EQ(box.source, path + ":46");
  EXPECT_EQ(box.region.kind, Region::Kind::box);
  EXPECT_EQ(box.region.lo, Vec3(-0.025, -0.025, -0.035));
  EXPECT_EQ(box.region.hi, Vec3(0.025, 0.025, 0));
  EXPECT_EQ(box.count, 1000);
  EXPECT_FALSE(box.volume_fraction.has_value());
  EXPECT_EQ(box.material, 0);
  EXPECT_EQ(box.radius.kind, SizeDistribution::Kind::discrete);
  EXPECT_EQ(box.radius.values, (std::vector<double>{1e-3, 2e-3}));
  ASSERT_EQ(box.radius.weights.size(), 2u);
  EXPECT_DOUBLE_EQ(box.radius.weights[0], 0.75) << "weights [3, 1] normalise to sum 1";
  EXPECT_DOUBLE_EQ(box.radius.weights[1], 0.25);
  EXPECT_EQ(box.velocity, Vec3(0, 0, -0.5));
  EXPECT_EQ(box.seed, 42u);

  const Insertion& cyl = s.insertions[1];
  EXPECT_EQ(cyl.source, path + ":53");
  EXPECT_EQ(cyl.region.kind, Region::Kind::cylinder);
  EXPECT_EQ(cyl.region.base, Vec3(0, 0, 0.005));
  EXPECT_EQ(cyl.region.axis, Vec3(0, 0, 1));
  EXPECT_DOUBLE_EQ(cyl.region.radius, 0.02);
  EXPECT_DOUBLE_EQ(cyl.region.height, 0.03);
  EXPECT_FALSE(cyl.count.has_value());
  EXPECT_EQ(cyl.volume_fraction, 0.3);
  EXPECT_EQ(cyl.material, 2);
  EXPECT_EQ(cyl.radius.kind, SizeDistribution::Kind::normal);
  EXPECT_DOUBLE_EQ(cyl.radius.mean, 1e-3);
  EXPECT_DOUBLE_EQ(cyl.radius.stddev, 1e-4);
  EXPECT_DOUBLE_EQ(cyl.radius.min, 7e-4) << "default truncation mean - 3 stddev";
  EXPECT_DOUBLE_EQ(cyl.radius.max, 1.3e-3) << "default truncation mean + 3 stddev";
  EXPECT_EQ(cyl.velocity, Vec3::Zero());
  EXPECT_EQ(cyl.seed, 2u) << "default seed 1 + its index in insert";

  const Insertion& csv = s.insertions[2];
  EXPECT_EQ(csv.kind, Insertion::Kind::csv);
  EXPECT_EQ(csv.source, path + ":58");
  EXPECT_EQ(std::filesystem::path(csv.csv_file),
            std::filesystem::path(kScenes) / "complete_particles.csv");
  EXPECT_TRUE(std::filesystem::exists(csv.csv_file));
  EXPECT_EQ(csv.material, 0);

  EXPECT_EQ(s.output.directory, "out/drum");
  EXPECT_EQ(s.output.snapshot_interval, 0.01);
  EXPECT_EQ(s.output.log_interval, 0.001);
  EXPECT_FALSE(s.output.progress);
}

TEST(SceneParser, MinimalExampleIsValid) {
  const Scene s = load_scene(kScenes + "/minimal.yaml");
  EXPECT_EQ(s.insertions.at(0).radius.kind, SizeDistribution::Kind::uniform);
  EXPECT_DOUBLE_EQ(s.insertions[0].radius.min, 4e-4);
  EXPECT_DOUBLE_EQ(s.insertions[0].radius.max, 6e-4);
  EXPECT_EQ(s.insertions[0].count, 500);
}

// One particle and no walls: nothing can touch, so the contact law, the interactions and the
// elastic constants may be left out; a second particle, a wall or a Rayleigh step needs them.
const std::string kLoneBead =
    "domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.05], periodic: [true, true, true]}\n"  // 1
    "time: {step: 1e-4, end: 0.01}\n"                                                    // 2
    "materials:\n"                                                                       // 3
    "  - {name: glass, density: 2500}\n"                                                 // 4
    "insert:\n"                                                                          // 5
    "  - type: fill\n"                                                                   // 6
    "    region: {box: {min: [0, 0, 0], max: [0.01, 0.01, 0.05]}}\n"                     // 7
    "    count: 1\n"                                                                     // 8
    "    material: glass\n"                                                              // 9
    "    radius: {distribution: constant, value: 3e-4}\n";                               // 10

TEST(SceneParser, ContactKeysMayBeLeftOutWhenNothingCanTouch) {
  const Scene lone = parse_scene(kLoneBead, kLabel);
  EXPECT_FALSE(lone.contacts_possible);
  EXPECT_EQ(lone.materials.at(0).youngs_modulus, 0.0);
  EXPECT_EQ(lone.materials.at(0).density, 2500.0);
  const Scene file = load_scene(kScenes + "/fluid/lone_bead.yaml");
  EXPECT_FALSE(file.contacts_possible);
  // Every complete scene with several particles or walls can touch.
  EXPECT_TRUE(load_scene(kScenes + "/minimal.yaml").contacts_possible);
}

TEST(SceneErrors, ContactKeysAreRequiredWhenParticlesCanTouch) {
  // Two particles: the first key left out is named where it belongs.
  const std::string two =
      expect_at(error_of(with("    count: 1\n", "    count: 2\n", kLoneBead)), 4, 5);
  EXPECT_THAT(two, HasSubstr("missing required key 'youngs_modulus' in materials[0]"));
  // A wall, with the elastic constants given: the interactions, then the contact law.
  const std::string elastic =
      "  - {name: glass, density: 2500, youngs_modulus: 5e6, poisson_ratio: 0.3}\n";
  const std::string with_wall =
      with("periodic: [true, true, true]", "periodic: [true, true, false]",
           with("  - {name: glass, density: 2500}\n", elastic, kLoneBead)) +
      "walls:\n  - {type: plane, name: floor, point: [0, 0, 0], normal: "
      "[0, 0, 1], material: glass}\n";
  const std::string pairs = error_of(with_wall).what();
  EXPECT_THAT(pairs, HasSubstr("no interaction properties for material pair (glass, glass)"));
  const std::string law = error_of(with_wall + "interaction_defaults: {restitution: 0.5}\n").what();
  EXPECT_THAT(law, HasSubstr("missing required key 'contact' in the top level"));
  // The Rayleigh time needs the elastic constants even when nothing can touch.
  const std::string rayleigh =
      expect_at(error_of(with("time: {step: 1e-4, end: 0.01}",
                              "time: {rayleigh_fraction: 0.2, end: 0.01}", kLoneBead)),
                2, 8);
  EXPECT_THAT(rayleigh, HasSubstr("the Rayleigh time needs youngs_modulus and poisson_ratio of "
                                  "material 'glass'"));
  EXPECT_THAT(rayleigh, HasSubstr("give `step: <s>` instead"));
}

TEST(SceneParser, HookeCharacteristicVelocityAndConstantRadius) {
  const Scene s = parse_scene(with("  normal: hertz\n",
                                   "  normal: hooke\n"
                                   "  hooke: {characteristic_velocity: 1.5}\n"
                                   "insert:\n"
                                   "  - type: fill\n"
                                   "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
                                   "    count: 10\n"
                                   "    material: glass\n"
                                   "    radius: {distribution: constant, value: 1e-3}\n"),
                              kLabel);
  EXPECT_EQ(s.contact.hooke_characteristic_velocity, 1.5);
  EXPECT_FALSE(s.contact.hooke_kn || s.contact.hooke_kt);
  EXPECT_EQ(s.insertions.at(0).radius.kind, SizeDistribution::Kind::constant);
  EXPECT_DOUBLE_EQ(s.insertions[0].radius.value, 1e-3);
  EXPECT_EQ(s.insertions[0].source, kLabel + ":19");
}

// `radius: 1e-3`, a plain number, is the constant distribution; anything else that is not a
// distribution map names both forms.
TEST(SceneParser, APlainNumberIsAConstantRadius) {
  const auto scene = [](const std::string& radius) {
    return kBase +
           "insert:\n"
           "  - type: fill\n"
           "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
           "    count: 10\n"
           "    material: glass\n"
           "    radius: " +
           radius + "\n";
  };
  const Scene s = parse_scene(scene("1e-3"), kLabel);
  EXPECT_EQ(s.insertions.at(0).radius.kind, SizeDistribution::Kind::constant);
  EXPECT_EQ(s.insertions[0].radius.value, 1e-3);
  EXPECT_THAT(expect_at(error_of(scene("-1e-3")), 22, 13),
              HasSubstr("insert[0].radius: value -1e-3 is out of range; it must be > 0"));
  for (const char* wrong : {"uniform", "[4e-4, 6e-4]", "''"})
    EXPECT_THAT(expect_at(error_of(scene(wrong)), 22, 13),
                HasSubstr("insert[0].radius: expected a radius in m (such as 5e-4) or a size "
                          "distribution ({distribution: constant, uniform, normal or discrete"))
        << wrong;
}

// A wall's name becomes log.csv's column names (<name>_load_x_N) and a material's a cell of
// particle CSV files: a comma, quote or line break in either would shift every column after
// it for every CSV reader, so they are refused naming the character.
TEST(SceneParser, NamesThatWouldBreakCsvColumnsAreRefused) {
  const std::string wall =
      kBase +
      "walls:\n  - {type: plane, name: \"floor, main\", point: [0, 0, 0], normal: [0, "
      "0, 1], material: glass}\n";
  EXPECT_THAT(error_of(wall).what(),
              HasSubstr("walls[0].name: wall name 'floor, main' holds a comma (at character 6), "
                        "which would break the columns of log.csv"));
  EXPECT_THAT(error_of(with("name: glass", "name: \"gl\\nass\"")).what(),
              HasSubstr("holds a line break (at character 3)"));
  EXPECT_THAT(error_of(with("name: glass", "name: 'gl\"ass'")).what(),
              HasSubstr("holds a double quote (at character 3)"));
  // Spaces and other punctuation stay allowed.
  std::string spaced = wall;
  spaced.replace(spaced.find("floor, main"), 11, "floor main-1.5");
  EXPECT_EQ(parse_scene(spaced, kLabel).walls.at(0).name, "floor main-1.5");
}

TEST(SceneParser, NormalDistributionLowerBoundIsClippedPositive) {
  const Scene s = parse_scene(kBase +
                                  "insert:\n"
                                  "  - type: fill\n"
                                  "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
                                  "    volume_fraction: 0.1\n"
                                  "    material: glass\n"
                                  "    radius: {distribution: normal, mean: 1e-3, stddev: 5e-4}\n",
                              kLabel);
  // mean - 3 stddev < 0, so the default lower bound is clipped to mean / 10.
  EXPECT_DOUBLE_EQ(s.insertions.at(0).radius.min, 1e-4);
  EXPECT_DOUBLE_EQ(s.insertions[0].radius.max, 2.5e-3);
}

TEST(SceneParser, DiscreteWithoutWeightsIsUniformInNumber) {
  const Scene s = parse_scene(
      kBase +
          "insert:\n"
          "  - type: fill\n"
          "    region: {cylinder: {base: [0.5, 0.5, 0], axis: [0, 0, 1], radius: 0.5, height: 1}}\n"
          "    count: 3\n"
          "    material: glass\n"
          "    radius: {distribution: discrete, values: [1e-3, 2e-3, 3e-3, 4e-3]}\n",
      kLabel);
  EXPECT_EQ(s.insertions.at(0).radius.weights, (std::vector<double>{0.25, 0.25, 0.25, 0.25}));
}

TEST(SceneParser, PairLookupWorksOnHandBuiltTables) {
  Scene s;
  s.materials = {{"a", 1, 0.3, 1}, {"b", 1, 0.3, 1}};
  s.pairs = {{1, 1, 0.1}, {0, 1, 0.2}, {0, 0, 0.3}};  // not in canonical order
  EXPECT_DOUBLE_EQ(s.pair(1, 0).restitution, 0.2);
  EXPECT_DOUBLE_EQ(s.pair(0, 0).restitution, 0.3);
  EXPECT_DOUBLE_EQ(s.pair(1, 1).restitution, 0.1);
}

// ---------------------------------------------------------------------------
// Errors, one category per test

TEST(SceneErrors, UnknownKeyListsAllowedKeys) {
  const std::string msg = expect_at(error_of(with("density: 2500", "densty: 2500")), 11, 5);
  EXPECT_THAT(msg, AllOf(HasSubstr("unknown key 'densty' in materials[0]"),
                         HasSubstr("allowed keys: name, youngs_modulus, poisson_ratio, density"),
                         HasSubstr("did you mean 'density'?")));

  const std::string top = expect_at(error_of(kBase + "gravty: [0, 0, -9.81]\n"), 17, 1);
  EXPECT_THAT(top, AllOf(HasSubstr("unknown key 'gravty' in the top level"),
                         HasSubstr("allowed keys: domain, gravity, time, materials, interactions, "
                                   "interaction_defaults, contact, neighbour, walls, insert, "
                                   "output")));

  // Allowed keys depend on the kind of entry.
  const std::string wall =
      expect_at(error_of(kBase + "walls:\n  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], "
                                 "radius: 1, material: glass}\n"),
                18, 56);
  EXPECT_THAT(wall, AllOf(HasSubstr("unknown key 'radius' in walls[0] (a plane wall)"),
                          HasSubstr("allowed keys: type, name, point, normal, material")));
}

TEST(SceneErrors, DuplicateKey) {
  const std::string msg =
      expect_at(error_of(with("  end: 0.5\n", "  end: 0.5\n  end: 0.7\n")), 7, 3);
  EXPECT_THAT(msg, AllOf(HasSubstr("key 'end' is given twice in time (first at line 6)"),
                         HasSubstr("keep only one")));
}

TEST(SceneErrors, WrongTypeNumber) {
  const std::string msg = expect_at(error_of(with("density: 2500", "density: abc")), 11, 14);
  EXPECT_THAT(msg, AllOf(HasSubstr("materials[0].density: expected a number, got 'abc'")));
}

TEST(SceneErrors, WrongTypeVector) {
  const std::string short_list = expect_at(error_of(with("max: [1, 1, 1]", "max: [1, 1]")), 3, 8);
  EXPECT_THAT(short_list,
              AllOf(HasSubstr("domain.max: expected a list of 3 numbers, got a list of 2"),
                    HasSubstr("[x, y, z]")));

  // A bad element is pointed at directly.
  const std::string element = expect_at(error_of(kBase + "gravity: [0, 0, down]\n"), 17, 17);
  EXPECT_THAT(element, HasSubstr("gravity: expected a list of 3 numbers, but item 3 is 'down'"));

  const std::string scalar = expect_at(error_of(kBase + "gravity: -9.81\n"), 17, 10);
  EXPECT_THAT(scalar, HasSubstr("gravity: expected a list of 3 numbers, got '-9.81'"));
}

// A YAML alias carries its anchor's position; the error points where the alias is used (the
// key, or the list holding it), where the wrong value entered, not at the anchor.
TEST(SceneErrors, AnAliasOfTheWrongTypeIsReportedWhereItIsUsed) {
  const std::string base = with("  max: [1, 1, 1]\n", "  max: &top [1, 1, 1]\n");
  const std::string end = expect_at(error_of(with("  end: 0.5\n", "  end: *top\n", base)), 6, 3);
  EXPECT_THAT(end, HasSubstr("time.end: expected a number, got a list of 3"));

  const std::string item = expect_at(
      error_of(with("density: 2500", "density: &rho 2500",
                    with("materials: [glass, glass]", "materials: [glass, *rho]", kBase))),
      13, 16);
  EXPECT_THAT(item, HasSubstr("interactions[0].materials"));

  // An alias of the right type is read as its anchor's value.
  const Scene s = parse_scene(
      with("  step: 1e-6\n", "  step: &dt 1e-6\n", with("  end: 0.5\n", "  end: *dt\n")), kLabel);
  EXPECT_EQ(s.time.end, 1e-6);
}

TEST(SceneErrors, WrongTypeSectionAndList) {
  const std::string map =
      expect_at(error_of(with("time:\n  step: 1e-6\n  end: 0.5\n", "time: 0.5\n")), 4, 7);
  EXPECT_THAT(map, HasSubstr("time: expected a map of keys, got '0.5'"));

  const std::string list = expect_at(error_of(kBase + "walls: {type: plane}\n"), 17, 8);
  EXPECT_THAT(list, HasSubstr("walls: expected a list, got a map"));
}

TEST(SceneErrors, MissingRequiredKeyNamesKeyAndParent) {
  const std::string in_item = expect_at(error_of(with("    density: 2500\n", "")), 8, 5);
  EXPECT_THAT(in_item, AllOf(HasSubstr("missing required key 'density' in materials[0]"),
                             HasSubstr("add `density: <number>` with a value > 0")));

  const std::string in_section = expect_at(error_of(with("  end: 0.5\n", "")), 4, 1);
  EXPECT_THAT(in_section, HasSubstr("missing required key 'end' in time"));

  const std::string top = expect_at(error_of(with("contact:\n  normal: hertz\n", "")), 1, 1);
  EXPECT_THAT(top, HasSubstr("missing required key 'contact' in the top level"));

  const std::string empty_value =
      expect_at(error_of(with("  normal: hertz\n", "  normal:\n")), 16, 3);
  EXPECT_THAT(empty_value, HasSubstr("contact.normal: expected a normal contact model name, got "
                                     "nothing; allowed: hertz, hooke"));
}

TEST(SceneErrors, ValueOutOfRangeStatesRangeAndValue) {
  const std::string poisson =
      expect_at(error_of(with("poisson_ratio: 0.3", "poisson_ratio: 0.5")), 10, 20);
  EXPECT_THAT(poisson,
              HasSubstr("materials[0].poisson_ratio: value 0.5 is out of range; it must be "
                        "in (-1, 0.5)"));

  const std::string e_high =
      expect_at(error_of(with("restitution: 0.9", "restitution: 1.5")), 14, 18);
  EXPECT_THAT(e_high,
              HasSubstr("interactions[0].restitution: value 1.5 is out of range; it must be "
                        "in (0, 1]"));
  const std::string e_zero =
      expect_at(error_of(with("restitution: 0.9", "restitution: 0")), 14, 18);
  EXPECT_THAT(e_zero, HasSubstr("value 0 is out of range; it must be in (0, 1]"));

  const std::string radius =
      expect_at(error_of(kBase + "insert:\n"
                                 "  - type: fill\n"
                                 "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
                                 "    count: 10\n"
                                 "    material: glass\n"
                                 "    radius: {distribution: constant, value: -1e-3}\n"),
                22, 45);
  EXPECT_THAT(radius,
              HasSubstr("insert[0].radius.value: value -1e-3 is out of range; it must be > 0"));

  const std::string steps =
      expect_at(error_of(with("end: 0.5", "end: 0.5\n  min_steps_per_contact: -1")), 7, 26);
  EXPECT_THAT(steps, HasSubstr("time.min_steps_per_contact: value -1 is out of range; it must "
                               "be >= 0"));
  EXPECT_DOUBLE_EQ(parse_scene(with("end: 0.5", "end: 0.5\n  min_steps_per_contact: 0"), kLabel)
                       .time.min_steps_per_contact,
                   0.0);  // 0 turns the steps-per-contact guard off
  const std::string travel =
      expect_at(error_of(with("end: 0.5", "end: 0.5\n  max_step_travel: -0.5")), 7, 20);
  EXPECT_THAT(travel, HasSubstr("time.max_step_travel: value -0.5 is out of range; it must be "
                                ">= 0"));
  EXPECT_DOUBLE_EQ(
      parse_scene(with("end: 0.5", "end: 0.5\n  max_step_travel: 0"), kLabel).time.max_step_travel,
      0.0);  // 0 turns the travel guard off

  const std::string end = expect_at(error_of(with("end: 0.5", "end: 0")), 6, 8);
  EXPECT_THAT(end, HasSubstr("time.end: value 0 is out of range; it must be > 0"));

  const std::string box = expect_at(error_of(with("max: [1, 1, 1]", "max: [1, -1, 1]")), 3, 12);
  EXPECT_THAT(box, HasSubstr("domain.max[1]: value -1 is not greater than domain.min[1] = 0"));
}

TEST(SceneErrors, UnknownModelNameListsModels) {
  const std::string msg = expect_at(error_of(with("normal: hertz", "normal: hertzz")), 16, 11);
  EXPECT_THAT(msg, AllOf(HasSubstr("contact.normal: unknown normal contact model 'hertzz'"),
                         HasSubstr("allowed: hertz, hooke"), HasSubstr("did you mean 'hertz'?")));

  const std::string rolling = expect_at(error_of(kBase + "  rolling: friction\n"), 17, 12);
  EXPECT_THAT(rolling, HasSubstr("unknown rolling resistance model 'friction'; allowed: none, cdt, "
                                 "epsd"));

  const std::string dashpot = expect_at(error_of(kBase + "  dashpot_velocity: end\n"), 17, 21);
  EXPECT_THAT(dashpot, HasSubstr("contact.dashpot_velocity: unknown dashpot velocity 'end'; "
                                 "allowed: half_step, predicted"));
}

TEST(SceneContact, DashpotVelocityDefaultsToHalfStep) {
  EXPECT_EQ(parse_scene(kBase, kLabel).contact.dashpot_velocity, DashpotVelocity::half_step);
  EXPECT_EQ(parse_scene(kBase + "  dashpot_velocity: predicted\n", kLabel).contact.dashpot_velocity,
            DashpotVelocity::predicted);
}

TEST(SceneErrors, UnknownMaterialReferenceListsKnownNames) {
  const std::string msg = expect_at(error_of(with("[glass, glass]", "[glass, glas]")), 13, 24);
  EXPECT_THAT(msg, AllOf(HasSubstr("interactions[0].materials[1]: unknown material 'glas'"),
                         HasSubstr("known materials: glass"), HasSubstr("did you mean 'glass'?")));

  const std::string wall = expect_at(
      error_of(kBase + "walls:\n"
                       "  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: steel}\n"),
      18, 66);
  EXPECT_THAT(wall,
              HasSubstr("walls[0].material: unknown material 'steel'; known materials: glass"));
}

TEST(SceneErrors, DuplicateMaterialName) {
  const std::string msg = expect_at(
      error_of(with("interactions:\n",
                    "  - {name: glass, youngs_modulus: 1e9, poisson_ratio: 0.2, density: 3000}\n"
                    "interactions:\n")),
      12, 12);
  EXPECT_THAT(msg, AllOf(HasSubstr("materials[1].name: duplicate material name 'glass' (first "
                                   "defined at line 8)"),
                         HasSubstr("unique name")));
}

// "glass[k=2]" names glass's parcel class of coarse_grain 2: a material of that name would be
// mistaken for it in every message.
TEST(SceneErrors, MaterialNamedLikeAParcelClass) {
  const std::string msg =
      expect_at(error_of(with("interactions:\n",
                              "  - {name: 'glass[k=2]', youngs_modulus: 1e9, poisson_ratio: 0.2, "
                              "density: 3000}\n"
                              "interactions:\n")),
                12, 12);
  EXPECT_THAT(msg, HasSubstr("materials[1].name: material name 'glass[k=2]' contains \"[k=\", "
                             "which names parcel classes"));
}

TEST(SceneErrors, MissingMaterialPairNamesThePair) {
  const std::string two_materials =
      with("interactions:\n",
           "  - {name: steel, youngs_modulus: 2e11, poisson_ratio: 0.29, density: 7800}\n"
           "interactions:\n");
  const std::string msg = expect_at(error_of(two_materials), 13, 1);
  EXPECT_THAT(msg,
              AllOf(HasSubstr("no interaction properties for material pair (glass, steel)"),
                    HasSubstr("materials: [glass, steel]"), HasSubstr("interaction_defaults")));

  // interaction_defaults fills the gap.
  const Scene s = parse_scene(two_materials + "interaction_defaults: {restitution: 0.7}\n", kLabel);
  EXPECT_DOUBLE_EQ(s.pair(0, 1).restitution, 0.7);
  EXPECT_DOUBLE_EQ(s.pair(1, 1).restitution, 0.7);
  EXPECT_DOUBLE_EQ(s.pair(0, 0).restitution, 0.9);
}

TEST(SceneErrors, DuplicateMaterialPair) {
  const std::string msg = expect_at(
      error_of(with("contact:\n", "  - {materials: [glass, glass], restitution: 0.5}\ncontact:\n")),
      15, 17);
  EXPECT_THAT(msg, HasSubstr("the pair (glass, glass) is already given at line 13"));
}

TEST(SceneErrors, StepAndRayleighFractionExactlyOne) {
  const std::string both =
      expect_at(error_of(with("  end: 0.5\n", "  end: 0.5\n  rayleigh_fraction: 0.1\n")), 7, 3);
  EXPECT_THAT(both, AllOf(HasSubstr("both 'step' and 'rayleigh_fraction' are given in time"),
                          HasSubstr("give exactly one of them")));

  const std::string neither = expect_at(error_of(with("  step: 1e-6\n", "")), 4, 1);
  EXPECT_THAT(neither, AllOf(HasSubstr("neither 'step' nor 'rayleigh_fraction' is given in time"),
                             HasSubstr("give exactly one of them")));
}

TEST(SceneErrors, CountAndVolumeFractionExactlyOne) {
  const std::string fill =
      "insert:\n"                                              // 17
      "  - type: fill\n"                                       // 18
      "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"  // 19
      "    count: 10\n"                                        // 20
      "    material: glass\n"                                  // 21
      "    radius: {distribution: constant, value: 1e-3}\n";   // 22
  const std::string both = expect_at(error_of(kBase + fill + "    volume_fraction: 0.3\n"), 23, 5);
  EXPECT_THAT(both, HasSubstr("both 'count' and 'volume_fraction' are given in insert[0]"));

  const std::string neither = expect_at(error_of(kBase + with("    count: 10\n", "", fill)), 18, 5);
  EXPECT_THAT(neither, HasSubstr("neither 'count' nor 'volume_fraction' is given in insert[0]"));

  const std::string fraction =
      expect_at(error_of(kBase + with("count: 10", "volume_fraction: 0.7", fill)), 20, 22);
  EXPECT_THAT(fraction, HasSubstr("value 0.7 is out of range; it must be in (0, 0.6]"));

  const std::string whole =
      expect_at(error_of(kBase + with("count: 10", "count: 10.5", fill)), 20, 12);
  EXPECT_THAT(whole, HasSubstr("insert[0].count: expected a whole number, got '10.5'"));
}

TEST(SceneErrors, YamlSyntaxErrorHasPosition) {
  const std::string msg = expect_at(error_of(with("max: [1, 1, 1]", "max: [1, 1, 1")), 4, 5);
  EXPECT_THAT(msg, HasSubstr("YAML syntax error: end of sequence flow not found"));

  const std::string indent =
      expect_at(error_of(with("  end: 0.5\n", "  end: 0.5\n   oops: 1\n")), 7, 8);
  EXPECT_THAT(indent, HasSubstr("YAML syntax error"));
}

TEST(SceneErrors, EmptyScene) {
  const std::string msg = expect_at(error_of("# nothing here\n"), 1, 1);
  EXPECT_THAT(msg, HasSubstr("the scene is empty"));
}

TEST(SceneErrors, ZeroDirection) {
  const std::string msg = expect_at(
      error_of(kBase + "walls:\n"
                       "  - {type: plane, point: [0, 0, 0], normal: [0, 0, 0], material: glass}\n"),
      18, 45);
  EXPECT_THAT(msg, HasSubstr("walls[0].normal: the direction [0, 0, 0] has no length"));
}

// Settings accepted but without effect in the scene are named at start-up (Scene::notes, one
// "<file>:<line>:<column>: note: ..." each): a pair's rolling_friction with rolling none,
// cohesion_energy_density with cohesion none, friction with tangential none; checkpoint_keep
// without checkpoint_interval; wall_loads without walls; a wall motion's axis that turns nothing.
// They ran without a word, bit for bit as without them. Used, none is named.
TEST(SceneNotes, SettingsWithoutEffectAreNamed) {
  const std::string unused =
      with("    restitution: 0.9\n",
           "    restitution: 0.9\n    friction: 0.9\n    rolling_friction: 0.3\n"
           "    cohesion_energy_density: 1e5\n") +
      "  tangential: none\n"                                                       // 20
      "walls:\n"                                                                   // 21
      "  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: glass,\n"  // 22
      "     motion: {velocity: [0.1, 0, 0], axis: [0, 0, 1]}}\n"                   // 23
      "output: {checkpoint_keep: 3}\n";                                            // 24
  const Scene s = parse_scene(unused, kLabel);
  ASSERT_EQ(s.notes.size(), 5u);
  const std::string at = kLabel + ":";
  EXPECT_EQ(s.notes[0], at + "16:5: note: interactions[0].rolling_friction: 0.3 has no effect: "
                             "contact.rolling is none, so contacts resist no rolling; name "
                             "`rolling: cdt` or `rolling: epsd` in contact to use it");
  EXPECT_THAT(s.notes[1], HasSubstr(at + "17:5: note: interactions[0].cohesion_energy_density: "
                                         "100000 has no effect: contact.cohesion is none"));
  EXPECT_THAT(s.notes[2], HasSubstr(at + "15:5: note: interactions[0].friction: 0.9 has no "
                                         "effect: contact.tangential is none"));
  EXPECT_THAT(s.notes[3], HasSubstr(at + "24:10: note: output.checkpoint_keep: 3 has no effect: "
                                         "no checkpoint_interval is given"));
  EXPECT_THAT(s.notes[4], HasSubstr(at + "23:38: note: walls[0].motion.axis: is given but has no "
                                         "effect: the wall does not rotate"));
  // The same settings where they act: no note.
  std::string used = unused;
  used.replace(used.find("  tangential: none\n"), 19, "  rolling: cdt\n  cohesion: sjkr\n");
  used.replace(used.find("axis: [0, 0, 1]"), 15, "axis: [0, 0, 1], angular_velocity: 1");
  used.replace(used.find("{checkpoint_keep: 3}"), 20,
               "{checkpoint_keep: 3, checkpoint_interval: 0.1}");
  EXPECT_TRUE(parse_scene(used, kLabel).notes.empty()) << parse_scene(used, kLabel).notes[0];
  // A friction of 0 agrees with frictionless contacts: no note. A cylinder's turning with
  // neither friction nor rolling resistance moves nothing: a note; with friction, none.
  const std::string drum =
      with("    restitution: 0.9\n", "    restitution: 0.9\n    friction: 0\n") +
      "  tangential: none\n"
      "walls:\n"
      "  - {type: cylinder, axis_point: [0.5, 0.5, 0], axis: [0, 0, 1], radius: 0.4,\n"
      "     angular_velocity: 3, material: glass}\n";
  const Scene d = parse_scene(drum, kLabel);
  ASSERT_EQ(d.notes.size(), 1u);
  EXPECT_THAT(d.notes[0], HasSubstr(":21:6: note: walls[0].angular_velocity: is given but has no "
                                    "effect: the wall's surface moves in its own plane"));
  std::string rough = drum;
  rough.replace(rough.find("  tangential: none\n"), 18, "  tangential: history\n");
  EXPECT_TRUE(parse_scene(rough, kLabel).notes.empty());
  // wall_loads without walls.
  const Scene no_walls = parse_scene(kBase + "output: {wall_loads: true}\n", kLabel);
  ASSERT_EQ(no_walls.notes.size(), 1u);
  EXPECT_THAT(no_walls.notes[0], HasSubstr("note: output.wall_loads: true has no effect: the "
                                           "scene has no walls"));
  // The mirror of the first two: a rolling or cohesion model named while every pair's
  // coefficient is 0, the default (the run was bit for bit the one without the model).
  const Scene models = parse_scene(kBase + "  rolling: epsd\n  cohesion: sjkr\n", kLabel);
  ASSERT_EQ(models.notes.size(), 2u);
  EXPECT_THAT(models.notes[0],
              HasSubstr(":17:3: note: contact.rolling: epsd has no effect: no pair of materials "
                        "has a rolling_friction above 0"));
  EXPECT_THAT(models.notes[1],
              HasSubstr(":18:3: note: contact.cohesion: sjkr has no effect: no pair of "
                        "materials has a cohesion_energy_density above 0"));
  // Coefficients only on a pair of wall materials (walls never touch each other): the
  // same notes.
  const std::string walls_only =
      with("    density: 2500\n",
           "    density: 2500\n  - {name: steel, youngs_modulus: 5e6, poisson_ratio: 0.3, "
           "density: 7800}\n") +
      "  rolling: epsd\n  cohesion: sjkr\n"
      "walls: [{type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: steel}]\n"
      "interaction_defaults: {restitution: 0.5}\n"
      "insert: [{type: fill, region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, count: 10, "
      "material: glass, radius: 0.01}]\n";
  std::string walls_pair = walls_only;
  walls_pair.replace(walls_pair.find("  - materials: [glass, glass]\n"), 30,
                     "  - {materials: [steel, steel], restitution: 0.5, rolling_friction: 0.1, "
                     "cohesion_energy_density: 1e5}\n  - materials: [glass, glass]\n");
  const Scene only_walls = parse_scene(walls_pair, kLabel);
  EXPECT_EQ(only_walls.notes.size(), 2u) << (only_walls.notes.empty() ? "" : only_walls.notes[0]);
  // On the pair of the particles' and the floor's materials: used, no note.
  std::string floor_pair = walls_pair;
  floor_pair.replace(floor_pair.find("[steel, steel]"), 14, "[glass, steel]");
  EXPECT_TRUE(parse_scene(floor_pair, kLabel).notes.empty())
      << parse_scene(floor_pair, kLabel).notes[0];
  EXPECT_TRUE(parse_scene(with("    restitution: 0.9\n",
                               "    restitution: 0.9\n    rolling_friction: 0.1\n"
                               "    cohesion_energy_density: 1e4\n") +
                              "  rolling: epsd\n  cohesion: sjkr\n",
                          kLabel)
                  .notes.empty());
}

TEST(SceneErrors, ModelSettingsMustMatchTheModel) {
  const std::string no_block = expect_at(error_of(with("normal: hertz", "normal: hooke")), 15, 1);
  EXPECT_THAT(no_block, HasSubstr("missing required key 'hooke' in contact; normal: hooke needs"));

  const std::string stray =
      expect_at(error_of(kBase + "  hooke: {characteristic_velocity: 1}\n"), 17, 3);
  EXPECT_THAT(stray,
              HasSubstr("contact.hooke: settings for the hooke model are given but normal is "
                        "hertz"));

  const std::string both =
      expect_at(error_of(with("normal: hertz",
                              "normal: hooke\n  hooke: {characteristic_velocity: 1, "
                              "stiffness: {normal: 1e4}}")),
                17, 39);
  EXPECT_THAT(both, HasSubstr("both 'characteristic_velocity' and 'stiffness' are given in "
                              "contact.hooke"));
}

// A missing CSV file is reported by its insertion, at the `file` key (file:line:column):
// the parser keeps the error, as a restart, which inserts nothing, runs without the file.
TEST(SceneErrors, CsvFileMustExist) {
  const Scene s = parse_scene(
      kBase + "insert:\n  - {type: csv, file: no_such_file.csv, material: glass}\n", kLabel);
  ASSERT_EQ(s.insertions.size(), 1u);
  const std::string& msg = s.insertions[0].csv_missing;
  EXPECT_EQ(msg.rfind(kLabel + ":18:23: error: ", 0), 0u) << msg;
  EXPECT_THAT(msg, AllOf(HasSubstr("insert[0].file: particle file 'no_such_file.csv' not found"),
                         HasSubstr(kScenes + "/no_such_file.csv"),
                         HasSubstr("relative to the scene file's folder")));
  // The insertion throws it (`grain check` and `grain run` exit 2 with it): user_files.py,
  // restart_missing_csv.
}

TEST(SceneErrors, FillRegionMustLieInsideDomain) {
  const std::string msg = expect_at(
      error_of(
          kBase +
          "insert:\n"
          "  - type: fill\n"
          "    region: {cylinder: {base: [0.5, 0.5, 0], axis: [0, 0, 1], radius: 0.6, height: 1}}\n"
          "    count: 10\n"
          "    material: glass\n"
          "    radius: {distribution: constant, value: 1e-3}\n"),
      19, 14);
  EXPECT_THAT(msg, HasSubstr("the region reaches outside the domain along x (region from -0.1 to "
                             "1.1, domain from 0 to 1)"));
}

TEST(SceneErrors, DiscreteWeightsMustMatchValues) {
  const std::string msg = expect_at(
      error_of(kBase +
               "insert:\n"
               "  - type: fill\n"
               "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
               "    count: 10\n"
               "    material: glass\n"
               "    radius: {distribution: discrete, values: [1e-3, 2e-3], weights: [1, 2, 3]}\n"),
      22, 69);
  EXPECT_THAT(msg, HasSubstr("insert[0].radius.weights: 3 weights are given for 2 values"));
}

TEST(SceneErrors, MissingFileHasNoPosition) {
  const std::string path = kScenes + "/does_not_exist.yaml";
  try {
    load_scene(path);
    FAIL() << "expected a SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 0);
    EXPECT_THAT(e.what(), HasSubstr(path + ": error: cannot open the scene file"));
  }
}

TEST(SceneErrors, DuplicateWallName) {
  const std::
      string
          walls =
              "walls:\n"  // 17
              "  - {type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: "
              "glass}\n"                                                                    // 18
              "  - {type: plane, point: [0, 0, 1], normal: [0, 0, -1], material: glass}\n"  // 19
              "  - {type: plane, name: floor, point: [0, 0, 0], normal: [1, 0, 0], material: "
              "glass}\n";  // 20
  const std::string msg = expect_at(error_of(kBase + walls), 20, 25);
  EXPECT_THAT(msg, HasSubstr("walls[2].name: duplicate wall name 'floor'"));
  // The unnamed wall is 'wall1'; naming a later one so collides too.
  const std::string msg2 =
      expect_at(error_of(kBase + with("name: floor, point: [0, 0, 0], normal: [1",
                                      "name: wall1, point: [0, 0, 0], normal: [1", walls)),
                20, 25);
  EXPECT_THAT(msg2, HasSubstr("duplicate wall name 'wall1'"));
}

// yaml-cpp refuses deep nesting (500 levels in 0.7) instead of overflowing the stack;
// the error says what that means.
TEST(SceneErrors, DeepNestingIsASyntaxErrorNotACrash) {
  const std::string deep = "domain: " + std::string(5000, '[') + std::string(5000, ']') + "\n";
  const SceneError e = error_of(deep);
  EXPECT_EQ(e.line(), 1);
  EXPECT_THAT(e.what(), AllOf(HasSubstr("YAML syntax error: brackets or indentation nest "),
                              HasSubstr(" levels deep; a scene needs at most a few levels")));
}

TEST(SceneErrors, NumbersNearTheDoubleLimit) {
  const std::string extent = expect_at(error_of(with("min: [0, 0, 0]", "min: [-1e308, 0, 0]",
                                                     with("max: [1, 1, 1]", "max: [1e308, 1, 1]"))),
                                       3, 9);
  EXPECT_THAT(extent, HasSubstr("domain.max[0]: the domain's extent max - min overflows"));
  const std::string fill =
      "insert:\n"
      "  - type: fill\n"
      "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
      "    count: 10\n"
      "    material: glass\n";
  const std::string stddev = expect_at(
      error_of(kBase + fill + "    radius: {distribution: normal, mean: 1e-3, stddev: 1e308}\n"),
      22, 56);
  EXPECT_THAT(stddev, HasSubstr("insert[0].radius.stddev: mean + 3 stddev overflows"));
  // Weights near the limit would sum to inf and normalise to 0: scaled first.
  const Scene s = parse_scene(
      kBase + fill +
          "    radius: {distribution: discrete, values: [1e-3, 2e-3], weights: [1e308, 1.5e308]}\n",
      kLabel);
  EXPECT_DOUBLE_EQ(s.insertions[0].radius.weights[0], 0.4);
  EXPECT_DOUBLE_EQ(s.insertions[0].radius.weights[1], 0.6);
}

// Hostile sizes (docs/reliability.md, "Hostile input"): what the parser would build
// from them is bounded before it is built.
TEST(SceneErrors, MaterialCountIsBounded) {
  std::string many = "materials:\n";
  for (int i = 0; i < 1001; ++i)
    many += "  - {name: m" + std::to_string(i) +
            ", youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}\n";
  const std::string text =
      with("interactions:\n  - materials: [glass, glass]\n    restitution: 0.9\n",
           "interaction_defaults: {restitution: 0.9}\n",
           with("materials:\n  - name: glass\n    youngs_modulus: 5e6\n    poisson_ratio: 0.3\n"
                "    density: 2500\n",
                many));
  const std::string msg = expect_at(error_of(text), 7, 1);
  EXPECT_THAT(msg, HasSubstr("materials: 1001 materials are listed; at most 1000 are allowed"));
}

TEST(SceneErrors, FillCountMustFitTheRegionByVolume) {
  const std::string fill =
      "insert:\n"                                                     // 17
      "  - type: fill\n"                                              // 18
      "    region: {box: {min: [0, 0, 0], max: [1, 1, 0.5]}}\n"       // 19
      "    count: 1e9\n"                                              // 20
      "    material: glass\n"                                         // 21
      "    radius: {distribution: uniform, min: 1e-3, max: 2e-3}\n";  // 22
  // 1e9 spheres of r >= 1 mm: 1e9 (4/3) pi 1e-9 = 4.18879 m^3 > 0.5 m^3.
  const std::string msg = expect_at(error_of(kBase + fill), 20, 12);
  EXPECT_THAT(msg, HasSubstr("insert[0].count: 1000000000 spheres of radius at least 0.001 m have "
                             "a volume of 4.18879020479 m^3, more than the region's 0.5 m^3"));
}

// Periodic checkpoints (docs/reliability.md): off unless an interval is given; keep 2.
TEST(SceneParser, CheckpointSettings) {
  const Scene none = parse_scene(kBase, kLabel);
  EXPECT_FALSE(none.output.checkpoint_interval);
  EXPECT_EQ(none.output.checkpoint_keep, 2);

  const Scene s =
      parse_scene(kBase + "output:\n  checkpoint_interval: 0.05\n  checkpoint_keep: 3\n", kLabel);
  EXPECT_EQ(s.output.checkpoint_interval, 0.05);
  EXPECT_EQ(s.output.checkpoint_keep, 3);

  // Lines 17-18 are the output block appended to the 16-line base.
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  checkpoint_interval: 0\n"), 18, 24),
              HasSubstr("output.checkpoint_interval: value 0 is out of range; it must be > 0"));
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  checkpoint_interval: soon\n"), 18, 24),
              HasSubstr("expected a number, got 'soon'"));
  EXPECT_THAT(
      expect_at(error_of(kBase + "output:\n  checkpoint_keep: 0\n"), 18, 20),
      HasSubstr("output.checkpoint_keep: value 0 is out of range; it must be in [1, 1000]"));
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  checkpoint_keep: 2.5\n"), 18, 20),
              HasSubstr("expected a whole number, got '2.5'"));
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  checkpoint_every: 1\n"), 18, 3),
              HasSubstr("checkpoint_interval, checkpoint_keep"));
}

// output.fields / start / stop: the default is the eight state fields; a list selects
// fields (id and position always); unknown names, an inverted window and a window after the
// end are refused at the value, naming the key and what is allowed.
TEST(SceneParser, SnapshotFieldsAndWindow) {
  const Scene none = parse_scene(kBase, kLabel);
  EXPECT_EQ(none.output.fields, snapshot_default_fields);
  EXPECT_FALSE(none.output.start);
  EXPECT_FALSE(none.output.stop);

  const Scene s = parse_scene(
      kBase + "output:\n  fields: [force, coordination]\n  start: 0.1\n  stop: 0.2\n", kLabel);
  EXPECT_EQ(s.output.fields, snapshot_required_fields | snapshot_field_bit("force") |
                                 snapshot_field_bit("coordination"));
  EXPECT_EQ(s.output.start, 0.1);
  EXPECT_EQ(s.output.stop, 0.2);

  // Lines 17-18 are the output block appended to the 16-line base.
  const std::string unknown =
      expect_at(error_of(kBase + "output:\n  fields: [velocity, torqe]\n"), 18, 22);
  EXPECT_THAT(unknown, HasSubstr("output.fields[1]: unknown snapshot field 'torqe'; allowed: id, "
                                 "position, velocity, angular_velocity, radius, diameter, mass, "
                                 "material, force, torque, coordination, fluid_force, "
                                 "overlap_max, temperature, coarse_grain, real_count (did you mean 'torque'?)"));
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  fields: []\n"), 18, 11),
              HasSubstr("output.fields: the list is empty"));
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  fields: force\n"), 18, 11),
              HasSubstr("output.fields: expected a list"));
  EXPECT_THAT(
      expect_at(error_of(kBase + "output:\n  start: 0.3\n  stop: 0.2\n"), 19, 9),
      HasSubstr("output.stop: output.stop (0.2 s) must be after output.start (0.3 s)"));
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  start: 0.7\n"), 18, 10),
              HasSubstr("output.start (0.7 s) is after time.end (0.5 s)"));
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  stop: later\n"), 18, 9),
              HasSubstr("output.stop: expected a number, got 'later'"));
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  start: -1\n"), 18, 10),
              HasSubstr("output.start: value -1 is out of range; it must be >= 0"));
}

// output.contacts: off by default, `true` writes the contact network, and a value that is not
// a boolean is refused at the value (file:line:column), naming the key and what it accepts.
TEST(SceneParser, OutputContacts) {
  EXPECT_FALSE(parse_scene(kBase, kLabel).output.contacts);
  EXPECT_TRUE(parse_scene(kBase + "output: {contacts: true}\n", kLabel).output.contacts);
  EXPECT_FALSE(parse_scene(kBase + "output:\n  contacts: false\n", kLabel).output.contacts);
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  contacts: pairs\n"), 18, 13),
              HasSubstr("output.contacts: expected true or false, got 'pairs'"));
  EXPECT_THAT(expect_at(error_of(kBase + "output:\n  contacts: [walls]\n"), 18, 13),
              HasSubstr("output.contacts: expected true or false"));
}

// parallel.reproducible: off by default, `true` selects canonical summation, and a value
// that is not a boolean names the key and what it accepts.
TEST(SceneParser, ParallelReproducible) {
  EXPECT_FALSE(parse_scene(kBase, kLabel).parallel.reproducible);
  const Scene on = parse_scene(kBase + "parallel: {reproducible: true}\n", kLabel);
  EXPECT_TRUE(on.parallel.reproducible);
  const std::string msg =
      expect_at(error_of(kBase + "parallel: {reproducible: sometimes}\n"), 17, 26);
  EXPECT_THAT(msg, HasSubstr("parallel.reproducible: expected true or false, got 'sometimes'"));
}

// A wall must look the same from both sides of a periodic boundary. A plane across a periodic
// axis was accepted, and a particle coming back through the other side landed behind it: the
// overlap guard stopped the run, and its advice (a larger time.max_overlap) ended in "done"
// with the kinetic energy grown 250-fold, without gravity or any energy input.
TEST(SceneErrors, WallsAcrossAPeriodicAxis) {
  const std::string periodic =
      with("  max: [1, 1, 1]\n", "  max: [1, 1, 1]\n  periodic: [true, false, false]\n");
  const auto walls = [&](const std::string& w) { return periodic + "walls:\n  - " + w + "\n"; };
  const std::string plane = expect_at(
      error_of(
          walls("{type: plane, name: left, point: [0, 0, 0], normal: [1, 0, 0], material: glass}")),
      19, 49);
  EXPECT_THAT(
      plane,
      AllOf(
          HasSubstr("walls[0].normal: plane 'left' has a normal with the component 1 along x, and "
                    "x is periodic (domain.periodic)"),
          HasSubstr("make x bounded, or give the plane a normal perpendicular to x")));
  // Inclined: the component 0.7071 along x.
  EXPECT_THAT(
      error_of(walls("{type: plane, point: [0, 0, 0], normal: [1, 0, 1], material: glass}")).what(),
      HasSubstr("with the component 0.7071 along x"));
  EXPECT_THAT(
      error_of(walls("{type: cylinder, axis_point: [0.5, 0.5, 0], axis: [1, 0, 1], radius: 0.2, "
                     "material: glass}"))
          .what(),
      HasSubstr("cylinder 'wall0' has an axis tilted to x, and x is periodic"));
  EXPECT_THAT(
      error_of(walls("{type: cylinder, axis_point: [0.9, 0.5, 0], axis: [0, 0, 1], radius: 0.2, "
                     "side: outside, material: glass}"))
          .what(),
      HasSubstr("cylinder 'wall0' reaches from x = 0.7 to 1.1 m, across the domain's 0 to 1 m"));
  EXPECT_THAT(
      error_of(walls("{type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: glass, "
                     "motion: {angular_velocity: 1, axis: [0, 1, 0]}}"))
          .what(),
      HasSubstr("rotates (motion.angular_velocity) about an axis that turns its normal towards x"));
  // A translation along x carries a drum across the periodic sides (it was accepted and blew
  // particles out when it got there) and a mesh out of the range.
  EXPECT_THAT(
      error_of(walls("{type: cylinder, axis_point: [0.5, 0.5, 0], axis: [0, 0, 1], radius: 0.3, "
                     "material: glass, motion: {velocity: [0.1, 0, 0]}}"))
          .what(),
      HasSubstr("walls[0].motion: cylinder 'wall0' moves along x (motion.velocity x = 0.1 m/s), "
                "and x is periodic"));
  // What periodicity allows: a floor, a pipe along x, a drum across x within the range, a
  // plane rotating about x, a floor and a pipe moving along x.
  for (
      const char* ok :
      {"{type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: glass}",
       "{type: cylinder, axis_point: [0, 0.5, 0.5], axis: [1, 0, 0], radius: 0.4, material: glass}",
       "{type: cylinder, axis_point: [0.5, 0.5, 0], axis: [0, 0, 1], radius: 0.5, material: glass}",
       "{type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: glass, "
       "motion: {angular_velocity: 1, axis: [1, 0, 0]}}",
       "{type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: glass, "
       "motion: {velocity: [0.1, 0, 0]}}",
       "{type: cylinder, axis_point: [0, 0.5, 0.5], axis: [1, 0, 0], radius: 0.4, material: glass, "
       "motion: {velocity: [0.1, 0, 0]}}"})
    EXPECT_NO_THROW(parse_scene(walls(ok), kLabel)) << ok;
}

// A shear varying along a periodic axis would jump by G L at the periodic sides (the answer
// depended on the neighbour skin: the jump came when a centre was wrapped): refused at
// gradient_direction. Along a bounded axis, with the others periodic, it runs.
// A key with no effect, a number a double cannot hold, and one below the smallest normal
// double (a viscosity of 1e-320 gave NaN drag): refused at the value, saying why.
TEST(SceneErrors, FluidValuesThatCannotWork) {
  const auto fluid = [](const std::string& extra, const std::string& viscosity) {
    return kBase + "fluid:\n  density: 1000\n  viscosity: " + viscosity +
           "\n  drag: schiller_naumann\n  model: B\n"
           "  forces: [drag, pressure_gradient, viscous]\n" +
           extra;
  };
  EXPECT_THAT(error_of(fluid("  virtual_mass_coefficient: 3\n", "1e-3")).what(),
              HasSubstr("fluid.virtual_mass_coefficient: has no effect without `virtual_mass` in "
                        "fluid.forces"));
  EXPECT_THAT(error_of(fluid("", "1e-320")).what(),
              HasSubstr("fluid.viscosity: value 1e-320 is below the smallest normal double"));
  EXPECT_THAT(error_of(fluid("", "1e400")).what(),
              HasSubstr("fluid.viscosity: value 1e400 is beyond the range of a double"));
  EXPECT_THAT(error_of(fluid("", "abc")).what(),
              HasSubstr("fluid.viscosity: expected a number, got 'abc'"));
  EXPECT_NO_THROW(parse_scene(with("forces: [drag, pressure_gradient, viscous]",
                                   "forces: [drag, pressure_gradient, viscous, virtual_mass]",
                                   fluid("  virtual_mass_coefficient: 3\n", "1e-3")),
                              kLabel));
}

TEST(SceneErrors, ShearAcrossAPeriodicAxis) {
  const auto sheared = [](const std::string& periodic, const std::string& gradient) {
    return with("  max: [1, 1, 1]\n", "  max: [1, 1, 1]\n  periodic: " + periodic + "\n") +
           "fluid:\n  density: 1000\n  viscosity: 1e-3\n  drag: schiller_naumann\n  model: B\n"
           "  forces: [drag, pressure_gradient, viscous]\n"
           "  shear: {rate: 10, flow_direction: [1, 0, 0], gradient_direction: " +
           gradient + "}\n";
  };
  EXPECT_THAT(error_of(sheared("[true, true, true]", "[0, 0, 1]")).what(),
              AllOf(HasSubstr("fluid.shear.gradient_direction: has the component 1 along z, and z "
                              "is periodic (domain.periodic): the sheared fluid velocity would "
                              "jump by 10 m/s at the periodic sides"),
                    HasSubstr("make z bounded, or choose a gradient_direction along a bounded "
                              "axis")));
  EXPECT_THAT(error_of(sheared("[false, true, false]", "[0, 1, 1]")).what(),
              HasSubstr("has the component 0.7071 along y, and y is periodic"));
  EXPECT_NO_THROW(parse_scene(sheared("[true, true, false]", "[0, 0, 1]"), kLabel));
}

// A stream that would deliver particles the domain removes at once (a face reaching beyond a
// bounded side: they were counted as delivered), or nothing (starting after time.end): refused
// at the key. Across a periodic side a face may reach: its particles wrap.
TEST(SceneErrors, StreamsThatCannotDeliver) {
  const auto stream = [](const std::string& centre, const std::string& extra) {
    return kBase + "insert:\n  - {type: stream, face: {rectangle: {centre: " + centre +
           ", normal: [0, 0, -1], u: [1, 0, 0], size: [0.4, 0.4]}}, count_rate: 100, "
           "material: glass, radius: {distribution: constant, value: 0.01}" +
           extra + "}\n";
  };
  EXPECT_THAT(error_of(stream("[0.5, 0.1, 0.9]", "")).what(),
              AllOf(HasSubstr("insert[0].face: the face reaches beyond the domain along y: "
                              "particles entering through it span y from -0.1 to 0.3 m"),
                    HasSubstr("Move the face's centre to y between 0.2 and 0.8 m")));
  EXPECT_THAT(error_of(stream("[0.5, 0.5, 0.9]", ", start: 0.5")).what(),
              HasSubstr("insert[0].start: start 0.5 s is not before time.end (0.5 s)"));
  // Values 1e-12 apart are printed with every digit (12 digits showed "0.5 s is not before
  // 0.5 s"; the stop's message did not give the stop).
  EXPECT_THAT(error_of(stream("[0.5, 0.5, 0.9]", ", start: 0.5000000000005")).what(),
              HasSubstr("start 0.5000000000005 s is not before time.end (0.5 s)"));
  EXPECT_THAT(error_of(stream("[0.5, 0.5, 0.9]", ", start: 0.1, stop: 0.0999999999999")).what(),
              HasSubstr("insert[0].stop: stop 0.0999999999999 s must be later than start (0.1 s)"));
  EXPECT_NO_THROW(
      parse_scene(with("  max: [1, 1, 1]\n", "  max: [1, 1, 1]\n  periodic: [false, true, false]\n",
                       stream("[0.5, 0.1, 0.9]", "")),
                  kLabel));
}

// The model record a checkpoint keeps (Scene::model_record): one value, however written, and
// keys in any order are one record; another value is another record, with its source line.
TEST(SceneParser, ModelRecordIsTheValuesNotTheirSpelling) {
  const Scene a = parse_scene(kBase, kLabel);
  const Scene b = parse_scene(with("    density: 2500\n", "    density: 2.5e3\n",
                                   with("    youngs_modulus: 5e6\n    poisson_ratio: 0.3\n",
                                        "    poisson_ratio: 0.30\n    youngs_modulus: 5000000\n")),
                              kLabel);
  EXPECT_EQ(a.model_record, b.model_record);
  EXPECT_NE(a.model_record.find("materials[0].density = 2500\n"), std::string::npos)
      << a.model_record;
  EXPECT_NE(a.model_record.find("interactions[0].restitution = 0.9\n"), std::string::npos);
  EXPECT_EQ(a.model_record.find("time."), std::string::npos);  // time, output: not the model
  const Scene c = parse_scene(with("restitution: 0.9", "restitution: 0.8"), kLabel);
  EXPECT_NE(a.model_record, c.model_record);
  ASSERT_EQ(c.model_sources.size(), static_cast<std::size_t>(std::count(
                                        c.model_record.begin(), c.model_record.end(), '\n')));
}

// A direction is normalised whatever its length: [0, 0, 1e155] was normalised to [0, 0, 0]
// (its squared length overflowed), and a floor with that normal refused every particle.
TEST(SceneParser, DirectionsOfAnyLengthAreNormalised) {
  for (const char* n : {"[0, 0, 1e155]", "[0, 0, 1e-160]", "[1e300, 0, 1e300]"}) {
    const Scene s = parse_scene(
        kBase + "walls:\n  - {type: plane, point: [0, 0, 0], normal: " + n + ", material: glass}\n",
        kLabel);
    ASSERT_EQ(s.walls.size(), 1u);
    EXPECT_NEAR(s.walls[0].plane.normal.norm(), 1.0, 1e-15) << n;
    EXPECT_GT(s.walls[0].plane.normal[2], 0.7) << n;
  }
}

}  // namespace
}  // namespace grainflow
