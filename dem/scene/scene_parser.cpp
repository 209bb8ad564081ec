// Scene parser: YAML -> validated Scene.
//
// Two layers:
//  1. A small reading layer (Field, Map, Range) that turns YAML nodes into numbers,
//     vectors, names and model choices, checking type and range and remembering
//     where in the file each value came from, so every error can point at it.
//  2. One function per scene section, which only says what the section contains.
// The first mistake found throws a SceneError; nothing is collected or deferred.
#include "dem/scene/scene_parser.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace grainflow {

namespace {

namespace fs = std::filesystem;

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------
// Message helpers

std::string format_number(double x) {
  std::ostringstream s;
  s << std::setprecision(12) << x;
  return s.str();
}

std::string join(const std::vector<std::string>& items, std::string_view separator = ", ") {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += separator;
    out += items[i];
  }
  return out;
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const std::size_t substitute = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      row[j] = std::min({above + 1, row[j - 1] + 1, substitute});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// " (did you mean 'hertz'?)" when exactly one candidate is close to `given`, else "".
std::string suggestion(std::string_view given, const std::vector<std::string>& candidates) {
  const std::size_t limit = std::clamp<std::size_t>((given.size() + 1) / 3, 1, 3);
  std::size_t best = limit + 1;
  const std::string* match = nullptr;
  bool tie = false;
  for (const std::string& c : candidates) {
    const std::size_t d = edit_distance(given, c);
    if (d < best) {
      best = d;
      match = &c;
      tie = false;
    } else if (d == best) {
      tie = true;
    }
  }
  if (match == nullptr || tie) return "";
  return " (did you mean '" + *match + "'?)";
}

// ---------------------------------------------------------------------------
// Allowed ranges of numbers

struct Range {
  double lo = -kInf;
  double hi = kInf;
  bool lo_closed = true;
  bool hi_closed = true;

  bool contains(double x) const {
    const bool above = lo_closed ? x >= lo : x > lo;
    const bool below = hi_closed ? x <= hi : x < hi;
    return above && below;
  }

  bool bounded() const { return lo != -kInf || hi != kInf; }

  std::string describe() const {
    if (lo != -kInf && hi != kInf)
      return std::string("in ") + (lo_closed ? "[" : "(") + format_number(lo) + ", " +
             format_number(hi) + (hi_closed ? "]" : ")");
    if (lo != -kInf) return std::string(lo_closed ? ">= " : "> ") + format_number(lo);
    if (hi != kInf) return std::string(hi_closed ? "<= " : "< ") + format_number(hi);
    return "any number";
  }
};

constexpr Range kAny{};
constexpr Range kPositive{0, kInf, false, true};
constexpr Range kNonNegative{0, kInf, true, true};
constexpr Range kUnitOpenBelow{0, 1, false, true};  // (0, 1]
constexpr Range kUnitClosed{0, 1, true, true};      // [0, 1]

// ---------------------------------------------------------------------------
// Reading layer

// What every value needs to report an error: the file it came from.
struct Source {
  std::string label;  // as given by the caller; used in messages
  fs::path folder;    // relative file names inside the scene are resolved against it
};

[[noreturn]] void raise(const Source& src, const YAML::Mark& mark, const std::string& message) {
  // yaml-cpp marks are 0-based; ours are 1-based.
  throw SceneError(src.label, mark.line + 1, mark.column + 1, message);
}

YAML::Mark start_of_file() {
  YAML::Mark m;
  m.pos = 0;
  m.line = 0;
  m.column = 0;
  return m;
}

template <class E>
struct Choice {
  const char* name;
  E value;
};

class Map;

// One YAML value with its name in the scene ("materials[1].density") and where it is.
class Field {
 public:
  Field(const Source& src, YAML::Node node, std::string path, YAML::Mark key_mark)
      : src_(&src), node_(std::move(node)), path_(std::move(path)), key_mark_(key_mark) {
    // A missing value (`key:` alone) has no useful mark of its own; use the key's.
    const bool has_own_mark = node_.IsDefined() && !node_.IsNull() && node_.Mark().line >= 0;
    mark_ = has_own_mark ? node_.Mark() : key_mark_;
  }

  const Source& source() const { return *src_; }
  const std::string& path() const { return path_; }
  const YAML::Mark& mark() const { return mark_; }
  const YAML::Mark& key_mark() const { return key_mark_; }
  int line() const { return mark_.line + 1; }
  const YAML::Node& node() const { return node_; }

  // Throws at the value: "<path>: <message>".
  [[noreturn]] void fail(const std::string& message) const {
    raise(*src_, mark_, prefixed(message));
  }
  // Throws at the key that names this value (for problems with the value as a whole).
  [[noreturn]] void fail_at_key(const std::string& message) const {
    raise(*src_, key_mark_, prefixed(message));
  }

