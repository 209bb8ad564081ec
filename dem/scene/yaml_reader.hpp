#pragma once
// The scene parser's reading layer, shared by the section parsers (scene_parser.cpp,
// fluid_section.cpp): Field, Map and Range turn YAML nodes into numbers, vectors,
// names and model choices, checking type and range and remembering where in the file
// each value came from, so every error can point at it (SceneError, file:line:column).
// Moved here unchanged from scene_parser.cpp's anonymous namespace.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "dem/core/suggestion.hpp"
#include "dem/core/types.hpp"
#include "dem/scene/scene_error.hpp"

namespace grainflow::scene_yaml {

constexpr double kInf = std::numeric_limits<double>::infinity();

using grainflow::edit_distance;
using grainflow::suggestion;

// ---------------------------------------------------------------------------
// Message helpers

inline std::string format_number(double x) {
  std::ostringstream s;
  s << std::setprecision(12) << x;
  return s.str();
}

inline std::string join(const std::vector<std::string>& items, std::string_view separator = ", ") {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += separator;
    out += items[i];
  }
  return out;
}

// " (it holds the character U+200B, at character 5: retype it)" when `name` holds a character
// outside printable ASCII (a zero-width or non-breaking space pasted in shows as nothing), else "".
inline std::string hidden_character(std::string_view name) {
  std::size_t position = 0;
  for (std::size_t i = 0; i < name.size(); ++position) {
    const auto c = static_cast<unsigned char>(name[i]);
    if (c >= 0x20 && c < 0x7f) {
      ++i;
      continue;
    }
    // One UTF-8 sequence: its code point (a malformed byte is shown as itself).
    const int extra = c >= 0xf0 ? 3 : c >= 0xe0 ? 2 : c >= 0xc0 ? 1 : 0;
    unsigned long code = extra == 0 ? c : c & (0x3fu >> extra);
    for (int k = 1; k <= extra && i + k < name.size(); ++k)
      code = (code << 6) | (static_cast<unsigned char>(name[i + k]) & 0x3fu);
    char hex[16];
    std::snprintf(hex, sizeof hex, "U+%04lX", code);
    return " (it holds the character " + std::string(hex) + ", at character " +
           std::to_string(position + 1) + ", which may not show: retype it)";
  }
  return "";
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
  std::filesystem::path folder;    // relative file names inside the scene are resolved against it
};

// A message with every word (a run without spaces) longer than 200 characters shown by its
// first 60 and its length: a value pasted in or the wrong file given, quoted into a message
// (an unknown model's name, a number beyond a double, a list of names), stays readable.
inline std::string shorten_long_words(const std::string& message) {
  std::string out;
  std::size_t i = 0;
  while (i < message.size()) {
    const std::size_t end = std::min(message.find(' ', i), message.size());
    if (end - i > 200) {
      // Its closing quote and punctuation stay ("'...(200003 characters)';").
      std::size_t tail = 0;
      while (tail < 3 && std::string("';,.)").find(message[end - 1 - tail]) != std::string::npos)
        ++tail;
      out += message.substr(i, 60) + "...(" + std::to_string(end - i) + " characters)" +
             message.substr(end - tail, tail);
    } else
      out.append(message, i, end - i);
    if (end < message.size()) out += ' ';
    i = end + 1;
  }
  return out;
}

[[noreturn]] inline void raise(const Source& src, const YAML::Mark& mark, const std::string& message) {
  // yaml-cpp marks are 0-based; ours are 1-based.
  throw SceneError(src.label, mark.line + 1, mark.column + 1, shorten_long_words(message));
}

