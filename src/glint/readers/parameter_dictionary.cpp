#include "glint/readers/parameter_dictionary.h"

#include "glint/core/bounds.h"
#include "glint/core/seeded_hash.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>

#include "glint/readers/spelling.h"
#include "glint/readers/text_statements.h"

namespace glint {

namespace {

// A YAML 1.2 core-schema float (also 1.1's .inf/.nan spellings), as text → double. Accepts any
// usual notation: 0.00001, 1e-5, 1.5E+3, +2, .5; "inf"/"nan" forms parse to non-finite values,
// which the caller rejects with a precise message. A magnitude beyond the double range is
// infinite; one below it is what strtod rounds it to (0 or a subnormal), not an error.
std::optional<double> parseDouble(std::string_view text) {
  if (text == ".inf" || text == ".Inf" || text == ".INF" || text == "+.inf" || text == "+.Inf" ||
      text == "+.INF") {
    return std::numeric_limits<double>::infinity();
  }
  if (text == "-.inf" || text == "-.Inf" || text == "-.INF") {
    return -std::numeric_limits<double>::infinity();
  }
  if (text == ".nan" || text == ".NaN" || text == ".NAN") {
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (text.size() > 1 && text[0] == '+' && text[1] != '-') text.remove_prefix(1);
  if (text.empty()) return std::nullopt;
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ptr != end) return std::nullopt;
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves the value unset; strtod says which way it is out of range.
    return outOfRangeNumber(text);
  }
  if (ec != std::errc()) return std::nullopt;
  return value;
}

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Below this many entries duplicate keys are found by comparing pairs; above, by a hash table, so
// that a mapping with 400,000 keys is read in linear time.
constexpr std::size_t kPairwiseDuplicateLimit = 16;

}  // namespace

std::string ValuePath::str() const {
  std::string base = parent != nullptr ? parent->str() : std::string(prefix);
  if (index != kNoIndex) return fmt::format("{}[{}]", base, index);
  if (name.empty()) return base;
  if (base.empty()) return std::string(name);
  base += '.';
  base += name;
  return base;
}

SourceLocation SourceText::location(ValueId id) const {
  const TextPosition p = values->position(id);
  if (p.line == 0) return {*file, 0, 0};
  return {*file, static_cast<int>(p.line), static_cast<int>(p.column)};
}

void ValueReader::error(ValueId where, std::string message) const {
  sink_.error(source_.location(where), std::move(message));
}

std::string ValueReader::describe(ValueId id) const {
  if (id == kNoValue) return "nothing";
  switch (tree().kind(id)) {
    case ValueKind::Null:
      return "nothing";
    case ValueKind::Scalar:
      return quoteForMessage(tree().scalar(id));
    case ValueKind::List: {
      const std::size_t n = tree().size(id);
      return n == 1 ? "a list of 1 item" : fmt::format("a list of {} items", n);
    }
    case ValueKind::Map:
      return "a mapping";
  }
  return "nothing";
}

ValueId ValueReader::itemPlace(ValueId list, ValueId listWhere, std::size_t i) const {
  const ValueId child = tree().item(list, i);
  return tree().isNull(child) ? listWhere : child;
}

std::optional<double> ValueReader::number(ValueId v, ValueId where, const ValuePath& path) const {
  if (!tree().isScalar(v)) {
    error(where, fmt::format("{}: expected a number, got {}", path.str(), describe(v)));
    return std::nullopt;
  }
  const std::string_view text = tree().scalar(v);
  const std::optional<double> value = parseDouble(text);
  if (!value) {
    error(where, fmt::format("{}: expected a number, got {}", path.str(), quoteForMessage(text)));
    return std::nullopt;
  }
  if (!std::isfinite(*value)) {
    error(where,
          fmt::format("{} must be a finite number, got {}", path.str(), shortenForMessage(text)));
    return std::nullopt;
  }
  return *value;
}

