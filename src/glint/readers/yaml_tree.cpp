#include "glint/readers/yaml_tree.h"

#include <yaml-cpp/anchor.h>
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <istream>
#include <streambuf>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>

namespace glint::yaml {

struct Tree {
  struct Item {
    Node::Kind kind = Node::Kind::Null;
    Mark mark;
    std::string text;                   // scalars
    std::vector<std::size_t> children;  // sequence items, or mapping key, value, key, value...
  };
  std::vector<Item> items;
};

namespace {

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

// Documents read before stopping: the first is the scene; a second means "several documents"; a
// third at the same place as the second means the parser is stuck.
constexpr std::size_t kDocumentsRead = 3;

Mark convert(const YAML::Mark& m) { return {m.pos, m.line, m.column}; }

// An istream over text already in memory: the scene file is not copied again for yaml-cpp.
class TextBuffer : public std::streambuf {
 public:
  explicit TextBuffer(const std::string& text) {
    char* begin = const_cast<char*>(text.data());  // only read: the get area is never written
    setg(begin, begin, begin + text.size());
  }
};

std::uint64_t saturatingAdd(std::uint64_t a, std::uint64_t b) {
  return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}

const std::string& emptyString() {
  static const std::string empty;
  return empty;
}

}  // namespace

// Builds the first document's tree from parser events; later documents only record their start.
class TreeBuilder : public YAML::EventHandler {
 public:
  TreeBuilder(Tree& tree, const Limits& limits) : tree_(tree), limits_(limits) {}

  std::vector<Mark> starts;
  std::size_t root = kNone;

  static Node node(const Tree* tree, std::size_t index) { return Node(tree, index); }

  void OnDocumentStart(const YAML::Mark& mark) override {
    starts.push_back(convert(mark));
    building_ = starts.size() == 1;
    stack_.clear();
  }
  // Nodes aliases have added so far (each alias counts its anchor's expanded subtree).
  std::uint64_t aliasNodes = 0;
  void OnDocumentEnd() override { building_ = false; }
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    add(Node::Kind::Null, mark, anchor, emptyString());
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    if (!building_) return;
    const auto it = anchors_.find(anchor);
    if (it == anchors_.end()) {
      add(Node::Kind::Null, mark, YAML::NullAnchor, emptyString());
      return;
    }
    const std::size_t target = it->second;
    if (open_[target]) {
      // `&a [*a]`: the anchor's node would contain itself, and every walk of it never ends.
      throw SyntaxError(convert(mark),
                        "an alias (*name) refers to a list or mapping that contains it", false,
                        true);
    }
    aliasNodes = saturatingAdd(aliasNodes, weight_[target]);
    const std::uint64_t allowed =
        std::max<std::uint64_t>(limits_.maxAliasNodes, tree_.items.size());
    if (aliasNodes > allowed) {
      throw SyntaxError(
          convert(mark),
          fmt::format("the aliases (*name) up to here repeat {} nodes, more than the limit of {} "
                      "(a YAML alias bomb?)",
                      aliasNodes == UINT64_MAX ? std::string("more than 10^19")
                                               : std::to_string(aliasNodes),
                      allowed),
          false, true);
    }
    attach(target);
  }
  void OnScalar(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t anchor,
                const std::string& value) override {
    add(Node::Kind::Scalar, mark, anchor, value);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value /*style*/) override {
    open(add(Node::Kind::Sequence, mark, anchor, emptyString()));
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value /*style*/) override {
    open(add(Node::Kind::Map, mark, anchor, emptyString()));
  }
  void OnMapEnd() override { close(); }