  double number(const Range& range = kAny) const {
    const std::optional<double> x = as_number(node_);
    if (!x) fail("expected a number, got " + got() + "; write a plain number such as 0.5 or 2e-3");
    check_range(*x, range);
    return *x;
  }

  long long integer(const Range& range) const {
    const std::optional<double> x = as_number(node_);
    if (!x || std::floor(*x) != *x || std::abs(*x) > 9e15)
      fail("expected a whole number, got " + got() + "; write an integer such as 1000");
    check_range(*x, range);
    return static_cast<long long>(*x);
  }

  bool boolean() const {
    bool b = false;
    if (!node_.IsScalar() || !YAML::convert<bool>::decode(node_, b))
      fail("expected true or false, got " + got());
    return b;
  }

  std::string text() const {
    if (!node_.IsScalar() || node_.Scalar().empty()) fail("expected a name or text, got " + got());
    return node_.Scalar();
  }

  // A model or kind chosen by name from a fixed list.
  template <class E>
  E choice(const char* what, std::initializer_list<Choice<E>> choices) const {
    std::vector<std::string> names;
    for (const Choice<E>& c : choices) names.emplace_back(c.name);
    if (!node_.IsScalar())
      fail("expected a " + std::string(what) + " name, got " + got() + "; allowed: " + join(names));
    for (const Choice<E>& c : choices)
      if (node_.Scalar() == c.name) return c.value;
    fail("unknown " + std::string(what) + " '" + node_.Scalar() + "'; allowed: " + join(names) +
         suggestion(node_.Scalar(), names));
  }

  std::vector<Field> items() const {
    if (!node_.IsSequence())
      fail("expected a list, got " + got() +
           "; write it as [a, b, ...] or as lines starting with '- '");
    std::vector<Field> out;
    for (std::size_t i = 0; i < node_.size(); ++i) {
      const YAML::Node item = node_[i];
      const YAML::Mark m = item.IsNull() || item.Mark().line < 0 ? mark_ : item.Mark();
      out.emplace_back(*src_, item, path_ + "[" + std::to_string(i) + "]", m);
    }
    return out;
  }

  std::vector<Field> non_empty_items(const std::string& what_to_do) const {
    std::vector<Field> out = items();
    if (out.empty()) fail("the list is empty; " + what_to_do);
    return out;
  }

  std::vector<double> numbers(const Range& range) const {
    std::vector<double> out;
    for (const Field& f : non_empty_items("give at least one number"))
      out.push_back(f.number(range));
    return out;
  }

  Vec3 vec3() const {
    const std::array<Field, 3> e = three("numbers", "[x, y, z]");
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
      const std::optional<double> x = as_number(e[i].node_);
      if (!x)
        e[i].raise_here("expected a list of 3 numbers, but item " + std::to_string(i + 1) + " is " +
                        e[i].got() + "; write it as [x, y, z]");
      v[i] = *x;
    }
    return v;
  }

  // A direction: any non-zero vector, returned normalised.
  Vec3 direction() const {
    const Vec3 v = vec3();
    if (!(v.norm() > 0)) fail("the direction [0, 0, 0] has no length; give a non-zero vector");
    return v.normalized();
  }

  std::array<bool, 3> bool3() const {
    const std::array<Field, 3> e = three("true/false values", "[false, false, true]");
    std::array<bool, 3> b{};
    for (int i = 0; i < 3; ++i) {
      if (!e[i].node_.IsScalar() || !YAML::convert<bool>::decode(e[i].node_, b[i]))
        e[i].raise_here("expected a list of 3 true/false values, but item " +
                        std::to_string(i + 1) + " is " + e[i].got() +
                        "; write it as [false, false, true]");
    }
    return b;
  }

  Map map() const;
  Map map(std::vector<std::string> allowed) const;

  // The value as the user wrote it, for messages.
  std::string got() const {
    if (!node_.IsDefined() || node_.IsNull()) return "nothing";
    if (node_.IsSequence()) return "a list of " + std::to_string(node_.size());
    if (node_.IsMap()) return "a map";
    return "'" + node_.Scalar() + "'";
  }

 private:
  static std::optional<double> as_number(const YAML::Node& n) {
    double x = 0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, x) || !std::isfinite(x))
      return std::nullopt;
    return x;
  }

  std::string prefixed(const std::string& message) const {
    return path_.empty() ? message : path_ + ": " + message;
  }

  // Throws at this value, but names the enclosing vector (the path without "[i]").
  [[noreturn]] void raise_here(const std::string& message) const {
    raise(*src_, mark_, path_.substr(0, path_.rfind('[')) + ": " + message);
  }

  std::array<Field, 3> three(const std::string& what, const std::string& example) const {
    if (!node_.IsSequence() || node_.size() != 3)
      fail("expected a list of 3 " + what + ", got " + got() + "; write it as " + example);
    const std::vector<Field> e = items();
    return {e[0], e[1], e[2]};
  }

  void check_range(double x, const Range& range) const {
    if (!range.contains(x))
      fail("value " + node_.Scalar() + " is out of range; it must be " + range.describe());
  }

  const Source* src_;
  YAML::Node node_;
  std::string path_;
  YAML::Mark key_mark_;
  YAML::Mark mark_;
};

