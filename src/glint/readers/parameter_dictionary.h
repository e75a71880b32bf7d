// ParameterDictionary: the named parameters of one scene entity (or of one nested mapping) with a
// "used" mark per parameter, and typed getters that report every problem at the value's
// file:line:col (pbrt-v4's ParameterDictionary). A parameter nothing read is the unknown-key error,
// with did-you-mean over the keys the reader declared.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/vec.h"
#include "glint/readers/diagnostics.h"
#include "glint/readers/value_tree.h"

namespace glint {

// A value read from a file and the value whose place names it in messages: the value itself, or
// its key when it is empty (`center:` with nothing after it), or its list when an item is empty.
template <class T>
struct Located {
  T value{};
  ValueId where = kNoValue;
};

// A colour as written: [r, g, b] (linear) or "#rrggbb" (an 8-bit display code, decoded by the
// scene builder once the image encoding is known).
struct ColorValue {
  bool isHex = false;
  Color rgb;                           // when !isHex: linear components as written
  std::array<std::uint8_t, 3> code{};  // when isHex
};

// A path naming a value in messages ("sphere.center[1]", "camera.view_plane.width"), built only
// when a message needs it: a chain of stack objects, each a key or a list index below its parent.
struct ValuePath {
  static constexpr std::size_t kNoIndex = static_cast<std::size_t>(-1);
  const ValuePath* parent = nullptr;  // or, at the root, `prefix`: "sphere", "materials.glass"
  std::string_view prefix;
  std::string_view name;         // a key below the parent or prefix
  std::size_t index = kNoIndex;  // or a list item of the parent
  std::string str() const;
  ValuePath item(std::size_t i) const { return {this, {}, {}, i}; }
  ValuePath child(std::string_view key) const { return {this, {}, key, kNoIndex}; }
};

// One text and its values: the file name used in messages and the values read from it.
struct SourceText {
  const ValueTree* values = nullptr;
  const std::string* file = nullptr;
  SourceLocation location(ValueId id) const;
};

// Reads single values as numbers, vectors, colours, ... reporting type errors (expected X, got Y)
// at their place. Shared by the dictionaries and the readers of lists of values.
class ValueReader {
 public:
  ValueReader(SourceText source, Diagnostics& sink) : source_(source), sink_(sink) {}

  const ValueTree& tree() const { return *source_.values; }
  const SourceText& source() const { return source_; }
  Diagnostics& sink() const { return sink_; }
  void error(ValueId where, std::string message) const;

  // What a value is, for "expected X, got Y": 'abc', a list of 2 items, a mapping, nothing.
  std::string describe(ValueId id) const;

  std::optional<double> number(ValueId v, ValueId where, const ValuePath& path) const;
  // A whole number within ±2^62.
  std::optional<std::int64_t> integer(ValueId v, ValueId where, const ValuePath& path) const;
  // 0 .. 2^64 − 1, exact.
  std::optional<std::uint64_t> unsignedInteger(ValueId v, ValueId where,
                                               const ValuePath& path) const;
  // A list of 3 numbers; `what` names the form in messages: "[x, y, z]", "[r, g, b]".
  std::optional<std::array<double, 3>> triple(ValueId v, ValueId where, const ValuePath& path,
                                              std::string_view what) const;
  std::optional<Vec3> vec3(ValueId v, ValueId where, const ValuePath& path) const;
  std::optional<Point3> point3(ValueId v, ValueId where, const ValuePath& path) const;
  std::optional<ColorValue> color(ValueId v, ValueId where, const ValuePath& path) const;
  // A colour-valued material coefficient: a number (grey), [r, g, b] or "#rrggbb".
  std::optional<ColorValue> coefficient(ValueId v, ValueId where, const ValuePath& path) const;
  std::optional<std::string_view> text(ValueId v, ValueId where, const ValuePath& path) const;
  // YAML 1.2 core-schema booleans only (true/True/TRUE, false/False/FALSE).
  std::optional<bool> boolean(ValueId v, ValueId where, const ValuePath& path) const;
  std::optional<std::vector<Point3>> pointList(ValueId v, ValueId where, const ValuePath& path,
                                               std::size_t minCount, std::size_t maxCount) const;
  std::optional<std::vector<Vec3>> vectorList(ValueId v, ValueId where, const ValuePath& path,
                                              std::size_t count) const;
  // The place of item i of a list: the item, or the list when the item is empty.
  ValueId itemPlace(ValueId list, ValueId listWhere, std::size_t i) const;

 private:
  // Every item of a list read by `read`; nullopt when one is wrong (each wrong one reported).
  template <class T>
  std::optional<std::vector<T>> items(ValueId list, ValueId where, const ValuePath& path,
                                      std::optional<T> (ValueReader::*read)(ValueId, ValueId,
                                                                            const ValuePath&)
                                          const) const;

  SourceText source_;
  Diagnostics& sink_;
};

// How a dictionary names itself in messages.
struct DictionaryNames {
  std::string context;  // completes "unknown key 'x' ...": "in sphere", "at the top level"
  std::string path;     // prefixes its values: "sphere" → "sphere.radius"; "" at the top level
  std::string owner;    // "{owner} is missing required key 'x'": "sphere", "spot light"
};

enum class Presence { Optional, Required };

class ParameterDictionary {
 public:
  // The entries of `map` (a mapping value; anything else gives an empty dictionary placed at it).
  // Reports keys that are not plain names and duplicate keys (at the second occurrence, which is
  // then ignored), in linear time.
  ParameterDictionary(const ValueReader& reader, ValueId map, DictionaryNames names);

