// Did-you-mean suggestions for misspelt scene keys, types and material names (edit distance).
#pragma once

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "glint/readers/diagnostics.h"

namespace glint {

// Edit distance between a and b ignoring ASCII case: insertions, deletions, substitutions and
// transpositions of neighbours each count 1 (optimal string alignment, Damerau 1964), so "srbg" is
// one edit from "srgb".
inline std::size_t editDistance(std::string_view a, std::string_view b) {
  const auto same = [&](std::size_t i, std::size_t j) {
    return std::tolower(static_cast<unsigned char>(a[i])) ==
           std::tolower(static_cast<unsigned char>(b[j]));
  };
  const std::size_t columns = b.size() + 1;
  std::vector<std::size_t> d((a.size() + 1) * columns);
  for (std::size_t i = 0; i <= a.size(); ++i) d[i * columns] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      std::size_t best = std::min({d[(i - 1) * columns + j] + 1, d[i * columns + j - 1] + 1,
                                   d[(i - 1) * columns + j - 1] + (same(i - 1, j - 1) ? 0 : 1)});
      if (i > 1 && j > 1 && same(i - 1, j - 2) && same(i - 2, j - 1)) {
        best = std::min(best, d[(i - 2) * columns + j - 2] + 1);
      }
      d[i * columns + j] = best;
    }
  }
  return d[a.size() * columns + b.size()];
}

// A candidate's name: itself, or a map entry's key. (Not std::views::keys: clang before 16 cannot
// compile libstdc++ 12's views, and the fuzzers build with clang.)
template <class T>
std::string_view candidateName(const T& candidate) {
  return std::string_view(candidate);
}
template <class K, class V>
std::string_view candidateName(const std::pair<K, V>& entry) {
  return std::string_view(entry.first);
}

// The candidate closest to `word` when it is close enough to be a plausible typo (at most a third
// of the longer word's letters differ, and at most 3), else empty.
template <class Names>
std::string closestName(std::string_view word, const Names& candidates) {
  // No key is this long: a suggestion would only cost time (the distance is quadratic).
  constexpr std::size_t kLongestWord = 64;
  if (word.size() > kLongestWord) return {};
  std::string best;
  std::size_t bestDistance = 0;
  for (const auto& candidate : candidates) {
    const std::string_view name = candidateName(candidate);
    const std::size_t limit = std::min<std::size_t>(3, std::max(word.size(), name.size()) / 3);
    // The distance is at least the difference in length: a candidate that far (every long one)
    // costs no distance matrix.
    const std::size_t lengths =
        name.size() > word.size() ? name.size() - word.size() : word.size() - name.size();
    if (lengths > std::max<std::size_t>(limit, 1)) continue;
    const std::size_t d = editDistance(word, name);
    if (word == name || d > std::max<std::size_t>(limit, 1)) continue;
    if (best.empty() || d < bestDistance) {
      best = std::string(name);
      bestDistance = d;
    }
  }
  return best;
}

// " (did you mean 'radius'?)" or "".
template <class Names>
std::string didYouMean(std::string_view word, const Names& candidates) {
  const std::string best = closestName(word, candidates);
  return best.empty() ? std::string() : " (did you mean '" + nameForMessage(best) + "'?)";
}

// The hint after "undefined material 'x'" (and texture, group): " (did you mean 'y'?)" when a
// defined name is close, else "; defined: a, b, c and 37 more" — the first kListedNames in byte
// order, as messages show names (nameForMessage) —, else `none` when nothing is defined. A word
// longer than any name may be says so. The did-you-mean search reads every defined name, so only
// the first kMaxNameHints undefined names of a kind get one (`hintsLeft` counts down; the rest get
// the list): thousands of undefined names among thousands of definitions took minutes.
// `defined`: a map whose keys are the defined names.
inline constexpr std::size_t kListedNames = 10;
inline constexpr int kMaxNameHints = 20;
template <class Map>
std::string undefinedNameHint(std::string_view word, const Map& defined, std::string_view none,
                              int& hintsLeft) {
  if (word.size() > kMaxNameBytes) {
    return "; names are at most " + std::to_string(kMaxNameBytes) + " bytes";
  }
  if (defined.empty()) return std::string(none);
  if (hintsLeft > 0) {
    --hintsLeft;
    std::string hint = didYouMean(word, defined);
    if (!hint.empty()) return hint;
  }
  std::string hint = "; defined: ";
  std::size_t listed = 0;
  for (const auto& entry : defined) {
    if (listed == kListedNames) break;
    if (listed++ > 0) hint += ", ";
    hint += nameForMessage(entry.first);
  }
  if (defined.size() > kListedNames) {
    hint += " and " + std::to_string(defined.size() - kListedNames) + " more";
  }
  return hint;
}

}  // namespace glint