// A YAML map whose keys have been checked: no duplicates, and (once allow_only has
// run) no unknown keys.
class Map {
 public:
  struct Entry {
    std::string key;
    YAML::Mark key_mark;
    YAML::Node value;
  };

  Map(Field self, std::vector<Entry> entries)
      : self_(std::move(self)), entries_(std::move(entries)) {}

  const Field& self() const { return self_; }

  void allow_only(const std::vector<std::string>& allowed, const std::string& what = "") const {
    for (const Entry& e : entries_) {
      if (std::find(allowed.begin(), allowed.end(), e.key) != allowed.end()) continue;
      raise(self_.source(), e.key_mark,
            "unknown key '" + e.key + "' in " + where() + what +
                "; allowed keys: " + join(allowed) + suggestion(e.key, allowed));
    }
  }

  bool has(std::string_view key) const { return entry(key) != nullptr; }

  std::optional<Field> find(std::string_view key) const {
    const Entry* e = entry(key);
    if (e == nullptr) return std::nullopt;
    return Field(self_.source(), e->value, child_path(key), e->key_mark);
  }

  Field get(std::string_view key, const std::string& hint = "add it") const {
    std::optional<Field> f = find(key);
    if (!f)
      raise(self_.source(), self_.key_mark(),
            "missing required key '" + std::string(key) + "' in " + where() + "; " + hint);
    return *f;
  }

  double number(std::string_view key, const Range& range) const {
    return get(key, value_hint(key, range)).number(range);
  }
  double number_or(std::string_view key, double fallback, const Range& range) const {
    const std::optional<Field> f = find(key);
    return f ? f->number(range) : fallback;
  }
  std::optional<double> maybe_number(std::string_view key, const Range& range) const {
    const std::optional<Field> f = find(key);
    if (!f) return std::nullopt;
    return f->number(range);
  }
  Vec3 vec3(std::string_view key) const {
    return get(key, "add `" + std::string(key) + ": [x, y, z]`").vec3();
  }
  Vec3 vec3_or(std::string_view key, const Vec3& fallback) const {
    const std::optional<Field> f = find(key);
    return f ? f->vec3() : fallback;
  }
  Vec3 direction(std::string_view key) const {
    return get(key, "add `" + std::string(key) + ": [x, y, z]`").direction();
  }

  // Exactly one of two alternative keys must be present.
  void exactly_one_of(std::string_view a, std::string_view b, const std::string& hint) const {
    const Entry* ea = entry(a);
    const Entry* eb = entry(b);
    const std::string both = "'" + std::string(a) + "' and '" + std::string(b) + "'";
    if (ea != nullptr && eb != nullptr) {
      const Entry* later = ea->key_mark.pos > eb->key_mark.pos ? ea : eb;
      raise(self_.source(), later->key_mark,
            "both " + both + " are given in " + where() + "; give exactly one of them (" + hint +
                ")");
    }
    if (ea == nullptr && eb == nullptr)
      raise(self_.source(), self_.key_mark(),
            "neither '" + std::string(a) + "' nor '" + std::string(b) + "' is given in " + where() +
                "; give exactly one of them (" + hint + ")");
  }

 private:
  const Entry* entry(std::string_view key) const {
    for (const Entry& e : entries_)
      if (e.key == key) return &e;
    return nullptr;
  }

  std::string child_path(std::string_view key) const {
    return self_.path().empty() ? std::string(key) : self_.path() + "." + std::string(key);
  }

  std::string where() const { return self_.path().empty() ? "the top level" : self_.path(); }

  static std::string value_hint(std::string_view key, const Range& range) {
    std::string hint = "add `" + std::string(key) + ": <number>`";
    if (range.bounded()) hint += " with a value " + range.describe();
    return hint;
  }

  Field self_;
  std::vector<Entry> entries_;
};

Map Field::map() const {
  if (!node_.IsMap())
    fail("expected a map of keys, got " + got() +
         "; write it as `key: value` lines "
         "or as {key: value, ...}");
  std::vector<Map::Entry> entries;
  for (const auto& key_value : node_) {
    const YAML::Node key = key_value.first;  // copies: the iterator yields temporaries
    if (!key.IsScalar()) raise(*src_, key.Mark(), "a key in " + path_ + " is not a plain name");
    for (const Map::Entry& seen : entries)
      if (seen.key == key.Scalar())
        raise(*src_, key.Mark(),
              "key '" + key.Scalar() + "' is given twice in " +
                  (path_.empty() ? std::string("the top level") : path_) + " (first at line " +
                  std::to_string(seen.key_mark.line + 1) + "); keep only one");
    entries.push_back({key.Scalar(), key.Mark(), key_value.second});
  }
  return Map(*this, std::move(entries));
}

