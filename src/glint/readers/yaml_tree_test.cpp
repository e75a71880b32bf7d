// The YAML event reader's defences (DESIGN.md §7: hostile input refused before memory is
// committed): aliases share their anchor's node; expansion beyond the alias budget (nested
// "billion laughs" and one-level repetition of a large list), an alias inside its own anchor and
// more nodes than the limit are refused at the offending place; nesting deeper than yaml-cpp's
// guard is reported as such.
#include "glint/readers/yaml_tree.h"

#include <gtest/gtest.h>

#include <string>

namespace glint::yaml {
namespace {

// The SyntaxError parse() throws for `text`, or a default one (message "(parsed)") when it parses.
SyntaxError errorOf(const std::string& text, const Limits& limits = {}) {
  try {
    parse(text, limits);
  } catch (const SyntaxError& e) {
    return e;
  }
  return SyntaxError({}, "(parsed)", false);
}

// "[x, x, ..., x]" with `count` scalars.
std::string flowList(std::size_t count) {
  std::string text = "[";
  for (std::size_t i = 0; i < count; ++i) text += i == 0 ? "0" : ", 0";
  return text + "]";
}

TEST(YamlTree, AnAliasSharesItsAnchorsNode) {
  const Stream s = parse("a: &p [1, 2, 3]\nb: *p\nc: *p\n");
  ASSERT_TRUE(s.root.isMap());
  ASSERT_EQ(s.root.size(), 3u);
  const Node b = s.root.find("b");
  ASSERT_TRUE(b.isSequence());
  EXPECT_EQ(b.size(), 3u);
  EXPECT_EQ(b[2].scalar(), "3");
  // The anchor's place, not the alias's: the node is the same one.
  EXPECT_EQ(b.mark().line, 0);
  EXPECT_EQ(s.root.find("c").mark().pos, s.root.find("a").mark().pos);
}

TEST(YamlTree, NestedAliasBombIsRefusedAtTheAliasThatCrossesTheLimit) {
  // Each level repeats the one before ten times: level k stands for about 10^(k+1) nodes. With the
  // default budget (2^22 ≈ 4.2 million) the third alias of level 6 crosses it (0-based line 6).
  std::string text = "l0: &l0 [0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n";
  for (int k = 1; k <= 9; ++k) {
    const std::string prev = "*l" + std::to_string(k - 1);
    text += "l" + std::to_string(k) + ": &l" + std::to_string(k) + " [";
    for (int i = 0; i < 10; ++i) text += (i ? ", " : "") + prev;
    text += "]\n";
  }
  const SyntaxError e = errorOf(text);
  EXPECT_TRUE(e.refused);
  EXPECT_FALSE(e.tooDeep);
  EXPECT_EQ(e.mark.line, 6) << e.what();
  EXPECT_NE(std::string(e.what()).find("alias bomb"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("4194304"), std::string::npos) << e.what();
}

TEST(YamlTree, RepeatingALargeListIsRefusedExactlyPastTheBudget) {
  // A list of 999 scalars is 1000 nodes; with a budget of 10,000 alias nodes ten aliases fit and
  // the eleventh does not (the document itself has ~1,010 nodes, below the budget).
  const Limits limits{kMaxNodes, 10000};
  const auto text = [](int aliases) {
    std::string t = "big: &b " + flowList(999) + "\nobjects: [";
    for (int i = 0; i < aliases; ++i) t += (i ? ", " : "") + std::string("*b");
    return t + "]\n";
  };
  EXPECT_STREQ(errorOf(text(10), limits).what(), "(parsed)");
  const SyntaxError e = errorOf(text(11), limits);
  EXPECT_TRUE(e.refused);
  EXPECT_EQ(e.mark.line, 1);
  EXPECT_NE(std::string(e.what()).find("repeat 11000 nodes, more than the limit of 10000"),
            std::string::npos)
      << e.what();
}

TEST(YamlTree, AliasBudgetGrowsWithTheDocumentsOwnSize) {
  // 5,000 own nodes, then aliases repeating 4,000: within max(budget 1,000, 5,000 own nodes).
  const Limits limits{kMaxNodes, 1000};
  std::string text = "pad: " + flowList(4999) + "\nsmall: &s " + flowList(399) + "\nuse: [";
  for (int i = 0; i < 10; ++i) text += (i ? ", " : "") + std::string("*s");
  text += "]\n";
  EXPECT_STREQ(errorOf(text, limits).what(), "(parsed)");
}

TEST(YamlTree, AnAliasInsideItsOwnAnchorIsRefused) {
  for (const char* text : {"a: &a [1, *a]\n", "a: &m {k: *m}\n", "a: &x [[[*x]]]\n"}) {
    const SyntaxError e = errorOf(text);
    EXPECT_TRUE(e.refused) << text;
    EXPECT_NE(std::string(e.what()).find("contains it"), std::string::npos) << e.what();
  }
  // A sibling's anchor is fine.
  EXPECT_STREQ(errorOf("a: [&x 1, *x]\n").what(), "(parsed)");
}

TEST(YamlTree, MoreNodesThanTheLimitAreRefusedAtTheFirstOneTooMany) {
  const Limits limits{100, kMaxAliasNodes};
  // The mapping, its key and a list of 97 scalars: 100 nodes exactly.
  EXPECT_STREQ(errorOf("k: " + flowList(97), limits).what(), "(parsed)");
  const SyntaxError e = errorOf("k: " + flowList(98), limits);
  EXPECT_TRUE(e.refused);
  EXPECT_NE(std::string(e.what()).find("more than 100 values"), std::string::npos) << e.what();
  // The 101st node is the 98th scalar: "k: [0" then ", 0" per scalar.
  EXPECT_EQ(e.mark.column, 4 + 3 * 97);
}

TEST(YamlTree, NestingDeeperThanTheGuardIsReportedAsTooDeep) {
  const std::string text = "a: " + std::string(5000, '[') + std::string(5000, ']') + "\n";
  const SyntaxError e = errorOf(text);
  EXPECT_TRUE(e.tooDeep);
  EXPECT_FALSE(e.refused);
  // Moderate nesting parses.
  EXPECT_STREQ(errorOf("a: " + std::string(100, '[') + std::string(100, ']')).what(), "(parsed)");
}

TEST(YamlTree, DefaultLimitsBoundTheTreesMemory) {
  // About 90 bytes per node (item, scalar text, the parent's child index): the node limit keeps a
  // tree under half a GiB; aliases at most double the work of walking it.
  EXPECT_LE(kMaxNodes * 90, std::size_t{512} << 20);
  EXPECT_EQ(kMaxAliasNodes, std::uint64_t{kMaxNodes});
}

}  // namespace
}  // namespace glint::yaml