std::optional<std::int64_t> ValueReader::integer(ValueId v, ValueId where,
                                                 const ValuePath& path) const {
  const std::optional<double> n = number(v, where, path);
  if (!n) return std::nullopt;
  const std::string_view text = tree().scalar(v);
  if (*n != std::trunc(*n)) {
    error(where,
          fmt::format("{}: expected a whole number, got {}", path.str(), shortenForMessage(text)));
    return std::nullopt;
  }
  // ±2^62 holds every meaningful count; beyond it the value is only an absurd request.
  constexpr double kLimit = 4611686018427387904.0;
  if (std::abs(*n) > kLimit) {
    error(where, fmt::format("{}: {} is too large", path.str(), shortenForMessage(text)));
    return std::nullopt;
  }
  return static_cast<std::int64_t>(*n);
}

std::optional<std::uint64_t> ValueReader::unsignedInteger(ValueId v, ValueId where,
                                                          const ValuePath& path) const {
  if (tree().isScalar(v)) {
    // Exact for every 64-bit value, which a double is not.
    std::string_view s = tree().scalar(v);
    if (s.size() > 1 && s[0] == '+') s.remove_prefix(1);
    std::uint64_t value = 0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec == std::errc() && ptr == s.data() + s.size()) return value;
  }
  const std::optional<double> n = number(v, where, path);
  if (!n) return std::nullopt;
  const std::string_view text = tree().scalar(v);
  if (*n != std::trunc(*n)) {
    error(where,
          fmt::format("{}: expected a whole number, got {}", path.str(), shortenForMessage(text)));
    return std::nullopt;
  }
  if (*n < 0 || *n >= 18446744073709551616.0) {
    error(where, fmt::format("{} must be between 0 and {}, got {}", path.str(),
                             std::numeric_limits<std::uint64_t>::max(), shortenForMessage(text)));
    return std::nullopt;
  }
  return static_cast<std::uint64_t>(*n);
}