Map Field::map(std::vector<std::string> allowed) const {
  Map m = map();
  m.allow_only(allowed);
  return m;
}

// ---------------------------------------------------------------------------
// Scene sections

// A reference to a material by name; returns its index.
int material_ref(const Field& f, const std::vector<Material>& materials) {
  const std::string name = f.text();
  std::vector<std::string> known;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].name == name) return static_cast<int>(i);
    known.push_back(materials[i].name);
  }
  f.fail("unknown material '" + name + "'; known materials: " + join(known) +
         suggestion(name, known));
}

int material_ref(const Map& m, std::string_view key, const std::vector<Material>& materials) {
  return material_ref(m.get(key, "add `" + std::string(key) + ": <material name>`"), materials);
}

Domain parse_domain(const Field& f) {
  const Map m = f.map({"min", "max", "periodic"});
  Domain d;
  d.lo = m.vec3("min");
  const Field max = m.get("max", "add `max: [x, y, z]`");
  d.hi = max.vec3();
  for (int i = 0; i < 3; ++i)
    if (!(d.hi[i] > d.lo[i]))
      max.items()[i].fail("value " + max.items()[i].node().Scalar() +
                          " is not greater than domain.min[" + std::to_string(i) + "] = " +
                          format_number(d.lo[i]) + "; each max coordinate must exceed min");
  if (const auto p = m.find("periodic")) d.periodic = p->bool3();
  return d;
}

TimeSettings parse_time(const Field& f) {
  const Map m = f.map({"step", "rayleigh_fraction", "end", "expected_max_speed"});
  m.exactly_one_of("step", "rayleigh_fraction",
                   "`step` is the time step in s, `rayleigh_fraction` sets it as a fraction of "
                   "the Rayleigh time");
  TimeSettings t;
  t.step = m.maybe_number("step", kPositive);
  t.rayleigh_fraction = m.maybe_number("rayleigh_fraction", kUnitOpenBelow);
  t.end = m.number("end", kPositive);
  t.expected_max_speed = m.number_or("expected_max_speed", 1.0, kPositive);
  return t;
}

std::vector<Material> parse_materials(const Field& f) {
  std::vector<Material> out;
  std::map<std::string, int> first_line;
  for (const Field& item : f.non_empty_items("define at least one material")) {
    const Map m = item.map({"name", "youngs_modulus", "poisson_ratio", "density"});
    const Field name = m.get("name", "add `name: <material name>`");
    Material mat;
    mat.name = name.text();
    if (const auto it = first_line.find(mat.name); it != first_line.end())
      name.fail("duplicate material name '" + mat.name + "' (first defined at line " +
                std::to_string(it->second) + "); give each material a unique name");
    first_line.emplace(mat.name, name.line());
    mat.youngs_modulus = m.number("youngs_modulus", kPositive);
    mat.poisson_ratio = m.number("poisson_ratio", Range{-1, 0.5, false, false});
    mat.density = m.number("density", kPositive);
    out.push_back(mat);
  }
  return out;
}

// restitution (required), friction, rolling_friction, cohesion_energy_density.
void read_pair_properties(const Map& m, MaterialPair& p) {
  p.restitution = m.number("restitution", kUnitOpenBelow);
  p.friction = m.number_or("friction", 0.5, kNonNegative);
  p.rolling_friction = m.number_or("rolling_friction", 0.0, kNonNegative);
  p.cohesion_energy_density = m.number_or("cohesion_energy_density", 0.0, kNonNegative);
}

const std::vector<std::string> kPairPropertyKeys = {"restitution", "friction", "rolling_friction",
                                                    "cohesion_energy_density"};

std::size_t pair_count(std::size_t n) { return n * (n + 1) / 2; }

