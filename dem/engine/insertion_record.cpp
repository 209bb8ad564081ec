#include "dem/engine/insertion_record.hpp"

#include <algorithm>
#include <charconv>
#include <sstream>
#include <utility>
#include <vector>

#include "dem/core/fnv1a.hpp"
#include "dem/engine/restored_state.hpp"

namespace grainflow {
namespace {

using Fields = std::vector<std::pair<std::string, std::string>>;

// Numbers in their shortest form that reads back to the same double (std::to_chars),
// separated by spaces, after a word: "box 0 0 0.001 0.03 0.03 0.039". (A stream, not a chain
// of string additions: GCC 12 at -O3 warns of those, -Wrestrict.)
class Text {
 public:
  explicit Text(const char* word = "") { out_ << word; }
  Text& operator<<(double v) {
    out_ << (out_.tellp() > 0 ? " " : "") << shortest(v);
    return *this;
  }
  Text& operator<<(const Vec3& v) { return *this << v[0] << v[1] << v[2]; }
  Text& pair(double a, double b) {  // "a:b"
    out_ << (out_.tellp() > 0 ? " " : "") << shortest(a) << ':' << shortest(b);
    return *this;
  }
  std::string str() const { return out_.str(); }

 private:
  static std::string shortest(double v) {
    char buffer[32];
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, v);
    return error == std::errc() ? std::string(buffer, end) : std::string("?");
  }
  std::ostringstream out_;
};

std::string number(double v) { return (Text() << v).str(); }

const char* kind_name(Insertion::Kind k) {
  switch (k) {
    case Insertion::Kind::fill:
      return "fill";
    case Insertion::Kind::csv:
      return "csv";
    case Insertion::Kind::stream:
      return "stream";
    case Insertion::Kind::snapshot:
      return "snapshot";
  }
  return "?";
}

std::string radius_text(const SizeDistribution& r) {
  switch (r.kind) {
    case SizeDistribution::Kind::constant:
      return (Text("constant") << r.value).str();
    case SizeDistribution::Kind::uniform:
      return (Text("uniform") << r.min << r.max).str();
    case SizeDistribution::Kind::normal:
      return (Text("normal") << r.mean << r.stddev << r.min << r.max).str();
    case SizeDistribution::Kind::discrete: {
      Text t("discrete");
      for (std::size_t k = 0; k < r.values.size(); ++k)
        t.pair(r.values[k], k < r.weights.size() ? r.weights[k] : 0.0);
      return t.str();
    }
  }
  return "?";
}

Fields fields_of(const Insertion& in, const Scene& scene) {
  Fields f{{"kind", kind_name(in.kind)}};
  const auto add = [&f](const char* key, std::string value) {
    f.emplace_back(key, std::move(value));
  };
  const bool made = in.kind == Insertion::Kind::fill || in.kind == Insertion::Kind::stream;
  if (made) {  // coarse_grain first: it also changes the material's name and the radii
    add("coarse_grain", number(in.coarse_grain));
    const auto m = static_cast<std::size_t>(in.material);
    add("material", m < scene.materials.size() ? scene.materials[m].name : std::to_string(m));
    add("seed", std::to_string(in.seed));
    add("radius", radius_text(in.radius));
    add("velocity", (Text() << in.velocity).str());
  }
  if (in.kind == Insertion::Kind::fill) {
    const Region& g = in.region;
    add("region", g.kind == Region::Kind::box
                      ? (Text("box") << g.lo << g.hi).str()
                      : (Text("cylinder") << g.base << g.axis << g.radius << g.height).str());
    if (in.count) add("count", std::to_string(*in.count));
    if (in.volume_fraction) add("volume_fraction", number(*in.volume_fraction));
  }
  if (in.kind == Insertion::Kind::stream) {
    const InsertionFace& face = in.face;
    add("face", face.kind == InsertionFace::Kind::rectangle
                    ? (Text("rectangle")
                       << face.centre << face.normal << face.u << face.length_u << face.length_v)
                          .str()
                    : (Text("disc") << face.centre << face.normal << face.radius).str());
    if (in.mass_rate) add("mass_rate", number(*in.mass_rate));
    if (in.count_rate) add("count_rate", number(*in.count_rate));
    add("start", number(in.start));
    if (in.stop) add("stop", number(*in.stop));
  }
  if (in.kind == Insertion::Kind::snapshot) {
    add("keep_velocity", in.keep_velocity ? "true" : "false");
    add("coarse_grain", number(in.coarse_grain));
  }
  if (in.temperature) add("temperature", number(*in.temperature));
  return f;
}

std::string line_of(const Fields& f) {
  std::ostringstream s;
  for (std::size_t k = 0; k < f.size(); ++k)
    s << (k ? "; " : "") << f[k].first << '=' << f[k].second;
  return s.str();
}

Fields parse_line(const std::string& line) {
  Fields f;
  std::size_t at = 0;
  while (at <= line.size()) {
    std::size_t end = line.find("; ", at);
    if (end == std::string::npos) end = line.size();
    const std::string field = line.substr(at, end - at);
    const std::size_t eq = field.find('=');
    if (eq != std::string::npos) f.emplace_back(field.substr(0, eq), field.substr(eq + 1));
    at = end + 2;
  }
  return f;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(line);
  return out;
}

const std::string* find(const Fields& f, const std::string& key) {
  for (const auto& [k, v] : f)
    if (k == key) return &v;
  return nullptr;
}

// The record's first line, followed by the number of insertions.
const std::string kHeader = "grainflow insertions ";

constexpr const char* kWhy =
    "A restart continues that run as it was: it inserts nothing at t = 0 (fills, csv and "
    "snapshot insertions are in the checkpoint's particles) and continues each stream from "
    "what it has delivered, so a changed insertion would not take effect, or (a stream's "
    "rate) would deliver at once what it owed since t = 0. Restore the `insert` section as "
    "the checkpoint's run had it, or start the changed scene afresh (to keep the run's "
    "particles, insert its last snapshot with `type: snapshot`)";

}  // namespace