std::optional<std::array<double, 3>> ValueReader::triple(ValueId v, ValueId where,
                                                         const ValuePath& path,
                                                         std::string_view what) const {
  if (!tree().isList(v) || tree().size(v) != 3) {
    error(where, fmt::format("{}: expected a list of 3 numbers {}, got {}", path.str(), what,
                             describe(v)));
    return std::nullopt;
  }
  std::array<double, 3> out{};
  bool ok = true;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::optional<double> n = number(tree().item(v, i), itemPlace(v, where, i), path.item(i));
    if (n) {
      out[i] = *n;
    } else {
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return out;
}

std::optional<Vec3> ValueReader::vec3(ValueId v, ValueId where, const ValuePath& path) const {
  const auto t = triple(v, where, path, "[x, y, z]");
  if (!t) return std::nullopt;
  return Vec3{(*t)[0], (*t)[1], (*t)[2]};
}

std::optional<Point3> ValueReader::point3(ValueId v, ValueId where, const ValuePath& path) const {
  const auto t = triple(v, where, path, "[x, y, z]");
  if (!t) return std::nullopt;
  for (const double c : *t) {
    if (std::abs(c) > kMaxCoordinate) {
      error(where, fmt::format("{} must lie within ±{:g} of the origin, got [{}, {}, {}] (glint's "
                               "double-precision tests multiply up to three coordinates, which "
                               "would overflow): scale the scene down",
                               path.str(), kMaxCoordinate, (*t)[0], (*t)[1], (*t)[2]));
      return std::nullopt;
    }
  }
  return Point3{(*t)[0], (*t)[1], (*t)[2]};
}

std::optional<ColorValue> ValueReader::color(ValueId v, ValueId where,
                                             const ValuePath& path) const {
  ColorValue out;
  const std::string_view s = tree().scalar(v);
  if (tree().isScalar(v) && !s.empty() && s[0] == '#') {
    bool ok = s.size() == 7;
    for (std::size_t i = 1; ok && i < 7; ++i) ok = hexDigit(s[i]) >= 0;
    if (!ok) {
      error(where, fmt::format("{}: expected a color \"#rrggbb\" with 6 hexadecimal digits, got {}",
                               path.str(), quoteForMessage(s)));
      return std::nullopt;
    }
    out.isHex = true;
    for (std::size_t c = 0; c < 3; ++c) {
      out.code[c] = static_cast<std::uint8_t>(hexDigit(s[1 + 2 * c]) * 16 + hexDigit(s[2 + 2 * c]));
    }
    return out;
  }
  if (!tree().isList(v)) {
    error(where, fmt::format("{}: expected a color [r, g, b] or \"#rrggbb\", got {}", path.str(),
                             describe(v)));
    return std::nullopt;
  }
  const auto t = triple(v, where, path, "[r, g, b]");
  if (!t) return std::nullopt;
  out.rgb = Color((*t)[0], (*t)[1], (*t)[2]);
  return out;
}

std::optional<ColorValue> ValueReader::coefficient(ValueId v, ValueId where,
                                                   const ValuePath& path) const {
  const std::string_view s = tree().scalar(v);
  if (tree().isScalar(v) && !s.empty() && s[0] == '#') return color(v, where, path);
  if (tree().isScalar(v)) {
    const std::optional<double> n = number(v, where, path);
    if (!n) return std::nullopt;
    ColorValue out;
    out.rgb = Color(*n);
    return out;
  }
  if (!tree().isList(v)) {
    error(where, fmt::format("{}: expected a number, a color [r, g, b] or \"#rrggbb\", got {}",
                             path.str(), describe(v)));
    return std::nullopt;
  }
  return color(v, where, path);
}

std::optional<std::string_view> ValueReader::text(ValueId v, ValueId where,
                                                  const ValuePath& path) const {
  if (!tree().isScalar(v)) {
    error(where, fmt::format("{}: expected text, got {}", path.str(), describe(v)));
    return std::nullopt;
  }
  return tree().scalar(v);
}

std::optional<bool> ValueReader::boolean(ValueId v, ValueId where, const ValuePath& path) const {
  if (tree().isScalar(v)) {
    const std::string_view s = tree().scalar(v);
    if (s == "true" || s == "True" || s == "TRUE") return true;
    if (s == "false" || s == "False" || s == "FALSE") return false;
  }
  error(where, fmt::format("{}: expected true or false, got {}", path.str(), describe(v)));
  return std::nullopt;
}

std::optional<std::vector<Point3>> ValueReader::pointList(ValueId v, ValueId where,
                                                          const ValuePath& path,
                                                          std::size_t minCount,
                                                          std::size_t maxCount) const {
  const std::size_t n = tree().size(v);
  if (!tree().isList(v) || n < minCount || n > maxCount) {
    const std::string count =
        minCount == maxCount ? std::to_string(minCount) : fmt::format("at least {}", minCount);
    error(where, fmt::format("{}: expected a list of {} points [[x, y, z], ...], got {}",
                             path.str(), count, describe(v)));
    return std::nullopt;
  }
  return items(v, where, path, &ValueReader::point3);
}

std::optional<std::vector<Vec3>> ValueReader::vectorList(ValueId v, ValueId where,
                                                         const ValuePath& path,
                                                         std::size_t count) const {
  if (!tree().isList(v) || tree().size(v) != count) {
    error(where, fmt::format("{}: expected a list of {} vectors [[x, y, z], ...], got {}",
                             path.str(), count, describe(v)));
    return std::nullopt;
  }
  return items(v, where, path, &ValueReader::vec3);
}

template <class T>
std::optional<std::vector<T>> ValueReader::items(
    ValueId list, ValueId where, const ValuePath& path,
    std::optional<T> (ValueReader::*read)(ValueId, ValueId, const ValuePath&) const) const {
  std::vector<T> out;
  out.reserve(tree().size(list));
  bool ok = true;
  for (std::size_t i = 0; i < tree().size(list); ++i) {
    if (auto item = (this->*read)(tree().item(list, i), itemPlace(list, where, i), path.item(i))) {
      out.push_back(*item);
    } else {
      ok = false;  // every wrong item is reported
    }
  }
  if (!ok) return std::nullopt;
  return out;
}

// ---------------------------------------------------------------------------------- dictionary

ParameterDictionary::ParameterDictionary(const ValueReader& reader, ValueId map,
                                         DictionaryNames names)
    : reader_(reader),
      map_(map),
      names_(std::move(names)),
      sinkErrorsBefore_(reader.sink().errorCount()) {
  const ValueTree& tree = reader_.tree();
  if (!tree.isMap(map)) return;
  const std::size_t n = tree.size(map);
  items_.reserve(n);
  std::unordered_map<std::string_view, std::size_t, SeededHash> seen;  // only for large mappings
  if (n > kPairwiseDuplicateLimit) seen.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const ValueId key = tree.key(map, i);
    if (!tree.isScalar(key)) {
      error(key,
            fmt::format("expected a key name {}, got {}", names_.context, reader_.describe(key)));
      continue;
    }
    const std::string_view name = tree.scalar(key);
    const Item* first = nullptr;
    if (n > kPairwiseDuplicateLimit) {
      const auto [it, inserted] = seen.emplace(name, items_.size());
      if (!inserted) first = &items_[it->second];
    } else {
      for (const Item& other : items_) {
        if (other.name == name) first = &other;
      }
    }
    if (first != nullptr) {
      const TextPosition p = tree.position(first->key);
      error(key, fmt::format("duplicate key '{}' {} (first at line {}, column {})",
                             shortenForMessage(name), names_.context, p.line, p.column));
      continue;
    }
    items_.push_back({name, key, tree.value(map, i), false});
  }
}