// The complete pair table, in the canonical order Scene::pair expects.
std::vector<MaterialPair> parse_pairs(const Map& top, const std::vector<Material>& materials) {
  std::map<std::pair<int, int>, std::pair<MaterialPair, int>> listed;  // (a,b) -> (props, line)
  if (const auto list = top.find("interactions")) {
    std::vector<std::string> keys = kPairPropertyKeys;
    keys.insert(keys.begin(), "materials");
    for (const Field& item : list->items()) {
      const Map m = item.map(keys);
      const Field names = m.get("materials", "add `materials: [name1, name2]`");
      const std::vector<Field> two = names.items();
      if (two.size() != 2)
        names.fail("expected a list of 2 material names, got " + names.got() +
                   "; write it as [glass, steel]");
      MaterialPair p;
      p.a = material_ref(two[0], materials);
      p.b = material_ref(two[1], materials);
      if (p.a > p.b) std::swap(p.a, p.b);
      if (const auto it = listed.find({p.a, p.b}); it != listed.end())
        names.fail("the pair (" + materials[p.a].name + ", " + materials[p.b].name +
                   ") is already given at line " + std::to_string(it->second.second) +
                   "; keep one entry per pair");
      read_pair_properties(m, p);
      listed.emplace(std::make_pair(p.a, p.b), std::make_pair(p, names.line()));
    }
  }
  std::optional<MaterialPair> defaults;
  if (const auto d = top.find("interaction_defaults")) {
    defaults.emplace();
    read_pair_properties(d->map(kPairPropertyKeys), *defaults);
  }

  const int n = static_cast<int>(materials.size());
  std::vector<MaterialPair> table;
  table.reserve(pair_count(materials.size()));
  for (int a = 0; a < n; ++a) {
    for (int b = a; b < n; ++b) {
      MaterialPair p;
      if (const auto it = listed.find({a, b}); it != listed.end()) {
        p = it->second.first;
      } else if (defaults) {
        p = *defaults;
      } else {
        const std::string pair = materials[a].name + ", " + materials[b].name;
        const Field at = top.find("interactions").value_or(top.get("materials"));
        at.fail_at_key("no interaction properties for material pair (" + pair +
                       "); add an entry with `materials: [" + pair +
                       "]` to interactions, or give interaction_defaults for unlisted pairs");
      }
      p.a = a;
      p.b = b;
      table.push_back(p);
    }
  }
  return table;
}

void parse_hooke(const Field& f, ContactSettings& c) {
  const Map m = f.map({"characteristic_velocity", "stiffness"});
  m.exactly_one_of("characteristic_velocity", "stiffness",
                   "`characteristic_velocity` derives the stiffness from Hertz theory at that "
                   "impact speed, `stiffness` gives it directly");
  c.hooke_characteristic_velocity = m.maybe_number("characteristic_velocity", kPositive);
  if (const auto s = m.find("stiffness")) {
    const Map k = s->map({"normal", "tangential"});
    c.hooke_kn = k.number("normal", kPositive);
    c.hooke_kt = k.maybe_number("tangential", kPositive);
  }
}

ContactSettings parse_contact(const Field& f) {
  const Map m = f.map({"normal", "tangential", "rolling", "cohesion", "hooke", "epsd"});
  ContactSettings c;
  c.normal = m.get("normal", "add `normal: hertz` or `normal: hooke`")
                 .choice<NormalModel>("normal contact model", {{"hertz", NormalModel::hertz},
                                                               {"hooke", NormalModel::hooke}});
  if (const auto t = m.find("tangential"))
    c.tangential = t->choice<TangentialModel>(
        "tangential contact model",
        {{"none", TangentialModel::none}, {"history", TangentialModel::history}});
  if (const auto r = m.find("rolling"))
    c.rolling = r->choice<RollingModel>(
        "rolling resistance model",
        {{"none", RollingModel::none}, {"cdt", RollingModel::cdt}, {"epsd", RollingModel::epsd}});
  if (const auto co = m.find("cohesion"))
    c.cohesion = co->choice<CohesionModel>(
        "cohesion model", {{"none", CohesionModel::none}, {"sjkr", CohesionModel::sjkr}});

  const std::optional<Field> hooke = m.find("hooke");
  if (c.normal == NormalModel::hooke)
    parse_hooke(m.get("hooke",
                      "normal: hooke needs `hooke: {characteristic_velocity: <m/s>}` or "
                      "`hooke: {stiffness: {normal: <N/m>}}`"),
                c);
  else if (hooke)
    hooke->fail_at_key(
        "settings for the hooke model are given but normal is hertz; "
        "set `normal: hooke` or remove this block");

  if (const auto epsd = m.find("epsd")) {
    if (c.rolling != RollingModel::epsd)
      epsd->fail_at_key(
          "settings for the epsd rolling model are given but rolling is not epsd; "
          "set `rolling: epsd` or remove this block");
    c.epsd_damping_ratio =
        epsd->map({"damping_ratio"}).number_or("damping_ratio", 0.3, kUnitClosed);
  }
  return c;
}

ParallelSettings parse_parallel(const Field& f) {
  const Map m = f.map({"grid", "balance"});
  ParallelSettings par;
  if (const auto g = m.find("grid")) {
    const std::vector<Field> items = g->items();
    if (items.size() != 3)
      g->fail("expected a list of 3 whole numbers (ranks along x, y, z), got " + g->got() +
              "; write it as [nx, ny, nz] with nx * ny * nz = the number of MPI ranks");
    for (int a = 0; a < 3; ++a)
      par.grid[a] = static_cast<int>(items[a].integer(Range{1, 1e6, true, true}));
  }
  if (const auto b = m.find("balance")) par.balance = b->boolean();
  return par;
}