std::string insertion_record(const Scene& scene) {
  std::string out = std::string(kHeader) + std::to_string(scene.insertions.size()) + "\n";
  for (const Insertion& in : scene.insertions) out += line_of(fields_of(in, scene)) + "\n";
  return out;
}

std::uint64_t scene_fingerprint(const Scene& scene) {
  std::string text = insertion_record(scene);
  for (const Material& m : scene.materials)
    text += m.name + " " + number(m.density) + " " + number(m.coarse_grain) + "\n";
  // The model (gravity, walls, contact, ...), its lines sorted: a run with other physics is
  // another run, whose snapshots a restart must not take over.
  std::vector<std::string> model;
  std::istringstream lines(scene.model_record);
  for (std::string line; std::getline(lines, line);) model.push_back(line);
  std::sort(model.begin(), model.end());
  for (const std::string& line : model) text += line + "\n";
  return fnv1a64(text);
}

void check_insertions(const std::string& written, const Scene& scene,
                      const std::string& checkpoint_file) {
  std::vector<std::string> before = lines_of(written);
  // The header line counts the insertions; a record that does not start with it, or whose
  // count is not its number of lines, was not written by insertion_record.
  const std::string count = std::to_string(before.empty() ? std::size_t{0} : before.size() - 1);
  if (before.empty() || before.front() != kHeader + count)
    throw StateError(checkpoint_file +
                     ": error: dataset '/streams/insertions' does not begin with '" + kHeader +
                     count +
                     "'; the checkpoint was changed or damaged after it was written: "
                     "restart from an earlier checkpoint of this run");
  before.erase(before.begin());
  const std::size_t now = scene.insertions.size();
  const std::string run = "the run that wrote checkpoint '" + checkpoint_file + "'";
  for (std::size_t i = 0; i < std::min(before.size(), now); ++i) {
    const Insertion& in = scene.insertions[i];
    const Fields was = parse_line(before[i]), is = fields_of(in, scene);
    if (line_of(is) == line_of(was)) continue;
    std::string key, here = "not given", there = "not given";
    for (const auto& [k, v] : is)
      if (const std::string* w = find(was, k); !w || *w != v) {
        key = k;
        here = v;
        if (w) there = *w;
        break;
      }
    if (key.empty())
      for (const auto& [k, v] : was)
        if (!find(is, k)) {
          key = k;
          there = v;
          break;
        }
    throw StateError(in.source + ": error: insert[" + std::to_string(i) + "] (" +
                     kind_name(in.kind) + ") is not the insertion " + run + " had: " + key +
                     " is " + here + " here, " + there + " in that run. " + kWhy);
  }
  if (now > before.size()) {
    const Insertion& in = scene.insertions[before.size()];
    throw StateError(in.source + ": error: insert[" + std::to_string(before.size()) + "] (" +
                     kind_name(in.kind) + ") is not in " + run + ", which had " +
                     std::to_string(before.size()) + " insertion(s). " + kWhy);
  }
  if (now < before.size())
    throw StateError(scene.file + ": error: the scene has " + std::to_string(now) +
                     " insertion(s), " + run + " had " + std::to_string(before.size()) +
                     "; the missing insert[" + std::to_string(now) + "] was: " + before[now] +
                     ". " + kWhy);
}

