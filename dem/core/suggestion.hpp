#pragma once
// "Did you mean" for a misspelt name: the closest of the allowed names by edit distance. For
// every message that names a wrong word (scene keys and choices, grainFoam's
// couplingProperties keys); no dependency beyond the standard library.
#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

namespace grainflow {

// Levenshtein distance: insertions, deletions and substitutions of one character each.
inline std::size_t edit_distance(std::string_view a, std::string_view b) {
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
inline std::string suggestion(std::string_view given, const std::vector<std::string>& candidates) {
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

}  // namespace grainflow