NeighbourSettings parse_neighbour(const Field& f) {
  NeighbourSettings n;
  n.skin = f.map({"skin"}).maybe_number("skin", kPositive);
  return n;
}

// `earlier` are the walls already read, to keep names unique.
Wall parse_wall(const Field& item, const std::vector<Wall>& earlier,
                const std::vector<Material>& materials) {
  const Map m = item.map();
  Wall w;
  w.kind = m.get("type", "add `type: plane` or `type: cylinder`")
               .choice<Wall::Kind>(
                   "wall type", {{"plane", Wall::Kind::plane}, {"cylinder", Wall::Kind::cylinder}});
  if (w.kind == Wall::Kind::plane) {
    m.allow_only({"type", "name", "point", "normal", "material"}, " (a plane wall)");
    w.plane.point = m.vec3("point");
    w.plane.normal = m.direction("normal");
  } else {
    m.allow_only(
        {"type", "name", "axis_point", "axis", "radius", "side", "angular_velocity", "material"},
        " (a cylinder wall)");
    CylinderWall& c = w.cylinder;
    c.axis_point = m.vec3("axis_point");
    c.axis = m.direction("axis");
    c.radius = m.number("radius", kPositive);
    if (const auto side = m.find("side"))
      c.inside = side->choice<bool>("cylinder side", {{"inside", true}, {"outside", false}});
    c.angular_velocity = m.number_or("angular_velocity", 0.0, kAny);
  }
  const std::optional<Field> name = m.find("name");
  w.name = name ? name->text() : "wall" + std::to_string(earlier.size());
  for (const Wall& other : earlier)
    if (other.name == w.name)
      (name ? *name : item)
          .fail("duplicate wall name '" + w.name + "'; give each wall a unique name");
  w.material = material_ref(m, "material", materials);
  return w;
}

std::vector<Wall> parse_walls(const Field& f, const std::vector<Material>& materials) {
  std::vector<Wall> walls;
  for (const Field& item : f.items()) walls.push_back(parse_wall(item, walls, materials));
  return walls;
}

// The region must lie inside the domain, else particles would be created outside it.
void check_inside_domain(const Field& f, const Vec3& lo, const Vec3& hi, const Domain& d) {
  const char* axis_name[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    const double tol = 1e-12 * (d.hi[i] - d.lo[i]);  // round-off of a cylinder's extent
    if (lo[i] < d.lo[i] - tol || hi[i] > d.hi[i] + tol)
      f.fail_at_key("the region reaches outside the domain along " + std::string(axis_name[i]) +
                    " (region from " + format_number(lo[i]) + " to " + format_number(hi[i]) +
                    ", domain from " + format_number(d.lo[i]) + " to " + format_number(d.hi[i]) +
                    "); keep fill regions inside the domain");
  }
}

Region parse_region(const Field& f, const Domain& domain) {
  const Map m = f.map({"box", "cylinder"});
  m.exactly_one_of("box", "cylinder",
                   "`box: {min, max}` or `cylinder: {base, axis, radius, height}`");
  Region r;
  if (const auto box = m.find("box")) {
    const Map b = box->map({"min", "max"});
    r.kind = Region::Kind::box;
    r.lo = b.vec3("min");
    const Field max = b.get("max", "add `max: [x, y, z]`");
    r.hi = max.vec3();
    for (int i = 0; i < 3; ++i)
      if (!(r.hi[i] > r.lo[i]))
        max.items()[i].fail("value " + max.items()[i].node().Scalar() +
                            " is not greater than min[" + std::to_string(i) + "] = " +
                            format_number(r.lo[i]) + "; each max coordinate must exceed min");
    check_inside_domain(*box, r.lo, r.hi, domain);
    return r;
  }
  const Field cyl = *m.find("cylinder");
  const Map c = cyl.map({"base", "axis", "radius", "height"});
  r.kind = Region::Kind::cylinder;
  r.base = c.vec3("base");
  r.axis = c.direction("axis");
  r.radius = c.number("radius", kPositive);
  r.height = c.number("height", kPositive);
  // Bounding box: the two end discs; a disc of radius R normal to unit a spans
  // R*sqrt(1 - a_i^2) along axis i.
  const Vec3 top = r.base + r.height * r.axis;
  const Vec3 half =
      (Vec3::Ones() - r.axis.cwiseProduct(r.axis)).cwiseMax(0.0).cwiseSqrt() * r.radius;
  check_inside_domain(cyl, r.base.cwiseMin(top) - half, r.base.cwiseMax(top) + half, domain);
  return r;
}