void ParameterDictionary::declare(std::initializer_list<std::string_view> keys) {
  declared_.insert(declared_.end(), keys.begin(), keys.end());
}

void ParameterDictionary::declare(const std::vector<std::string_view>& keys) {
  for (const std::string_view key : keys) {
    if (std::find(declared_.begin(), declared_.end(), key) == declared_.end()) {
      declared_.push_back(key);
    }
  }
}

void ParameterDictionary::declareHidden(std::string_view key) { hidden_.push_back(key); }

bool ParameterDictionary::isDeclared(std::string_view key) const {
  return std::find(declared_.begin(), declared_.end(), key) != declared_.end() ||
         std::find(hidden_.begin(), hidden_.end(), key) != hidden_.end();
}

std::vector<std::string_view> ParameterDictionary::keys() const {
  std::vector<std::string_view> names;
  names.reserve(items_.size());
  for (const Item& i : items_) names.push_back(i.name);
  return names;
}

ParameterDictionary::Item* ParameterDictionary::item(std::string_view key) {
  for (Item& i : items_) {
    if (i.name == key) return &i;
  }
  return nullptr;
}

const ParameterDictionary::Item* ParameterDictionary::item(std::string_view key) const {
  for (const Item& i : items_) {
    if (i.name == key) return &i;
  }
  return nullptr;
}

ValueId ParameterDictionary::placeOf(const Item& i) const {
  return reader_.tree().isNull(i.value) ? i.key : i.value;
}

std::optional<ParameterDictionary::Entry> ParameterDictionary::find(std::string_view key) {
  Item* i = item(key);
  if (i == nullptr) return std::nullopt;
  i->used = true;
  return Entry{i->key, i->value, placeOf(*i)};
}

bool ParameterDictionary::has(std::string_view key) const { return item(key) != nullptr; }

ValueId ParameterDictionary::keyPlace(std::string_view key) const {
  const Item* i = item(key);
  return i != nullptr ? i->key : kNoValue;
}

ValueId ParameterDictionary::laterKey(std::string_view a, std::string_view b) const {
  const Item* ia = item(a);
  const Item* ib = item(b);
  if (ia == nullptr || ib == nullptr) return kNoValue;
  const TextPosition pa = reader_.tree().position(ia->key);
  const TextPosition pb = reader_.tree().position(ib->key);
  const bool aLater = pa.line > pb.line || (pa.line == pb.line && pa.column > pb.column);
  return aLater ? ia->key : ib->key;
}

void ParameterDictionary::markUsed(const std::vector<std::string_view>& keys) {
  for (Item& i : items_) {
    if (std::find(keys.begin(), keys.end(), i.name) != keys.end()) i.used = true;
  }
}

void ParameterDictionary::requireKey(std::string_view key) {
  if (std::find(missing_.begin(), missing_.end(), key) == missing_.end()) missing_.push_back(key);
}

const ParameterDictionary::Item* ParameterDictionary::fetch(std::string_view key, Presence p) {
  Item* i = item(key);
  if (i == nullptr) {
    if (p == Presence::Required) requireKey(key);
    return nullptr;
  }
  i->used = true;
  return i;
}

template <class T, class... Extra>
std::optional<Located<T>> ParameterDictionary::get(std::string_view key, Presence p,
                                                   Reader<T, Extra...> read, Extra... extra) {
  const Item* i = fetch(key, p);
  if (i == nullptr) return std::nullopt;
  const ValueId where = placeOf(*i);
  std::optional<T> value = (reader_.*read)(i->value, where, pathOf(key), extra...);
  if (!value) return std::nullopt;
  return Located<T>{std::move(*value), where};
}

