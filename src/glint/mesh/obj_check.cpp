#include "glint/mesh/obj_check.h"

#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <cstring>

namespace glint {

namespace {

constexpr bool blank(char c) { return c == ' ' || c == '\t'; }
constexpr bool digit(char c) { return c >= '0' && c <= '9'; }
constexpr char lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c + 32) : c; }

// Whether `word` starts with `prefix` in any case; moves past it if so.
bool takeWord(std::string_view& word, std::string_view prefix) {
  if (word.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (lower(word[i]) != prefix[i]) return false;
  }
  word.remove_prefix(prefix.size());
  return true;
}

std::size_t takeDigits(std::string_view& word) {
  std::size_t n = 0;
  while (n < word.size() && digit(word[n])) ++n;
  word.remove_prefix(n);
  return n;
}

bool isNumber(std::string_view word) {
  if (!word.empty() && (word[0] == '+' || word[0] == '-')) word.remove_prefix(1);
  if (takeWord(word, "nan")) return word.empty();
  if (takeWord(word, "inf")) return word.empty() || (takeWord(word, "inity") && word.empty());
  std::size_t digits = takeDigits(word);
  if (!word.empty() && word[0] == '.') {
    word.remove_prefix(1);
    digits += takeDigits(word);
    // "1.#QNAN", "-1.#IND": the Microsoft C library's not-a-number and infinity.
    if (digits > 0 && !word.empty() && word[0] == '#') {
      word.remove_prefix(1);
      if (takeWord(word, "qnan") || takeWord(word, "snan") || takeWord(word, "ind") ||
          takeWord(word, "inf")) {
        takeDigits(word);
        return word.empty();
      }
      return false;
    }
  }
  if (digits == 0) return false;
  if (!word.empty() && (word[0] == 'e' || word[0] == 'E')) {
    word.remove_prefix(1);
    if (!word.empty() && (word[0] == '+' || word[0] == '-')) word.remove_prefix(1);
    if (takeDigits(word) == 0) return false;
  }
  return word.empty();
}

// A word as a message shows it: at most 24 characters, printable ASCII (others as '?').
std::string quoted(std::string_view word) {
  constexpr std::size_t kMost = 24;
  std::string shown;
  for (std::size_t i = 0; i < word.size() && i < kMost; ++i) {
    const auto c = static_cast<unsigned char>(word[i]);
    shown += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
  }
  if (word.size() > kMost) shown += "...";
  return "'" + shown + "'";
}

enum Kind { kPosition, kTexcoord, kNormal, kKinds };
constexpr std::array<const char*, kKinds> kIndexNames = {"vertex", "texture coordinate", "normal"};
constexpr std::array<const char*, kKinds> kOneName = {"vertex", "texture coordinate", "normal"};
constexpr std::array<const char*, kKinds> kManyNames = {"vertices", "texture coordinates",
                                                        "normals"};

std::string counted(std::uint64_t count, Kind kind) {
  return fmt::format("{} {}", count, count == 1 ? kOneName[kind] : kManyNames[kind]);
}

// The file read statement by statement, once — twice when a face names a vertex further down
// (OBJ allows it): the first pass then counts the whole file (past a fault too), and the second
// judges every positive index against those totals, so the first fault in the file is the one
// said. Memory stays constant whatever the file.
class Checker {
 public:
  explicit Checker(std::string_view text) : text_(text) {}

  std::optional<ObjFault> run() {
    scan();
    if (!forwardSeen_) return fault_;
    totals_ = seen_;
    secondPass_ = true;
    p_ = 0;
    line_ = 1;
    lineStart_ = 0;
    seen_ = {};
    fault_.reset();
    scan();
    return fault_;
  }

 private:
  static bool lineEnd(char c) { return c == '\n' || c == '\r'; }
  // The index past the line end that starts at i.
  std::size_t pastLineEnd(std::size_t i) const {
    return text_[i] == '\r' && i + 1 < text_.size() && text_[i + 1] == '\n' ? i + 2 : i + 1;
  }

  // The next word of the statement from p_ (a backslash before a line end joins the next line);
  // empty at the statement's end (p_ then at its line end) or at a comment.
  std::string_view nextWord() {
    for (;;) {
      while (p_ < text_.size() && blank(text_[p_])) ++p_;
      if (p_ + 1 < text_.size() && text_[p_] == '\\' && lineEnd(text_[p_ + 1])) {
        p_ = pastLineEnd(p_ + 1);
        ++line_;
        lineStart_ = p_;
        continue;
      }
      break;
    }
    const std::size_t start = p_;
    if (start == text_.size() || lineEnd(text_[start]) || text_[start] == '#') return {};
    while (p_ < text_.size() && !blank(text_[p_]) && !lineEnd(text_[p_])) ++p_;
    return text_.substr(start, p_ - start);
  }

  std::size_t column(std::string_view word) const {
    return static_cast<std::size_t>(word.data() - text_.data()) - lineStart_ + 1;
  }

  void fail(std::size_t column, std::string what) {
    if (!fault_) fault_ = ObjFault{line_, column, std::move(what)};
  }