void parse_normal_distribution(const Map& m, SizeDistribution& s) {
  s.mean = m.number("mean", kPositive);
  s.stddev = m.number("stddev", kPositive);
  // Default truncation at mean +- 3 sigma; a non-positive lower bound is clipped to
  // mean/10 so no vanishingly small particle wrecks the time step.
  s.min = m.number_or("min", std::max(s.mean - 3 * s.stddev, 0.1 * s.mean), kPositive);
  s.max = m.number_or("max", s.mean + 3 * s.stddev, kPositive);
  if (!(s.min <= s.mean))
    m.find("min").value_or(m.self()).fail("the lower bound " + format_number(s.min) +
                                          " is above the mean " + format_number(s.mean) +
                                          "; need min <= mean <= max");
  if (!(s.max >= s.mean))
    m.find("max").value_or(m.self()).fail("the upper bound " + format_number(s.max) +
                                          " is below the mean " + format_number(s.mean) +
                                          "; need min <= mean <= max");
}

void parse_discrete_distribution(const Map& m, SizeDistribution& s) {
  s.values = m.get("values", "add `values: [r1, r2, ...]`").numbers(kPositive);
  const std::optional<Field> w = m.find("weights");
  if (!w) {
    s.weights.assign(s.values.size(), 1.0 / static_cast<double>(s.values.size()));
    return;
  }
  s.weights = w->numbers(kPositive);
  if (s.weights.size() != s.values.size())
    w->fail(std::to_string(s.weights.size()) + " weights are given for " +
            std::to_string(s.values.size()) + " values; give one weight per radius");
  double sum = 0;
  for (double x : s.weights) sum += x;
  for (double& x : s.weights) x /= sum;
}

SizeDistribution parse_size_distribution(const Field& f) {
  const Map m = f.map();
  SizeDistribution s;
  using K = SizeDistribution::Kind;
  s.kind = m.get("distribution", "add `distribution: constant` (or uniform, normal, discrete)")
               .choice<K>("size distribution", {{"constant", K::constant},
                                                {"uniform", K::uniform},
                                                {"normal", K::normal},
                                                {"discrete", K::discrete}});
  switch (s.kind) {
    case K::constant:
      m.allow_only({"distribution", "value"}, " (a constant size)");
      s.value = m.number("value", kPositive);
      break;
    case K::uniform: {
      m.allow_only({"distribution", "min", "max"}, " (a uniform distribution)");
      s.min = m.number("min", kPositive);
      s.max = m.number("max", kPositive);
      if (s.max < s.min)
        m.get("max").fail("value " + m.get("max").node().Scalar() +
                          " is less than min = " + format_number(s.min) + "; need 0 < min <= max");
      break;
    }
    case K::normal:
      m.allow_only({"distribution", "mean", "stddev", "min", "max"}, " (a normal distribution)");
      parse_normal_distribution(m, s);
      break;
    case K::discrete:
      m.allow_only({"distribution", "values", "weights"}, " (a discrete distribution)");
      parse_discrete_distribution(m, s);
      break;
  }
  return s;
}

void parse_fill(const Map& m, const Scene& scene, Insertion& ins) {
  m.allow_only(
      {"type", "region", "count", "volume_fraction", "material", "radius", "velocity", "seed"},
      " (a fill insertion)");
  ins.region =
      parse_region(m.get("region", "add `region: {box: {min: [..], max: [..]}}`"), scene.domain);
  m.exactly_one_of("count", "volume_fraction",
                   "`count` is a number of particles, `volume_fraction` the solid fraction of the "
                   "region");
  if (const auto c = m.find("count")) ins.count = static_cast<long>(c->integer(kPositive));
  ins.volume_fraction = m.maybe_number("volume_fraction", Range{0, 0.6, false, true});
  ins.material = material_ref(m, "material", scene.materials);
  ins.radius = parse_size_distribution(
      m.get("radius", "add `radius: {distribution: constant, value: <m>}`"));
  ins.velocity = m.vec3_or("velocity", Vec3::Zero());
  if (const auto s = m.find("seed"))
    ins.seed = static_cast<unsigned>(s->integer(Range{0, double(UINT_MAX), true, true}));
}

void parse_csv(const Map& m, const Scene& scene, Insertion& ins) {
  m.allow_only({"type", "file", "material"}, " (a csv insertion)");
  const Field file = m.get("file", "add `file: <particles.csv>`");
  const fs::path given = file.text();
  const fs::path resolved = given.is_absolute() ? given : file.source().folder / given;
  std::error_code ec;
  if (!fs::is_regular_file(resolved, ec))
    file.fail("particle file '" + given.string() + "' not found (looked for '" + resolved.string() +
              "'); file names are relative to the scene file's folder");
  ins.csv_file = resolved.string();
  ins.material = material_ref(m, "material", scene.materials);
}