std::optional<Located<double>> ParameterDictionary::number(std::string_view key, Presence p) {
  return get(key, p, &ValueReader::number);
}
std::optional<Located<std::int64_t>> ParameterDictionary::integer(std::string_view key,
                                                                  Presence p) {
  return get(key, p, &ValueReader::integer);
}
std::optional<Located<std::uint64_t>> ParameterDictionary::unsignedInteger(std::string_view key,
                                                                           Presence p) {
  return get(key, p, &ValueReader::unsignedInteger);
}
std::optional<Located<Vec3>> ParameterDictionary::vec3(std::string_view key, Presence p) {
  return get(key, p, &ValueReader::vec3);
}
std::optional<Located<Point3>> ParameterDictionary::point3(std::string_view key, Presence p) {
  return get(key, p, &ValueReader::point3);
}
std::optional<Located<std::array<double, 3>>> ParameterDictionary::triple(std::string_view key,
                                                                          std::string_view what,
                                                                          Presence p) {
  return get(key, p, &ValueReader::triple, what);
}
std::optional<Located<ColorValue>> ParameterDictionary::color(std::string_view key, Presence p) {
  return get(key, p, &ValueReader::color);
}
std::optional<Located<ColorValue>> ParameterDictionary::coefficient(std::string_view key,
                                                                    Presence p) {
  return get(key, p, &ValueReader::coefficient);
}
std::optional<Located<std::string_view>> ParameterDictionary::text(std::string_view key,
                                                                   Presence p) {
  return get(key, p, &ValueReader::text);
}
std::optional<Located<bool>> ParameterDictionary::boolean(std::string_view key, Presence p) {
  return get(key, p, &ValueReader::boolean);
}
std::optional<Located<std::vector<Point3>>> ParameterDictionary::pointList(std::string_view key,
                                                                           std::size_t minCount,
                                                                           std::size_t maxCount,
                                                                           Presence p) {
  return get(key, p, &ValueReader::pointList, minCount, maxCount);
}
std::optional<Located<std::vector<Vec3>>> ParameterDictionary::vectorList(std::string_view key,
                                                                          std::size_t count,
                                                                          Presence p) {
  return get(key, p, &ValueReader::vectorList, count);
}

std::optional<ParameterDictionary> ParameterDictionary::mapping(std::string_view key,
                                                                std::string_view what,
                                                                DictionaryNames names) {
  const Item* i = fetch(key, Presence::Optional);
  if (i == nullptr) return std::nullopt;
  if (!reader_.tree().isMap(i->value)) {
    error(placeOf(*i), fmt::format("{}: expected {}, got {}", pathOf(key).str(), what,
                                   reader_.describe(i->value)));
    return std::nullopt;
  }
  return ParameterDictionary(reader_, i->value, std::move(names));
}

void ParameterDictionary::error(ValueId where, std::string message) {
  reader_.error(where, std::move(message));
}

void ParameterDictionary::finish() {
  if (finished_) return;
  finished_ = true;
  std::vector<std::string_view> unknown;
  if (!declared_.empty() || !hidden_.empty()) {
    for (Item& i : items_) {
      if (i.used) continue;
      unknown.push_back(i.name);
    }
  }
  if (!unknown.empty()) {
    std::vector<std::string_view> candidates = declared_;
    candidates.insert(candidates.end(), hidden_.begin(), hidden_.end());
    const std::string offered = fmt::format("{}", fmt::join(declared_, ", "));
    for (Item& i : items_) {
      if (i.used) continue;
      error(i.key, fmt::format("unknown key {} {}; expected one of: {}{}", quoteForMessage(i.name),
                               names_.context, offered, didYouMean(i.name, candidates)));
    }
  }
  for (const std::string_view key : missing_) {
    // A misspelling of the key was already reported as unknown, with the suggestion: one error.
    bool misspelt = false;
    for (const std::string_view u : unknown) {
      misspelt = misspelt || closestName(u, std::vector<std::string_view>{key}) == key;
    }
    if (!misspelt) {
      error(map_, fmt::format("{} is missing required key '{}'", names_.owner, key));
    }
  }
}

}  // namespace glint
