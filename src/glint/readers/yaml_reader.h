// YAML (and JSON) text → ValueTree, read from libyaml's event stream in one pass, streaming from a
// file when there is one. Refuses hostile documents while reading them: alias bombs, an alias
// inside its own anchor, more values than a scene can mean, nesting beyond kMaxDepth.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "glint/readers/value_tree.h"

namespace glint::yaml {

// Values (scalars, nulls, lists, mappings; keys count) one document may hold: 16 bytes each in the
// tree plus their text, so at most ~100 MB for numbers. A scene file describes a scene; large
// geometry belongs in mesh files.
inline constexpr std::size_t kMaxValues = std::size_t{1} << 22;
// Values that aliases (*name) may add when expanded — every alias stands for its anchor's whole
// subtree, which a reader of the tree walks once per alias — on top of the document's own values:
// at most max(kMaxAliasValues, the document's value count). Without a bound, nested aliases
// ("billion laughs") grow exponentially and even one level (a 50,000-point list aliased 20,000
// times, 630 KB of text) asks for 10^9 points. Aliases share their anchor's values: the bound is
// on work, not on memory.
inline constexpr std::uint64_t kMaxAliasValues = std::uint64_t{1} << 22;
// Lists and mappings nested deeper than this are refused (a scene needs about 6 levels).
inline constexpr std::size_t kMaxDepth = 1000;

struct Limits {
  std::size_t maxValues = kMaxValues;
  std::uint64_t maxAliasValues = kMaxAliasValues;
  std::size_t maxDepth = kMaxDepth;
};

// A text the reader cannot take, in plain words (no library jargon), at its place.
class SyntaxError : public std::runtime_error {
 public:
  enum class Kind {
    Syntax,    // malformed YAML: "syntax error: a '[' is not closed with ']'"
    Refused,   // well-formed but refused: alias bomb, alias inside its anchor, too many values
    TooDeep,   // nesting beyond Limits::maxDepth
    Encoding,  // bytes that are not text: invalid UTF-8, control characters
  };
  SyntaxError(TextPosition where, const std::string& message, Kind kind)
      : std::runtime_error(message), where_(where), kind_(kind) {}
  const TextPosition& where() const { return where_; }
  Kind kind() const { return kind_; }

 private:
  TextPosition where_;
  Kind kind_;
};

struct Document {
  ValueTree values;
  ValueId root = kNoValue;  // the first document's root; kNoValue for an empty text
  // Where a second document starts (a scene file holds exactly one); nothing after it is read.
  std::optional<TextPosition> secondDocument;
  std::uint64_t bytesRead = 0;
};

// Reads the first document of `text`. Throws SyntaxError, or glint::Cancelled when `cancel` is set
// (polled every few thousand events).
Document read(std::string_view text, const Limits& limits = {},
              const std::atomic<bool>* cancel = nullptr);

// The same from an open file, read in blocks: the text is never held whole. Reading stops with an
// error (a SyntaxError of kind Refused) beyond `maxBytes`. An I/O error is thrown as
// std::system_error.
Document readFile(int fd, std::uint64_t maxBytes, const Limits& limits = {},
                  const std::atomic<bool>* cancel = nullptr);

}  // namespace glint::yaml
