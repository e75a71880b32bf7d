#include "glint/readers/value_tree.h"

#include <algorithm>
#include <cassert>

namespace glint {

std::string_view ValueTree::scalar(ValueId id) const {
  if (!isScalar(id)) return {};
  const Value& v = values_[id];
  return std::string_view(text_).substr(v.a, v.b);
}

std::size_t ValueTree::size(ValueId id) const {
  if (id == kNoValue) return 0;
  switch (kind(id)) {
    case ValueKind::List:
      return values_[id].b;
    case ValueKind::Map:
      return values_[id].b / 2;
    default:
      return 0;
  }
}

TextPosition ValueTree::position(ValueId id) const {
  if (id == kNoValue || id >= values_.size()) return {};
  const std::uint32_t offset = values_[id].where & kMaxOffset;
  // The last line starting at or before the offset: every value's line was noted when it was added.
  auto it = std::upper_bound(lines_.begin(), lines_.end(), offset,
                             [](std::uint32_t o, const auto& line) { return o < line.first; });
  if (it == lines_.begin()) return {offset, 1, offset + 1};
  --it;
  return {offset, it->second, offset - it->first + 1};
}

std::size_t ValueTree::memoryBytes() const {
  return values_.capacity() * sizeof(Value) + links_.capacity() * sizeof(ValueId) +
         text_.capacity() + lines_.capacity() * sizeof(lines_[0]) +
         textCache_.capacity() * sizeof(CachedText);
}

void ValueTree::reserveForText(std::uint64_t bytes) {
  const auto capped = static_cast<std::size_t>(std::min<std::uint64_t>(bytes, kMaxOffset));
  values_.reserve(capped / 2 + 16);
  links_.reserve(capped / 2 + 16);
  text_.reserve(capped + 16);
}

void ValueTree::noteLine(const TextPosition& where) {
  if (where.line == 0) return;
  const std::uint32_t offset = std::min(where.offset, kMaxOffset);
  const std::uint32_t column = std::max<std::uint32_t>(where.column, 1);
  const std::uint32_t start = offset >= column - 1 ? offset - (column - 1) : 0;
  if (!lines_.empty() && lines_.back().second == where.line) return;
  if (lines_.empty() || lines_.back().first < start) {
    lines_.emplace_back(start, where.line);
    return;
  }
  // Out of order (a reader that adds values before earlier ones, such as the NFF reader's meshes,
  // added at the end at their polygons' lines): keep the table sorted. Such values come in runs
  // on one line, line after line, so the few lines from the one found last are looked at first.
  for (std::size_t k = lastFound_; k < std::min(lastFound_ + 8, lines_.size()); ++k) {
    if (lines_[k].first == start) {
      lastFound_ = k;
      return;
    }
  }
  const auto it =
      std::lower_bound(lines_.begin(), lines_.end(), start,
                       [](const auto& line, std::uint32_t s) { return line.first < s; });
  const auto index = static_cast<std::size_t>(it - lines_.begin());
  if (it == lines_.end() || it->first != start) lines_.insert(it, {start, where.line});
  lastFound_ = index;
}

std::uint32_t ValueTree::storeText(std::string_view text) {
  const bool identifier =
      !text.empty() && text.size() <= kInternedLength &&
      ((text[0] >= 'a' && text[0] <= 'z') || (text[0] >= 'A' && text[0] <= 'Z') || text[0] == '_');
  CachedText* slot = nullptr;
  if (identifier) {
    // FNV-1a of the text picks the slot; a collision only stores the text again.
    std::uint32_t hash = 2166136261u;
    for (const char c : text) hash = (hash ^ static_cast<unsigned char>(c)) * 16777619u;
    slot = &textCache_[hash % kTextCacheSlots];
    if (slot->length == text.size() &&
        std::string_view(text_).substr(slot->offset, slot->length) == text) {
      return slot->offset;
    }
  }
  const auto offset = static_cast<std::uint32_t>(text_.size());
  text_.append(text);
  if (slot != nullptr) *slot = {offset, static_cast<std::uint32_t>(text.size())};
  return offset;
}

ValueId ValueTree::add(ValueKind kind, const TextPosition& where, std::uint32_t a,
                       std::uint32_t b) {
  noteLine(where);
  const auto id = static_cast<ValueId>(values_.size());
  const std::uint32_t offset = std::min(where.offset, kMaxOffset);
  values_.push_back({offset | (static_cast<std::uint32_t>(kind) << 30), a, b});
  attach(id);
  return id;
}

ValueId ValueTree::addScalar(std::string_view text, const TextPosition& where) {
  const std::uint32_t offset = storeText(text);
  return add(ValueKind::Scalar, where, offset, static_cast<std::uint32_t>(text.size()));
}

ValueId ValueTree::addNull(const TextPosition& where) { return add(ValueKind::Null, where, 0, 0); }

ValueId ValueTree::open(ValueKind kind, const TextPosition& where) {
  assert(kind == ValueKind::List || kind == ValueKind::Map);
  const ValueId id = add(kind, where, 0, 0);
  frames_.push_back({id, pending_.size()});
  return id;
}

void ValueTree::close() {
  assert(!frames_.empty());
  const Frame frame = frames_.back();
  frames_.pop_back();
  // The children of a closed collection become one contiguous run of links.
  const std::size_t count = pending_.size() - frame.firstPending;
  values_[frame.id].a = static_cast<std::uint32_t>(links_.size());
  values_[frame.id].b = static_cast<std::uint32_t>(count);
  links_.insert(links_.end(), pending_.begin() + static_cast<std::ptrdiff_t>(frame.firstPending),
                pending_.end());
  pending_.resize(frame.firstPending);
}

std::vector<ValueId> ValueTree::openChildren() const {
  assert(!frames_.empty());
  return {pending_.begin() + static_cast<std::ptrdiff_t>(frames_.back().firstPending),
          pending_.end()};
}

void ValueTree::replaceOpenChildren(const std::vector<ValueId>& children) {
  assert(!frames_.empty());
  pending_.resize(frames_.back().firstPending);
  pending_.insert(pending_.end(), children.begin(), children.end());
}

void ValueTree::attach(ValueId id) {
  if (frames_.empty()) {
    if (root_ == kNoValue) root_ = id;
    return;
  }
  pending_.push_back(id);
}

}  // namespace glint