  void scan() {
    while (p_ < text_.size() && (!fault_ || (forwardSeen_ && !secondPass_))) {
      if (!blank(text_[p_]) && !lineEnd(text_[p_])) statement();
      // The rest of the line (a comment, or what a skipped statement holds), then its end.
      while (p_ < text_.size() && !lineEnd(text_[p_])) {
        if (text_[p_] == '\\' && p_ + 1 < text_.size() && lineEnd(text_[p_ + 1])) {
          p_ = pastLineEnd(p_ + 1);
          ++line_;
          lineStart_ = p_;
        } else {
          ++p_;
        }
      }
      if (p_ < text_.size()) {
        p_ = pastLineEnd(p_);
        ++line_;
        lineStart_ = p_;
      }
    }
  }

  void statement() {
    const std::string_view keyword = nextWord();
    if (keyword == "v") {
      numbers(kPosition, 3, keyword);
    } else if (keyword == "vt") {
      numbers(kTexcoord, 1, keyword);
    } else if (keyword == "vn") {
      numbers(kNormal, 3, keyword);
    } else if (keyword == "f" && !fault_) {
      face();
    }
  }

  void numbers(Kind kind, int least, std::string_view keyword) {
    ++seen_[kind];
    if (fault_) return;  // counting the rest only
    int count = 0;
    std::size_t end = column(keyword) + keyword.size();
    for (std::string_view word = nextWord(); !word.empty(); word = nextWord()) {
      if (!isNumber(word)) return fail(column(word), quoted(word) + " is not a number");
      ++count;
      end = column(word) + word.size();
    }
    if (count < least) {
      fail(end, fmt::format("'{}' needs {} {}, this line has {}", keyword, least == 1 ? "a" : "3",
                            least == 1 ? "number" : "numbers", count));
    }
  }

  // A corner's index of `kind`, written as `word` at `column`.
  void index(std::string_view word, std::size_t column, Kind kind) {
    const bool negative = word[0] == '-';
    std::string_view digits = word.substr(word[0] == '-' || word[0] == '+' ? 1 : 0);
    std::uint64_t value = 0;
    for (const char c : digits) {
      value = value > (1ull << 40) ? value : value * 10 + static_cast<std::uint64_t>(c - '0');
    }
    if (value == 0) {
      return fail(column, fmt::format("{} index {}: OBJ indices count from 1 (or back from -1)",
                                      kIndexNames[kind], word));
    }
    if (negative && value > seen_[kind]) {
      return fail(column,
                  fmt::format("{} index {} reaches before the first {} ({} above it)",
                              kIndexNames[kind], word, kOneName[kind],
                              seen_[kind] == 1 ? "1 is" : fmt::format("{} are", seen_[kind])));
    }
    if (negative) return;
    if (!secondPass_) {
      forwardSeen_ = forwardSeen_ || value > seen_[kind];
    } else if (value > totals_[kind]) {
      fail(column, fmt::format("{} index {} is past the file's {}", kIndexNames[kind], word,
                               counted(totals_[kind], kind)));
    }
  }

  // One corner: v, v/vt, v//vn or v/vt/vn, each index [+-]digits.
  void corner(std::string_view word) {
    const std::size_t start = column(word);
    std::array<std::string_view, kKinds> parts{};
    std::array<std::size_t, kKinds> columns{};
    std::size_t part = 0;
    std::size_t i = 0;
    for (;;) {
      const std::size_t from = i;
      if (i < word.size() && (word[i] == '-' || word[i] == '+')) ++i;
      const std::size_t digitsFrom = i;
      while (i < word.size() && digit(word[i])) ++i;
      // Only the texture coordinate index may be left out ("1//2").
      const bool empty = i == from;
      const bool malformed = (!empty && i == digitsFrom) || (empty && part != kTexcoord);
      if (malformed || (i < word.size() && word[i] != '/') || (empty && i == word.size())) {
        return fail(start, quoted(word) +
                               " is not a face corner (v, v/vt, v//vn or v/vt/vn, whole numbers)");
      }
      parts[part] = word.substr(from, i - from);
      columns[part] = start + from;
      if (i == word.size()) break;
      ++i;  // the '/'
      if (++part == kKinds) {
        return fail(start, quoted(word) +
                               " is not a face corner (v, v/vt, v//vn or v/vt/vn, whole numbers)");
      }
    }
    for (int kind = 0; kind < kKinds && !fault_; ++kind) {
      if (!parts[kind].empty()) index(parts[kind], columns[kind], static_cast<Kind>(kind));
    }
  }

  void face() {
    for (std::string_view word = nextWord(); !word.empty() && !fault_; word = nextWord()) {
      corner(word);
    }
  }

  std::string_view text_;
  std::size_t p_ = 0;
  std::size_t line_ = 1;
  std::size_t lineStart_ = 0;
  std::array<std::uint64_t, kKinds> seen_{};    // vertices of each kind so far
  std::array<std::uint64_t, kKinds> totals_{};  // in the whole file (the second pass)
  bool forwardSeen_ = false;                    // a positive index past the vertices so far
  bool secondPass_ = false;
  std::optional<ObjFault> fault_;
};

}  // namespace

std::optional<ObjFault> findObjFault(std::string_view text) {
  for (const char stop : {'\0', '\f'}) {
    if (std::memchr(text.data(), stop, text.size()) != nullptr) return std::nullopt;
  }
  return Checker(text).run();
}

}  // namespace glint