 private:
  std::size_t add(Node::Kind kind, const YAML::Mark& mark, YAML::anchor_t anchor,
                  const std::string& text) {
    if (!building_) return kNone;
    const std::size_t index = tree_.items.size();
    if (index >= limits_.maxNodes) {
      throw SyntaxError(convert(mark),
                        fmt::format("the document holds more than {} values (scalars, lists and "
                                    "mappings); a scene file describes a scene, and large "
                                    "geometry belongs in mesh files",
                                    limits_.maxNodes),
                        false, true);
    }
    tree_.items.push_back({kind, convert(mark), text, {}});
    weight_.push_back(1);
    open_.push_back(false);
    if (anchor != YAML::NullAnchor) anchors_[anchor] = index;
    attach(index);
    return index;
  }
  void attach(std::size_t index) {
    if (stack_.empty()) {
      if (root == kNone) root = index;
    } else {
      tree_.items[stack_.back()].children.push_back(index);
    }
  }
  void open(std::size_t index) {
    if (index == kNone) return;
    stack_.push_back(index);
    open_[index] = true;
  }
  // A closed collection's weight: itself plus its children's (aliased subtrees included).
  void close() {
    if (!building_ || stack_.empty()) return;
    const std::size_t index = stack_.back();
    stack_.pop_back();
    open_[index] = false;
    std::uint64_t weight = 1;
    for (const std::size_t child : tree_.items[index].children) {
      weight = saturatingAdd(weight, weight_[child]);
    }
    weight_[index] = weight;
  }

  Tree& tree_;
  const Limits limits_;
  bool building_ = false;
  std::vector<std::size_t> stack_;  // open collections
  std::unordered_map<YAML::anchor_t, std::size_t> anchors_;
  // Per item: nodes of its subtree with aliases expanded (saturating), and whether it is open.
  std::vector<std::uint64_t> weight_;
  std::vector<bool> open_;
};

Node::Kind Node::kind() const { return tree_ ? tree_->items[index_].kind : Kind::Undefined; }

Mark Node::mark() const { return tree_ ? tree_->items[index_].mark : Mark{}; }

const std::string& Node::scalar() const {
  return isScalar() ? tree_->items[index_].text : emptyString();
}

std::size_t Node::size() const {
  if (!tree_) return 0;
  const std::size_t n = tree_->items[index_].children.size();
  return isMap() ? n / 2 : n;
}

Node Node::operator[](std::size_t i) const {
  if (!isSequence() || i >= size()) return {};
  return Node(tree_, tree_->items[index_].children[i]);
}

Node Node::key(std::size_t i) const {
  if (!isMap() || i >= size()) return {};
  return Node(tree_, tree_->items[index_].children[2 * i]);
}

Node Node::value(std::size_t i) const {
  if (!isMap() || i >= size()) return {};
  return Node(tree_, tree_->items[index_].children[2 * i + 1]);
}

Node Node::find(std::string_view name) const {
  for (std::size_t i = 0; i < size(); ++i) {
    const Node k = key(i);
    if (k.isScalar() && k.scalar() == name) return value(i);
  }
  return {};
}

Stream parse(const std::string& text, const Limits& limits) {
  auto tree = std::make_shared<Tree>();
  TreeBuilder builder(*tree, limits);
  try {
    TextBuffer buffer(text);
    std::istream in(&buffer);
    YAML::Parser parser(in);
    while (builder.starts.size() < kDocumentsRead && parser.HandleNextDocument(builder)) {
    }
  } catch (const YAML::DeepRecursion& e) {
    throw SyntaxError(convert(e.mark), e.msg, true);
  } catch (const YAML::Exception& e) {
    throw SyntaxError(convert(e.mark), e.msg, false);
  }
  Stream stream;
  stream.documentStarts = builder.starts;
  // yaml-cpp 0.7 answers a token it cannot place (a ',' outside brackets) with an empty document
  // that does not consume it, again and again (jbeder/yaml-cpp#1040).
  stream.stuck =
      builder.starts.size() == kDocumentsRead && builder.starts[1].pos == builder.starts[2].pos;
  if (builder.root != kNone) stream.root = TreeBuilder::node(tree.get(), builder.root);
  stream.tree = std::move(tree);
  return stream;
}

}  // namespace glint::yaml
