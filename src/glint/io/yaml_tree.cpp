#include "glint/io/yaml_tree.h"

#include <yaml-cpp/anchor.h>
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <sstream>
#include <unordered_map>
#include <utility>

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

const std::string& emptyString() {
  static const std::string empty;
  return empty;
}

}  // namespace

// Builds the first document's tree from parser events; later documents only record their start.
class TreeBuilder : public YAML::EventHandler {
 public:
  explicit TreeBuilder(Tree& tree) : tree_(tree) {}

  std::vector<Mark> starts;
  std::size_t root = kNone;

  static Node node(const Tree* tree, std::size_t index) { return Node(tree, index); }

  void OnDocumentStart(const YAML::Mark& mark) override {
    starts.push_back(convert(mark));
    building_ = starts.size() == 1;
    stack_.clear();
  }
  void OnDocumentEnd() override { building_ = false; }
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    add(Node::Kind::Null, mark, anchor, emptyString());
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    if (!building_) return;
    const auto it = anchors_.find(anchor);
    if (it == anchors_.end()) {
      add(Node::Kind::Null, mark, YAML::NullAnchor, emptyString());
    } else {
      attach(it->second);
    }
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
    tree_.items.push_back({kind, convert(mark), text, {}});
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
    if (index != kNone) stack_.push_back(index);
  }
  void close() {
    if (building_ && !stack_.empty()) stack_.pop_back();
  }

  Tree& tree_;
  bool building_ = false;
  std::vector<std::size_t> stack_;  // open collections
  std::unordered_map<YAML::anchor_t, std::size_t> anchors_;
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

Stream parse(const std::string& text) {
  auto tree = std::make_shared<Tree>();
  TreeBuilder builder(*tree);
  try {
    std::istringstream in(text);
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
