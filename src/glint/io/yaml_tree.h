// YAML text as a plain tree with the place of every node, read in one pass of yaml-cpp's event
// parser (no YAML::Node): faster than YAML::Load, keeps duplicate keys for the caller to report,
// and bounds the document loop that yaml-cpp 0.7's LoadAll runs forever on a stray ','.
#pragma once

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace glint::yaml {

// A place in the text, 0-based; -1 when unknown.
struct Mark {
  int pos = -1;
  int line = -1;
  int column = -1;
};

// A syntax error of the text, with yaml-cpp's own message (callers put it in plain words).
class SyntaxError : public std::runtime_error {
 public:
  SyntaxError(const Mark& where, const std::string& message, bool nestedTooDeeply)
      : std::runtime_error(message), mark(where), tooDeep(nestedTooDeeply) {}
  Mark mark;
  bool tooDeep;  // lists or mappings nested beyond yaml-cpp's depth guard
};

struct Tree;

// A node of a Tree: a cheap handle, valid while its Stream lives. A default Node is "undefined"
// (what find() returns for a missing key).
class Node {
 public:
  enum class Kind { Undefined, Null, Scalar, Sequence, Map };

  Node() = default;
  Kind kind() const;
  bool isDefined() const { return kind() != Kind::Undefined; }
  bool isNull() const { return kind() == Kind::Null; }
  bool isScalar() const { return kind() == Kind::Scalar; }
  bool isSequence() const { return kind() == Kind::Sequence; }
  bool isMap() const { return kind() == Kind::Map; }
  Mark mark() const;
  const std::string& scalar() const;  // empty unless a scalar

  // Items of a sequence, or key/value pairs of a mapping (in file order, duplicates kept).
  std::size_t size() const;
  Node operator[](std::size_t i) const;  // sequence item
  Node key(std::size_t i) const;         // mapping key
  Node value(std::size_t i) const;       // mapping value
  // The value of the first pair whose key is the scalar `name`, or an undefined Node.
  Node find(std::string_view name) const;

 private:
  friend class TreeBuilder;
  Node(const Tree* tree, std::size_t index) : tree_(tree), index_(index) {}
  const Tree* tree_ = nullptr;
  std::size_t index_ = 0;
};

struct Stream {
  std::shared_ptr<const Tree> tree;
  Node root;                         // the first document; undefined when there is none
  std::vector<Mark> documentStarts;  // where the first documents start (at most 3 are read)
  bool stuck = false;  // the parser repeated an empty document at one place: a stray token there
};

// Parses `text`. Throws SyntaxError.
Stream parse(const std::string& text);

}  // namespace glint::yaml
