// ValueTree: the values of one scene file (scalars, lists, mappings) as flat arrays with the place
// of every value — what readers produce and parameter dictionaries read. 12 bytes per value plus
// 4 per list item or mapping entry, scalar text in one arena; an alias shares its anchor's values.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

namespace glint {

using ValueId = std::uint32_t;
inline constexpr ValueId kNoValue = UINT32_MAX;

enum class ValueKind : std::uint8_t { Null, Scalar, List, Map };

// A place in a text: 1-based line and column (characters, not bytes), and the character offset
// from the start of the text. Readers give all three; the tree keeps the offset per value and
// the start offset of each line that holds one.
struct TextPosition {
  std::uint32_t offset = 0;
  std::uint32_t line = 0;    // 0: no place
  std::uint32_t column = 0;  // 1-based
};

class ValueTree {
 public:
  // Offsets beyond this (files of 1 Gi characters) are stored clamped; readers refuse such files.
  static constexpr std::uint32_t kMaxOffset = (std::uint32_t{1} << 30) - 1;

  ValueKind kind(ValueId id) const { return static_cast<ValueKind>(values_[id].where >> 30); }
  bool isNull(ValueId id) const { return id == kNoValue || kind(id) == ValueKind::Null; }
  bool isScalar(ValueId id) const { return id != kNoValue && kind(id) == ValueKind::Scalar; }
  bool isList(ValueId id) const { return id != kNoValue && kind(id) == ValueKind::List; }
  bool isMap(ValueId id) const { return id != kNoValue && kind(id) == ValueKind::Map; }

  // The text of a scalar; empty for anything else.
  std::string_view scalar(ValueId id) const;
  // Items of a list, or entries (key, value pairs) of a mapping, in file order (duplicates kept).
  std::size_t size(ValueId id) const;
  ValueId item(ValueId list, std::size_t i) const { return links_[values_[list].a + i]; }
  ValueId key(ValueId map, std::size_t i) const { return links_[values_[map].a + 2 * i]; }
  ValueId value(ValueId map, std::size_t i) const { return links_[values_[map].a + 2 * i + 1]; }

  // Where a value was written: line and column (1-based); {0, 0} for kNoValue.
  TextPosition position(ValueId id) const;

  std::size_t valueCount() const { return values_.size(); }
  // Bytes held by the tree (values, links, text, line table): for the memory tests.
  std::size_t memoryBytes() const;

  // --- building (readers) -------------------------------------------------------------------
  // Reserves room for a text of `bytes` bytes: at most one value per two bytes ("1,"), text no
  // longer than the bytes. Only address space: pages are committed as values fill them, and the
  // arrays never grow by copying.
  void reserveForText(std::uint64_t bytes);
  // Values are added in the order the text holds them. A list or mapping is opened, its items
  // (mapping: key, value, key, value...) are added, then it is closed; add() of an open
  // collection's children attaches them. `attach` of an existing value (an alias) adds it as the
  // next child without copying it.
  ValueId addScalar(std::string_view text, const TextPosition& where);
  ValueId addNull(const TextPosition& where);
  // Notes the line of `where` (position() of any value there resolves its line and column).
  // Every add() notes its own; a reader that adds values later at a position it has passed (the
  // mesh collector) notes it when it passes, so that the table of lines grows in order.
  void noteLine(const TextPosition& where);
  ValueId open(ValueKind kind, const TextPosition& where);
  void close();
  void attach(ValueId id);
  // The first value added outside any collection (the document's root), or kNoValue.
  ValueId root() const { return root_; }
  std::size_t openCollections() const { return frames_.size(); }
  // The children added so far to the innermost open collection (a mapping's: key, value, ...), and
  // their replacement before it is closed (a reader resolving YAML merge keys).
  std::vector<ValueId> openChildren() const;
  void replaceOpenChildren(const std::vector<ValueId>& children);

  // Short identifier-like scalars (keys, type names, material names: a letter or '_' first) are
  // stored once per text in a small cache; numbers and longer text each time.
  static constexpr std::size_t kInternedLength = 24;

 private:
  struct Value {
    std::uint32_t where;  // offset (30 bits) | kind << 30
    std::uint32_t a;      // scalar: text offset; list/map: first link
    std::uint32_t b;      // scalar: text length; list/map: items / entries
  };
  ValueId add(ValueKind kind, const TextPosition& where, std::uint32_t a, std::uint32_t b);
  std::uint32_t storeText(std::string_view text);

  std::vector<Value> values_;
  std::vector<ValueId> links_;
  std::string text_;
  // Identifier-like short scalars already stored: a direct-mapped cache of (offset, length) by a
  // hash of the text, so repeated keys and type names are stored once at the cost of one compare.
  struct CachedText {
    std::uint32_t offset = 0;
    std::uint32_t length = 0;  // 0: empty slot
  };
  static constexpr std::size_t kTextCacheSlots = 512;
  std::vector<CachedText> textCache_ = std::vector<CachedText>(kTextCacheSlots);
  // (offset of the first character of a line, line number) for every line holding a value,
  // ascending.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> lines_;
  std::size_t lastFound_ = 0;  // the entry of lines_ an out-of-order value was last noted at
  // Open collections: the collection and where its children start in `pending_`.
  struct Frame {
    ValueId id;
    std::size_t firstPending;
  };
  std::vector<Frame> frames_;
  std::vector<ValueId> pending_;  // children of open collections, innermost last
  ValueId root_ = kNoValue;
};

// A value of a tree as a handle with lookups, for code that reads a known structure (a glTF
// file's JSON): a missing key or an item past the end is a view of no value, whose lookups give
// no value again, so a chain of lookups needs no checks in between.
class ValueView {
 public:
  ValueView() = default;
  ValueView(const ValueTree* tree, ValueId id) : tree_(tree), id_(tree ? id : kNoValue) {}
  bool isDefined() const { return id_ != kNoValue; }
  bool isScalar() const { return isDefined() && tree_->isScalar(id_); }
  bool isList() const { return isDefined() && tree_->isList(id_); }
  bool isMap() const { return isDefined() && tree_->isMap(id_); }
  std::string_view scalar() const { return isDefined() ? tree_->scalar(id_) : std::string_view(); }
  std::size_t size() const { return isDefined() ? tree_->size(id_) : 0; }
  // Item i of a list.
  ValueView operator[](std::size_t i) const {
    return isList() && i < size() ? ValueView(tree_, tree_->item(id_, i)) : ValueView();
  }
  // The value of the first entry of a mapping whose key is `key`.
  ValueView find(std::string_view key) const {
    for (std::size_t i = 0; isMap() && i < size(); ++i) {
      if (tree_->scalar(tree_->key(id_, i)) == key) return {tree_, tree_->value(id_, i)};
    }
    return {};
  }
  ValueId id() const { return id_; }

 private:
  const ValueTree* tree_ = nullptr;
  ValueId id_ = kNoValue;
};

}  // namespace glint