inline YAML::Mark start_of_file() {
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
    // A missing value (`key:` alone) has no useful mark of its own; use the key's. An alias
    // (`end: *g`) has its anchor's mark, before its key: the key is where it is used.
    const bool has_own_mark = node_.IsDefined() && !node_.IsNull() && node_.Mark().line >= 0 &&
                              node_.Mark().pos >= key_mark_.pos;
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
  // A note at the key that names this value, as an error would name it but not thrown:
  // "<file>:<line>:<column>: note: <path>: <message>" (a setting that has no effect).
  std::string note_at_key(const std::string& message) const {
    return src_->label + ":" + std::to_string(key_mark_.line + 1) + ":" +
           std::to_string(key_mark_.column + 1) + ": note: " + prefixed(message);
  }

  double number(const Range& range = kAny) const {
    const std::optional<double> x = as_number(node_);
    if (!x) {
      if (looks_numeric())
        fail("value " + node_.Scalar() +
             " is beyond the range of a double (magnitudes up to "
             "1.8e308); write a finite number");
      fail("expected a number, got " + got() + "; write a plain number such as 0.5 or 2e-3");
    }
    // Below the smallest normal double: arithmetic on it loses its digits (a viscosity of
    // 1e-320 gave NaN drag), and no physical input is that small.
    if (*x != 0 && std::abs(*x) < std::numeric_limits<double>::min())
      fail("value " + node_.Scalar() +
           " is below the smallest normal double (2.2e-308); write "
           "0 or a number of a physical size");
    check_range(*x, range);
    return *x;
  }

  long long integer(const Range& range) const {
    const std::optional<double> x = as_number(node_);
    if (x && std::floor(*x) == *x && std::abs(*x) > 9e15)
      fail("value " + node_.Scalar() + " is too large for a whole number here (at most 9e15)");
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
      // An alias among the items has its anchor's mark, before the list: use the list's.
      const bool own = !item.IsNull() && item.Mark().line >= 0 && item.Mark().pos >= mark_.pos;
      const YAML::Mark m = own ? item.Mark() : mark_;
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
  // Scaled by its largest component first: the squares of components beyond 1.3e154 overflow
  // (the length was inf, and the direction [0, 0, 0]), and those below 1e-154 underflow.
  Vec3 direction() const {
    const Vec3 v = vec3();
    const double largest = v.cwiseAbs().maxCoeff();
    if (!(largest > 0)) fail("the direction [0, 0, 0] has no length; give a non-zero vector");
    return (v / largest).normalized();
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
    // A long value (a file pasted in, the wrong file given) is shown by its start.
    const std::string& text = node_.Scalar();
    if (text.size() > 80)
      return "'" + text.substr(0, 60) + "...' (" + std::to_string(text.size()) + " characters)";
    return "'" + text + "'";
  }

 private:
  // A decimal number in form (digits, a point, an exponent), whatever its size.
  bool looks_numeric() const {
    if (!node_.IsScalar()) return false;
    const std::string& t = node_.Scalar();
    std::size_t i = (t.size() > 0 && (t[0] == '+' || t[0] == '-')) ? 1 : 0;
    bool digits = false;
    while (i < t.size() && (std::isdigit(static_cast<unsigned char>(t[i])) || t[i] == '.'))
      digits |= t[i++] != '.';
    if (!digits) return false;
    if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
      ++i;
      if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
      const std::size_t start = i;
      while (i < t.size() && std::isdigit(static_cast<unsigned char>(t[i]))) ++i;
      if (i == start) return false;
    }
    return i == t.size();
  }

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
            "unknown key '" + e.key + "' in " + where() + what + "; allowed keys: " +
                join(allowed) + suggestion(e.key, allowed) + hidden_character(e.key));
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

inline Map Field::map() const {
  if (!node_.IsMap())
    fail("expected a map of keys, got " + got() +
         "; write it as `key: value` lines "
         "or as {key: value, ...}");
  std::vector<Map::Entry> entries;
  // Key -> its entry: a hostile map of many keys costs linear, not quadratic, time.
  std::unordered_map<std::string, std::size_t> seen;
  for (const auto& key_value : node_) {
    const YAML::Node key = key_value.first;  // copies: the iterator yields temporaries
    if (!key.IsScalar()) raise(*src_, key.Mark(), "a key in " + path_ + " is not a plain name");
    if (key.Scalar() == "<<" && key.Tag() != "!")
      raise(*src_, key.Mark(),
            "YAML merge keys ('<<: *anchor') are not supported in a scene; write the keys out "
            "(an alias of a whole value, `key: *anchor`, works)");
    if (const auto it = seen.find(key.Scalar()); it != seen.end())
      raise(*src_, key.Mark(),
            "key '" + key.Scalar() + "' is given twice in " +
                (path_.empty() ? std::string("the top level") : path_) + " (first at line " +
                std::to_string(entries[it->second].key_mark.line + 1) + "); keep only one");
    seen.emplace(key.Scalar(), entries.size());
    entries.push_back({key.Scalar(), key.Mark(), key_value.second});
  }
  return Map(*this, std::move(entries));
}

inline Map Field::map(std::vector<std::string> allowed) const {
  Map m = map();
  m.allow_only(allowed);
  return m;
}

}  // namespace grainflow::scene_yaml