std::vector<Insertion> parse_insertions(const Field& f, const Scene& scene) {
  std::vector<Insertion> out;
  for (const Field& item : f.items()) {
    const Map m = item.map();
    Insertion ins;
    ins.source = item.source().label + ":" + std::to_string(item.line());
    ins.kind = m.get("type", "add `type: fill` or `type: csv`")
                   .choice<Insertion::Kind>("insertion type", {{"fill", Insertion::Kind::fill},
                                                               {"csv", Insertion::Kind::csv}});
    if (ins.kind == Insertion::Kind::fill)
      parse_fill(m, scene, ins);
    else
      parse_csv(m, scene, ins);
    out.push_back(std::move(ins));
  }
  return out;
}

OutputSettings parse_output(const Field& f) {
  const Map m = f.map({"directory", "snapshot_interval", "log_interval", "progress"});
  OutputSettings o;
  if (const auto d = m.find("directory")) o.directory = d->text();
  o.snapshot_interval = m.maybe_number("snapshot_interval", kPositive);
  o.log_interval = m.maybe_number("log_interval", kPositive);
  if (const auto p = m.find("progress")) o.progress = p->boolean();
  return o;
}

const std::vector<std::string> kTopLevelKeys = {
    "domain",  "gravity",   "time",  "materials", "interactions", "interaction_defaults",
    "contact", "neighbour", "walls", "insert",    "output", "parallel"};

Scene build_scene(const Field& root) {
  if (!root.node().IsDefined() || root.node().IsNull())
    root.fail("the scene is empty; it needs at least domain, time, materials and contact");
  if (!root.node().IsMap())
    root.fail("expected top-level keys (domain:, time:, materials:, contact:, ...), got " +
              root.got() + "; see docs/scene-reference.md");
  const Map top = root.map(kTopLevelKeys);
  Scene s;
  s.file = root.source().label;
  s.domain = parse_domain(top.get("domain", "add `domain: {min: [x, y, z], max: [x, y, z]}`"));
  s.gravity = top.vec3_or("gravity", Vec3::Zero());
  s.time = parse_time(top.get("time", "add `time: {step: <s>, end: <s>}`"));
  s.materials = parse_materials(top.get("materials", "add a list of materials"));
  s.pairs = parse_pairs(top, s.materials);
  s.contact = parse_contact(top.get("contact", "add `contact: {normal: hertz}`"));
  if (const auto n = top.find("neighbour")) s.neighbour = parse_neighbour(*n);
  if (const auto w = top.find("walls")) s.walls = parse_walls(*w, s.materials);
  if (const auto i = top.find("insert")) s.insertions = parse_insertions(*i, s);
  if (const auto o = top.find("output")) s.output = parse_output(*o);
  if (const auto p = top.find("parallel")) s.parallel = parse_parallel(*p);
  return s;
}

// YAML forbids tabs in indentation, and yaml-cpp's message for them is cryptic:
// name the first offending line at or before the error instead.
void raise_if_tab_indented(const std::string& text, int error_line, const Source& src) {
  std::istringstream lines(text);
  std::string line;
  for (int n = 0; n <= error_line && std::getline(lines, line); ++n) {
    const std::size_t first = line.find_first_not_of(" \t");
    const std::size_t tab = line.find('\t');
    if (tab != std::string::npos && tab < first) {
      YAML::Mark m = start_of_file();
      m.line = n;
      m.column = static_cast<int>(tab);
      raise(src, m, "YAML syntax error: a tab is used for indentation; indent with spaces only");
    }
  }
}

YAML::Node load_yaml(const std::string& text, const Source& src) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    raise_if_tab_indented(text, e.mark.line, src);
    raise(src, e.mark,
          "YAML syntax error: " + e.msg +
              "; check indentation, brackets, quotes and the ':' after each key");
  } catch (const YAML::Exception& e) {
    raise(src, e.mark.line >= 0 ? e.mark : start_of_file(),
          "the file cannot be read as YAML: " + e.msg);
  }
}

}  // namespace

Scene parse_scene(const std::string& yaml_text, const std::string& file_label) {
  const Source src{file_label, fs::path(file_label).parent_path()};
  const Field root(src, load_yaml(yaml_text, src), "", start_of_file());
  return build_scene(root);
}

Scene load_scene(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in || fs::is_directory(path))
    throw SceneError(path, 0, 0,
                     "cannot open the scene file; check the path (relative paths are taken from "
                     "the working directory " +
                         fs::current_path().string() + ")");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw SceneError(path, 0, 0, "cannot read the scene file; check its permissions");
  return parse_scene(text.str(), path);
}

}  // namespace grainflow