  // Keys this dictionary accepts, in the order messages list them. A hidden key (`type`) is
  // accepted and offered as a suggestion but not listed.
  void declare(std::initializer_list<std::string_view> keys);
  void declare(const std::vector<std::string_view>& keys);
  void declareHidden(std::string_view key);
  const std::vector<std::string_view>& declared() const { return declared_; }
  bool isDeclared(std::string_view key) const;
  // The keys of the mapping in file order (duplicates and keys that are not names left out).
  std::vector<std::string_view> keys() const;

  // Raw access: the value of `key` (marked used) and its key, or nullopt when absent.
  struct Entry {
    ValueId key = kNoValue;
    ValueId value = kNoValue;
    ValueId where = kNoValue;  // the value, or the key when the value is empty
  };
  std::optional<Entry> find(std::string_view key);
  bool has(std::string_view key) const;
  // Where `key` was written, or kNoValue.
  ValueId keyPlace(std::string_view key) const;
  // The key of two given later in the file (for "has both 'a' and 'b'"), or kNoValue unless both.
  ValueId laterKey(std::string_view a, std::string_view b) const;
  // Marks every entry whose key is in `keys` as used without reading it.
  void markUsed(const std::vector<std::string_view>& keys);

  // Typed getters: nullopt when absent (with Presence::Required, a missing-key error reported by
  // finish()) or when the value has the wrong type (an error at the value, reported now).
  std::optional<Located<double>> number(std::string_view key, Presence p = Presence::Optional);
  std::optional<Located<std::int64_t>> integer(std::string_view key,
                                               Presence p = Presence::Optional);
  std::optional<Located<std::uint64_t>> unsignedInteger(std::string_view key,
                                                        Presence p = Presence::Optional);
  std::optional<Located<Vec3>> vec3(std::string_view key, Presence p = Presence::Optional);
  std::optional<Located<Point3>> point3(std::string_view key, Presence p = Presence::Optional);
  std::optional<Located<std::array<double, 3>>> triple(std::string_view key, std::string_view what,
                                                       Presence p = Presence::Optional);
  std::optional<Located<ColorValue>> color(std::string_view key, Presence p = Presence::Optional);
  std::optional<Located<ColorValue>> coefficient(std::string_view key,
                                                 Presence p = Presence::Optional);
  std::optional<Located<std::string_view>> text(std::string_view key,
                                                Presence p = Presence::Optional);
  std::optional<Located<bool>> boolean(std::string_view key, Presence p = Presence::Optional);
  std::optional<Located<std::vector<Point3>>> pointList(std::string_view key, std::size_t minCount,
                                                        std::size_t maxCount,
                                                        Presence p = Presence::Optional);
  std::optional<Located<std::vector<Vec3>>> vectorList(std::string_view key, std::size_t count,
                                                       Presence p = Presence::Optional);
  // A nested mapping read as a dictionary of its own (finish() it too); an error "expected {what}"
  // when the value is not a mapping.
  std::optional<ParameterDictionary> mapping(std::string_view key, std::string_view what,
                                             DictionaryNames names);
  // Records `key` as required and missing (reported by finish(), unless misspelt).
  void requireKey(std::string_view key);

  // Reports the keys nothing read (unknown keys) and the missing required keys that no unknown key
  // is a misspelling of. Call once, after everything that reads this dictionary.
  void finish();

  // Errors reported since this dictionary was made: its values, its keys, missing keys, and
  // those of the nested dictionaries and values read while it was being read.
  std::size_t errors() const { return reader_.sink().errorCount() - sinkErrorsBefore_; }
  void error(ValueId where, std::string message);
  SourceLocation location(ValueId id) const { return reader_.source().location(id); }
  SourceLocation location() const { return location(map_); }
  ValueId place() const { return map_; }
  const DictionaryNames& names() const { return names_; }
  void setOwner(std::string owner) { names_.owner = std::move(owner); }
  const ValueReader& reader() const { return reader_; }
  // The path of a key's value, for messages: "sphere" + "radius" → "sphere.radius".
  ValuePath pathOf(std::string_view key) const {
    return {nullptr, names_.path, key, ValuePath::kNoIndex};
  }

 private:
  struct Item {
    std::string_view name;
    ValueId key = kNoValue;
    ValueId value = kNoValue;
    bool used = false;
  };
  Item* item(std::string_view key);
  const Item* item(std::string_view key) const;
  // The value of `key` for a typed getter: marks it used, records a required key as missing.
  const Item* fetch(std::string_view key, Presence p);
  ValueId placeOf(const Item& item) const;
  // A typed getter: fetch(key), then the ValueReader conversion `read` of its value and place.
  template <class T, class... Extra>
  using Reader = std::optional<T> (ValueReader::*)(ValueId, ValueId, const ValuePath&,
                                                   Extra...) const;
  template <class T, class... Extra>
  std::optional<Located<T>> get(std::string_view key, Presence p, Reader<T, Extra...> read,
                                Extra... extra);

  ValueReader reader_;
  ValueId map_ = kNoValue;
  DictionaryNames names_;
  std::vector<Item> items_;
  std::vector<std::string_view> declared_;
  std::vector<std::string_view> hidden_;
  std::vector<std::string_view> missing_;
  std::size_t sinkErrorsBefore_ = 0;
  bool finished_ = false;
};

}  // namespace glint
