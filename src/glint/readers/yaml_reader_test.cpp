// The YAML reader's defences (DESIGN.md §7: hostile input refused before memory is committed):
// aliases share their anchor's values; expansion beyond the alias budget (nested "billion laughs"
// and one-level repetition of a large list), an alias inside its own anchor and more values than
// the limit are refused at the offending place; nesting deeper than kMaxDepth is reported as such.
// Also: reading a file in blocks gives what reading its text gives, cancellation, and the tree's
// places and memory.
#include "glint/readers/yaml_reader.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "glint/core/cancel.h"

namespace glint::yaml {
namespace {

// The SyntaxError read() throws for `text`, or one with the message "(parsed)" when it reads.
SyntaxError errorOf(const std::string& text, const Limits& limits = {}) {
  try {
    read(text, limits);
  } catch (const SyntaxError& e) {
    return e;
  }
  return SyntaxError({}, "(parsed)", SyntaxError::Kind::Syntax);
}

// "[x, x, ..., x]" with `count` scalars.
std::string flowList(std::size_t count) {
  std::string text = "[";
  for (std::size_t i = 0; i < count; ++i) text += i == 0 ? "0" : ", 0";
  return text + "]";
}

// The value of `key` in the root mapping.
ValueId find(const Document& d, std::string_view key) {
  const ValueTree& t = d.values;
  for (std::size_t i = 0; i < t.size(d.root); ++i) {
    if (t.scalar(t.key(d.root, i)) == key) return t.value(d.root, i);
  }
  return kNoValue;
}

TEST(YamlReader, AnAliasSharesItsAnchorsValues) {
  const Document d = read("a: &p [1, 2, 3]\nb: *p\nc: *p\n");
  const ValueTree& t = d.values;
  ASSERT_TRUE(t.isMap(d.root));
  ASSERT_EQ(t.size(d.root), 3u);
  const ValueId b = find(d, "b");
  ASSERT_TRUE(t.isList(b));
  EXPECT_EQ(t.size(b), 3u);
  EXPECT_EQ(t.scalar(t.item(b, 2)), "3");
  // The anchor's place, not the alias's: the value is the same one.
  EXPECT_EQ(t.position(b).line, 1u);
  EXPECT_EQ(find(d, "c"), find(d, "a"));
}

TEST(YamlReader, NestedAliasBombIsRefusedAtTheAliasThatCrossesTheLimit) {
  // Each level repeats the one before ten times: level k stands for about 10^(k+1) values. With
  // the default budget (2^22 ≈ 4.2 million) the third alias of level 6 crosses it (line 7).
  std::string text = "l0: &l0 [0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n";
  for (int k = 1; k <= 9; ++k) {
    const std::string prev = "*l" + std::to_string(k - 1);
    text += "l" + std::to_string(k) + ": &l" + std::to_string(k) + " [";
    for (int i = 0; i < 10; ++i) text += (i ? ", " : "") + prev;
    text += "]\n";
  }
  const SyntaxError e = errorOf(text);
  EXPECT_EQ(e.kind(), SyntaxError::Kind::Refused);
  EXPECT_EQ(e.where().line, 7u) << e.what();
  EXPECT_NE(std::string(e.what()).find("alias bomb"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("4194304"), std::string::npos) << e.what();
}

TEST(YamlReader, RepeatingALargeListIsRefusedExactlyPastTheBudget) {
  // A list of 999 scalars is 1000 values; with a budget of 10,000 alias values ten aliases fit
  // and the eleventh does not (the document itself has ~1,010 values, below the budget).
  const Limits limits{kMaxValues, 10000, kMaxDepth};
  const auto text = [](int aliases) {
    std::string t = "big: &b " + flowList(999) + "\nobjects: [";
    for (int i = 0; i < aliases; ++i) t += (i ? ", " : "") + std::string("*b");
    return t + "]\n";
  };
  EXPECT_STREQ(errorOf(text(10), limits).what(), "(parsed)");
  const SyntaxError e = errorOf(text(11), limits);
  EXPECT_EQ(e.kind(), SyntaxError::Kind::Refused);
  EXPECT_EQ(e.where().line, 2u);
  EXPECT_NE(std::string(e.what()).find("repeat 11000 nodes, more than the limit of 10000"),
            std::string::npos)
      << e.what();
}

TEST(YamlReader, AliasBudgetGrowsWithTheDocumentsOwnSize) {
  // 5,000 own values, then aliases repeating 4,000: within max(budget 1,000, 5,000 own values).
  const Limits limits{kMaxValues, 1000, kMaxDepth};
  std::string text = "pad: " + flowList(4999) + "\nsmall: &s " + flowList(399) + "\nuse: [";
  for (int i = 0; i < 10; ++i) text += (i ? ", " : "") + std::string("*s");
  text += "]\n";
  EXPECT_STREQ(errorOf(text, limits).what(), "(parsed)");
}

TEST(YamlReader, AnAliasInsideItsOwnAnchorIsRefused) {
  for (const char* text : {"a: &a [1, *a]\n", "a: &m {k: *m}\n", "a: &x [[[*x]]]\n"}) {
    const SyntaxError e = errorOf(text);
    EXPECT_EQ(e.kind(), SyntaxError::Kind::Refused) << text;
    EXPECT_NE(std::string(e.what()).find("contains it"), std::string::npos) << e.what();
  }
  // A sibling's anchor is fine; an undefined one is a syntax error at the alias.
  EXPECT_STREQ(errorOf("a: [&x 1, *x]\n").what(), "(parsed)");
  const SyntaxError undefined = errorOf("a: 1\nb: *nope\n");
  EXPECT_EQ(undefined.kind(), SyntaxError::Kind::Syntax);
  EXPECT_EQ(undefined.where().line, 2u);
  EXPECT_EQ(undefined.where().column, 4u);
  EXPECT_NE(std::string(undefined.what()).find("undefined anchor"), std::string::npos);
}

TEST(YamlReader, MoreValuesThanTheLimitAreRefusedAtTheFirstOneTooMany) {
  const Limits limits{100, kMaxAliasValues, kMaxDepth};
  // The mapping, its key and a list of 97 scalars: 100 values exactly.
  EXPECT_STREQ(errorOf("k: " + flowList(97), limits).what(), "(parsed)");
  const SyntaxError e = errorOf("k: " + flowList(98), limits);
  EXPECT_EQ(e.kind(), SyntaxError::Kind::Refused);
  EXPECT_NE(std::string(e.what()).find("more than 100 values"), std::string::npos) << e.what();
  // The 101st value is the 98th scalar: "k: [0" then ", 0" per scalar.
  EXPECT_EQ(e.where().column, 5u + 3 * 97);
}

TEST(YamlReader, NestingDeeperThanTheLimitIsReportedAsTooDeep) {
  const std::string text = "a: " + std::string(5000, '[') + std::string(5000, ']') + "\n";
  const SyntaxError e = errorOf(text);
  EXPECT_EQ(e.kind(), SyntaxError::Kind::TooDeep);
  EXPECT_NE(std::string(e.what()).find("nested too deeply"), std::string::npos);
  // Moderate nesting reads.
  EXPECT_STREQ(errorOf("a: " + std::string(100, '[') + std::string(100, ']')).what(), "(parsed)");
}

TEST(YamlReader, NullsScalarsAndPlaces) {
  const Document d = read("a: ~\nb: null\nc: 'null'\nd:\ne: \"x y\"\n");
  const ValueTree& t = d.values;
  EXPECT_TRUE(t.isNull(find(d, "a")));
  EXPECT_TRUE(t.isNull(find(d, "b")));
  EXPECT_EQ(t.scalar(find(d, "c")), "null");  // quoted: text
  EXPECT_TRUE(t.isNull(find(d, "d")));
  EXPECT_EQ(t.scalar(find(d, "e")), "x y");
  EXPECT_EQ(t.position(find(d, "e")).line, 5u);
  EXPECT_EQ(t.position(find(d, "e")).column, 4u);
  // Columns count characters, not bytes.
  const Document u = read("é: [1, ünï]\n");
  EXPECT_EQ(u.values.position(u.values.item(u.values.value(u.root, 0), 1)).column, 8u);
}

TEST(YamlReader, ASecondDocumentIsFoundAndNotRead) {
  const Document d = read("a: 1\n---\nb: [\n");
  ASSERT_TRUE(d.secondDocument);
  EXPECT_EQ(d.secondDocument->line, 2u);
  EXPECT_EQ(d.values.size(d.root), 1u);
}

TEST(YamlReader, BytesThatAreNotTextAreEncodingErrorsAtTheirPlace) {
  const SyntaxError nul = errorOf(std::string("a: 1\nb: x\0y\n", 11));
  EXPECT_EQ(nul.kind(), SyntaxError::Kind::Encoding);
  EXPECT_EQ(nul.where().line, 2u);
  EXPECT_EQ(nul.where().column, 5u);
  EXPECT_NE(std::string(nul.what()).find("NUL"), std::string::npos) << nul.what();
  // A NUL as the very first byte: still UTF-8 text with a NUL in it, not UTF-16.
  const SyntaxError first = errorOf(std::string("\0a: 1\n", 6));
  EXPECT_EQ(first.kind(), SyntaxError::Kind::Encoding);
  EXPECT_NE(std::string(first.what()).find("NUL"), std::string::npos) << first.what();
  const SyntaxError invalid = errorOf("a: \xff\n");
  EXPECT_EQ(invalid.kind(), SyntaxError::Kind::Encoding);
  EXPECT_NE(std::string(invalid.what()).find("0xFF"), std::string::npos) << invalid.what();
}

// Latin-1 text (the usual non-UTF-8 file): the error is at the accented character's own column
// and names its byte, whatever follows it (libyaml stops at the byte after it, or at the end).
TEST(YamlReader, ANonUtf8CharacterIsNamedByItsOwnByteAndColumn) {
  const std::string incomplete = "starts a character the bytes after it do not complete";
  const std::string latin1 = "(a Latin-1 or Windows-1252 file? save it as UTF-8)";
  struct Case {
    std::string text;
    std::uint32_t line, column;
    std::string message;
  };
  const Case cases[] = {
      {"a: 1\nname: caf\xe9\n", 2, 10, "byte 0xE9 " + incomplete + " " + latin1},
      {"a: 1\nname: caf\xe9", 2, 10, "byte 0xE9 " + incomplete + " " + latin1},
      {"a: 1\nname: caf\xe9 bar\n", 2, 10, "byte 0xE9 " + incomplete + " " + latin1},
      {"caf\xe9: 1\n", 1, 4, "byte 0xE9 " + incomplete + " " + latin1},
      {"a: \xf0\x9f\x98x\n", 1, 4, "byte 0xF0 " + incomplete + " " + latin1},
      {"a: \xc3\xa9\xff\n", 1, 5, "byte 0xFF cannot start a character " + latin1},
      {"a: \xc0\x80\n", 1, 4, "bytes 0xC0 0x80 are a character in more bytes than UTF-8 allows"},
      {"a: \xed\xa0\x80\n", 1, 4,
       "bytes 0xED 0xA0 0x80 are no Unicode character (a surrogate or past U+10FFFF)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const SyntaxError error = errorOf(c.text);
    EXPECT_EQ(error.kind(), SyntaxError::Kind::Encoding);
    EXPECT_EQ(error.where().line, c.line);
    EXPECT_EQ(error.where().column, c.column);
    EXPECT_EQ(std::string(error.what()), "the file is not UTF-8 text here: " + c.message);
  }
}

TEST(YamlReader, Utf16AndUtf8WithAByteOrderMarkAreRead) {
  // "a: é" in UTF-16LE and UTF-8, each after its byte-order mark.
  const std::string utf16(
      "\xff\xfe"
      "a\0:\0 \0\xe9\0\n\0",
      12);
  const Document d16 = read(utf16);
  EXPECT_EQ(d16.values.scalar(find(d16, "a")), "\xc3\xa9");
  const Document d8 = read(
      "\xef\xbb\xbf"
      "a: \xc3\xa9\n");
  EXPECT_EQ(d8.values.scalar(find(d8, "a")), "\xc3\xa9");
}

TEST(YamlReader, MergeKeysJoinTheNamedMappingsWithoutOverridingOwnKeys) {
  const Document d = read(
      "base: &base {a: 1, b: 2}\n"
      "more: &more {b: 20, c: 30}\n"
      "one: {<<: *base, b: 5}\n"
      "two: &two {<<: [*more, *base], d: 4}\n"
      "three: {<<: *two}\n");
  const ValueTree& t = d.values;
  const auto entries = [&](std::string_view key) {
    std::string out;
    const ValueId map = find(d, key);
    for (std::size_t i = 0; i < t.size(map); ++i) {
      out +=
          std::string(t.scalar(t.key(map, i))) + "=" + std::string(t.scalar(t.value(map, i))) + " ";
    }
    return out;
  };
  EXPECT_EQ(entries("one"), "b=5 a=1 ");              // own b wins
  EXPECT_EQ(entries("two"), "d=4 b=20 c=30 a=1 ");    // the first merged mapping wins
  EXPECT_EQ(entries("three"), "d=4 b=20 c=30 a=1 ");  // merged through a merged mapping
  // Merged entries keep their own places (the anchor's lines).
  EXPECT_EQ(t.position(t.key(find(d, "one"), 1)).line, 1u);
  // A quoted "<<" is an ordinary key.
  const Document quoted = read("a: {\"<<\": 1}\n");
  EXPECT_EQ(quoted.values.scalar(quoted.values.key(find(quoted, "a"), 0)), "<<");
  const SyntaxError bad = errorOf("a: {<<: 3}\n");
  EXPECT_EQ(bad.kind(), SyntaxError::Kind::Syntax);
  EXPECT_NE(std::string(bad.what()).find("merge key"), std::string::npos);
}

class YamlFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = std::filesystem::temp_directory_path() /
            ("glint_yaml_reader_" + std::to_string(::getpid()) + ".yaml");
  }
  void TearDown() override { std::filesystem::remove(path_); }
  std::filesystem::path path_;
};

TEST_F(YamlFileTest, AFileReadInBlocksGivesTheSameValuesAsItsText) {
  // Larger than libyaml's blocks (values straddle their boundaries) and than kPipelinedBytes (the
  // file is parsed on a second thread while the tree is built; the text alone is under it).
  std::string text = "objects:\n";
  for (int i = 0; i < 60000; ++i) text += "  - {k: " + std::to_string(i) + ", s: \"é\"}\n";
  ASSERT_GT(text.size(), std::size_t{1} << 20);
  std::ofstream(path_, std::ios::binary) << text;
  const int fd = ::open(path_.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  const Document fromFile = readFile(fd, text.size() + 1);
  ::close(fd);
  const Document fromText = read(text);
  ASSERT_EQ(fromFile.values.valueCount(), fromText.values.valueCount());
  for (ValueId v = 0; v < fromText.values.valueCount(); ++v) {
    ASSERT_EQ(fromFile.values.kind(v), fromText.values.kind(v));
    ASSERT_EQ(fromFile.values.scalar(v), fromText.values.scalar(v));
    ASSERT_EQ(fromFile.values.position(v).line, fromText.values.position(v).line);
    ASSERT_EQ(fromFile.values.position(v).column, fromText.values.position(v).column);
  }
  EXPECT_EQ(fromFile.bytesRead, text.size());
  EXPECT_EQ(fromText.bytesRead, text.size());
}

TEST_F(YamlFileTest, ErrorsDeepInALargeFileAreTheSameAsInASmallOne) {
  // Parsed on a second thread: the failure, its place and message come back as they would from one
  // thread (and the events parsed before it are freed).
  const std::string tail = "last: {a: [1, 2}\n";
  std::string big;
  for (int i = 0; i < 40000; ++i) big += "k" + std::to_string(i) + ": [1.5, 2.5, 3.5]\n";
  std::ofstream(path_, std::ios::binary) << big << tail;
  const int fd = ::open(path_.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  std::string message;
  TextPosition where;
  try {
    readFile(fd, (std::uint64_t{1} << 30));
  } catch (const SyntaxError& e) {
    message = e.what();
    where = e.where();
  }
  ::close(fd);
  const SyntaxError small = errorOf(tail);
  EXPECT_EQ(message, small.what());
  EXPECT_EQ(where.line, 40001u);
  EXPECT_EQ(where.column, small.where().column);
  // An alias bomb found while the other thread parses on: refused, and the thread stopped.
  std::string bomb = big + "l0: &l0 [0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n";
  for (int k = 1; k <= 9; ++k) {
    bomb += "l" + std::to_string(k) + ": &l" + std::to_string(k) + " [";
    for (int i = 0; i < 10; ++i) bomb += (i ? ", *l" : "*l") + std::to_string(k - 1);
    bomb += "]\n";
  }
  bomb += big;
  std::ofstream(path_, std::ios::binary | std::ios::trunc) << bomb;
  const int again = ::open(path_.c_str(), O_RDONLY);
  ASSERT_GE(again, 0);
  EXPECT_THROW(readFile(again, (std::uint64_t{1} << 30)), SyntaxError);
  ::close(again);
}

TEST_F(YamlFileTest, AFileGrowingPastItsLimitIsRefused) {
  std::ofstream(path_, std::ios::binary) << "a: " << std::string(100000, 'x') << "\n";
  const int fd = ::open(path_.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  EXPECT_THROW(readFile(fd, 1000), SyntaxError);
  ::close(fd);
}

TEST(YamlReader, ReadingStopsWhenCancelled) {
  std::string text = "objects:\n";
  for (int i = 0; i < 100000; ++i) text += "  - {k: " + std::to_string(i) + "}\n";
  std::atomic<bool> cancel{true};
  EXPECT_THROW(read(text, {}, &cancel), Cancelled);
}

TEST(YamlReader, EveryKeyAndScalarIsOneValueAndAliasesAddNone) {
  // 10,000 mappings of two entries: the mapping, two keys, two values each.
  std::string text = "objects:\n";
  for (int i = 0; i < 10000; ++i) text += "  - {type: sphere, radius: " + std::to_string(i) + "}\n";
  const Document d = read(text);
  // The root mapping, its key, the list, and 5 values per item.
  EXPECT_EQ(d.values.valueCount(), 3u + 10000 * 5);
  const Document aliased = read("a: &x {type: sphere}\nb: [*x, *x, *x]\n");
  EXPECT_EQ(aliased.values.valueCount(), 1u + 1 + 3 + 1 + 1);
}

}  // namespace
}  // namespace glint::yaml
