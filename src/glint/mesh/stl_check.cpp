#include "glint/mesh/stl_check.h"

#include <fmt/format.h>

#include <cctype>
#include <cstdint>

#include "glint/mesh/file_fault.h"
#include "glint/readers/diagnostics.h"

namespace glint {
namespace {

// The words of a text with their places; a word ends at a blank or a line end.
class Words {
 public:
  explicit Words(std::string_view text) : text_(text) {}

  struct Word {
    std::string_view text;  // empty at the end of the file
    std::size_t line = 0;
    std::size_t column = 0;
  };

  Word next() {
    while (at_ < text_.size() && isSpace(text_[at_])) advance();
    Word word;
    word.line = line_;
    word.column = at_ - lineStart_ + 1;
    const std::size_t start = at_;
    while (at_ < text_.size() && !isSpace(text_[at_])) ++at_;
    word.text = text_.substr(start, at_ - start);
    return word;
  }
  // Skips the rest of the current line (a solid's name).
  void skipLine() {
    while (at_ < text_.size() && text_[at_] != '\n') ++at_;
  }

 private:
  // NUL too: exporters pad files with NULs after endsolid.
  static bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v' || c == '\0';
  }
  void advance() {
    if (text_[at_] == '\n') {
      ++line_;
      lineStart_ = at_ + 1;
    }
    ++at_;
  }

  std::string_view text_;
  std::size_t at_ = 0;
  std::size_t line_ = 1;
  std::size_t lineStart_ = 0;
};

StlFault faultAt(const Words::Word& word, std::string what) {
  return StlFault{word.line, word.column, std::move(what)};
}

// A keyword in any case.
bool is(const Words::Word& word, std::string_view keyword) {
  if (word.text.size() != keyword.size()) return false;
  for (std::size_t i = 0; i < keyword.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(word.text[i])) != keyword[i]) return false;
  }
  return true;
}

}  // namespace

bool isBinaryStl(std::string_view file) {
  if (file.size() < 84) return false;
  const auto* bytes = reinterpret_cast<const unsigned char*>(file.data());
  const std::uint64_t count = std::uint64_t{bytes[80]} | std::uint64_t{bytes[81]} << 8 |
                              std::uint64_t{bytes[82]} << 16 | std::uint64_t{bytes[83]} << 24;
  return 84 + 50 * count == file.size();
}

std::optional<StlFault> findStlFault(std::string_view file) {
  if (isBinaryStl(file)) return std::nullopt;
  Words words(file);
  Words::Word word = words.next();
  if (!is(word, "solid")) return std::nullopt;  // not ASCII STL: assimp's words for it
  // Three numbers after `owner` (a vertex, a normal), or the fault.
  const auto numbers = [&](std::string_view owner) -> std::optional<StlFault> {
    for (int k = 0; k < 3; ++k) {
      const Words::Word number = words.next();
      if (number.text.empty()) {
        return faultAt(number, fmt::format("the file ends within a {} (3 numbers)", owner));
      }
      if (!isNumberWord(number.text)) {
        return faultAt(number, fmt::format("{} is not a number (a {} has 3)",
                                           quoteForMessage(number.text), owner));
      }
    }
    return std::nullopt;
  };
  const auto expect = [&](std::string_view keyword,
                          std::string_view where) -> std::optional<StlFault> {
    const Words::Word got = words.next();
    if (is(got, keyword)) return std::nullopt;
    if (got.text.empty()) {
      return faultAt(got,
                     fmt::format("the file ends {}, before '{}' (cut short?)", where, keyword));
    }
    return faultAt(
        got, fmt::format("expected '{}' {}, got {}", keyword, where, quoteForMessage(got.text)));
  };
  while (true) {
    // In a solid: its name, then facets until endsolid.
    words.skipLine();
    while (true) {
      word = words.next();
      if (word.text.empty()) return std::nullopt;  // no endsolid: assimp takes the facets read
      if (is(word, "endsolid")) break;
      if (!is(word, "facet")) {
        return faultAt(word, fmt::format("expected 'facet' or 'endsolid', got {}",
                                         quoteForMessage(word.text)));
      }
      const Words::Word facet = word;
      word = words.next();
      if (is(word, "normal")) {
        if (auto fault = numbers("normal")) return fault;
        if (auto fault = expect("outer", "in a facet")) return fault;
      } else if (!is(word, "outer")) {
        return faultAt(word, fmt::format("expected 'normal' or 'outer' in a facet, got {}",
                                         word.text.empty() ? "the end of the file"
                                                           : quoteForMessage(word.text)));
      }
      if (auto fault = expect("loop", "after 'outer'")) return fault;
      int vertices = 0;
      while (true) {
        word = words.next();
        if (is(word, "endloop")) break;
        if (!is(word, "vertex")) {
          if (word.text.empty()) {
            return faultAt(word, "the file ends within a facet, before 'endloop' (cut short?)");
          }
          return faultAt(word, fmt::format("expected 'vertex' or 'endloop', got {}",
                                           quoteForMessage(word.text)));
        }
        if (++vertices > 3) {
          return faultAt(word,
                         "a facet with more than 3 vertices: STL facets are triangles (the mesh "
                         "library would keep the first three and lose the rest)");
        }
        if (auto fault = numbers("vertex")) return fault;
      }
      if (vertices < 3) {
        return faultAt(facet,
                       fmt::format("a facet of {} vertices: STL facets are triangles", vertices));
      }
      if (auto fault = expect("endfacet", "after 'endloop'")) return fault;
    }
    words.skipLine();  // endsolid's name
    word = words.next();
    if (word.text.empty()) return std::nullopt;
    if (!is(word, "solid")) {
      return faultAt(word, fmt::format("expected 'solid' or the end after 'endsolid', got {}",
                                       quoteForMessage(word.text)));
    }
  }
}

}  // namespace glint