namespace {
// "path = value" lines as (path, value) pairs, in their order.
std::vector<std::pair<std::string, std::string>> model_entries(const std::string& record) {
  std::vector<std::pair<std::string, std::string>> out;
  std::istringstream in(record);
  for (std::string line; std::getline(in, line);) {
    const auto eq = line.find(" = ");
    if (eq == std::string::npos) continue;
    out.emplace_back(line.substr(0, eq), line.substr(eq + 3));
  }
  return out;
}
}  // namespace

void check_model(const std::string& written, const Scene& scene, const std::string& checkpoint_file,
                 std::string_view only) {
  if (written == scene.model_record) return;
  auto was = model_entries(written), is = model_entries(scene.model_record);
  // A checkpoint from before mesh walls were recorded by content (walls[k].file = <name>):
  // compared without the mesh files.
  const auto mesh_line = [](const auto& e, const char* field) {
    return e.first.starts_with("walls[") && e.first.ends_with(field);
  };
  if (std::none_of(was.begin(), was.end(),
                   [&](const auto& e) { return mesh_line(e, "].file_content"); })) {
    std::erase_if(was, [&](const auto& e) { return mesh_line(e, "].file"); });
    std::erase_if(is, [&](const auto& e) { return mesh_line(e, "].file_content"); });
  }
  const auto value_in = [](const auto& entries, const std::string& path) -> const std::string* {
    for (const auto& [p, v] : entries)
      if (p == path) return &v;
    return nullptr;
  };
  std::string where = scene.file, path, here, there;
  const auto skipped = [only](const std::string& p) { return !p.starts_with(only); };
  for (std::size_t k = 0; k < is.size() && path.empty(); ++k) {
    if (skipped(is[k].first)) continue;
    const std::string* w = value_in(was, is[k].first);
    if (w && *w == is[k].second) continue;
    path = is[k].first;
    here = is[k].second;
    there = w ? *w : std::string("not given (its default)");
    if (k < scene.model_sources.size()) where = scene.model_sources[k];
  }
  for (std::size_t k = 0; k < was.size() && path.empty(); ++k)
    if (!skipped(was[k].first) && !value_in(is, was[k].first)) {
      path = was[k].first;
      here = "not given (its default)";
      there = was[k].second;
    }
  if (path.empty()) return;  // the same entries in another order: the same model
  std::ostringstream o;
  if (path.starts_with("walls[") && path.ends_with("].file_content")) {
    const std::size_t k = std::stoul(path.substr(6));
    const std::string file = k < scene.walls.size() ? scene.walls[k].mesh.file : std::string("?");
    o << where << ": error: the STL file '" << file << "' of walls[" << k << "] is not the one "
      << "the run that wrote checkpoint '" << checkpoint_file << "' read (" << here << " here, "
      << there
      << " then). A restart continues that run with its walls: restore that file (moved or "
         "renamed is fine, its contents count), or start the changed scene afresh (to keep the "
         "run's particles, insert its last snapshot with `type: snapshot`)";
    throw StateError(o.str());
  }
  o << where << ": error: " << path << " is " << here << " here, " << there
    << " in the run that wrote checkpoint '" << checkpoint_file
    << "'. A restart continues that run as it was, with its model (domain, gravity, materials, "
       "interactions, contact, walls, heat, fluid): a changed one would go on as another run "
       "under the same name, from a state that run did not make. Restore "
    << path << (there.starts_with("not given") ? " to its default (leave it out)" : " to " + there)
    << ", or start the changed scene afresh (to keep the run's particles, insert its last "
       "snapshot with `type: snapshot`)";
  throw StateError(o.str());
}

}  // namespace grainflow
