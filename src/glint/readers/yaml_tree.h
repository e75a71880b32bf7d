// YAML text as a plain tree with the place of every node, read in one pass of yaml-cpp's event
// parser (no YAML::Node): faster than YAML::Load, keeps duplicate keys for the caller to report,
// bounds the document loop that yaml-cpp 0.7's LoadAll runs forever on a stray ',', and refuses
// hostile documents (alias bombs, self-containing aliases, too many nodes) while reading them.
#pragma once

#include <cstddef>
#include <cstdint>
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

// Nodes (scalars, nulls, lists, mappings) one document may hold: about 90 bytes each in the tree,
// so at most ~380 MB. A scene description is far smaller (meshes belong in mesh files).
inline constexpr std::size_t kMaxNodes = std::size_t{1} << 22;

// Nodes that aliases (*name) may add when expanded — every alias stands for its anchor's whole
// subtree, which the caller walks once per alias — on top of the document's own nodes: at most
// max(kMaxAliasNodes, the document's node count). Without a bound, nested aliases ("billion
// laughs") grow exponentially and even one level (a 50,000-point list aliased 20,000 times, 630 KB
// of text) asks for 10^9 points.
inline constexpr std::uint64_t kMaxAliasNodes = std::uint64_t{1} << 22;

// A syntax error of the text, with yaml-cpp's own message (callers put it in plain words), or a
// document refused for its size (`refused`: the message is already plain words).
class SyntaxError : public std::runtime_error {
 public:
  SyntaxError(const Mark& where, const std::string& message, bool nestedTooDeeply,
              bool refusedForSize = false)
      : std::runtime_error(message),
        mark(where),
        tooDeep(nestedTooDeeply),
        refused(refusedForSize) {}
  Mark mark;
  bool tooDeep;  // lists or mappings nested beyond yaml-cpp's depth guard
  bool refused;  // kMaxNodes, kMaxAliasNodes or an alias inside its own anchor
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

// The bounds parse() enforces; tests lower them.
struct Limits {
  std::size_t maxNodes = kMaxNodes;
  std::uint64_t maxAliasNodes = kMaxAliasNodes;
};

// Parses `text` (read in place, not copied). Throws SyntaxError: yaml-cpp's syntax errors, nesting
// deeper than yaml-cpp's guard, more than maxNodes nodes, aliases expanding beyond
// max(maxAliasNodes, nodes so far), an alias to a list or mapping from inside it (a cycle).
Stream parse(const std::string& text, const Limits& limits = {});

}  // namespace glint::yaml
