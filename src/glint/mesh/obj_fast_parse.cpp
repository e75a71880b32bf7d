#include "glint/mesh/obj_fast_parse.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include <assimp/fast_atof.h>

namespace glint {

namespace {

// The subset, line by line (a line ends at '\n', "\r\n" or the end of the text):
//   (empty or blanks only)                       skipped, as assimp does
//   # anything                                   a comment
//   s anything                                   a smoothing group (assimp ignores it)
//   o NAME                                       at most one, before the first face
//   v X Y Z | vn X Y Z | vt U V [W]              numbers: [+-]?digits[.digits][(e|E)[+-]?digits]
//   f C C C ...                                  3 or more corners of one form in the whole file:
//                                                I, I/I, I//I or I/I/I with I = [1-9][0-9]{0,8}
// Fields are separated by spaces and tabs, and a line may end in blanks. assimp reads every
// such line as written here; its parser's quirks lie outside (".5" is no number to its component
// count, a line starting with a blank is skipped whole, "v/n" means a normal index when there are
// no texture coordinates yet, a backslash before a line end continues the line, a NUL or a form
// feed ends one), and so does anything it would refuse or repair (index 0, indices past the
// arrays, which it rejects or answers by dropping all normals or texture coordinates).

// The longest number token taken: assimp copies a word into a 4 KiB buffer; far below that, and
// no real file writes more than ~25 characters for a float.
constexpr std::size_t kMaxNumberLength = 64;

// What assimp's number parser throws here (the arguments are its message's parts).
struct NumberRefused {
  template <typename... Parts>
  explicit NumberRefused(Parts&&... /*message*/) {}
};

enum class CornerForm : std::uint8_t { Unknown, V, VT, VN, VTN };

class Parser {
 public:
  explicit Parser(std::string_view text) : p_(text.data()), end_(text.data() + text.size()) {}

  std::optional<SimpleObj> run() {
    reserve();
    while (p_ < end_) {
      if (!line()) return std::nullopt;
    }
    return finish();
  }

 private:
  static bool blank(char c) { return c == ' ' || c == '\t'; }

  // The arrays sized from a count of the lines by their first characters (memchr's pass over the
  // text is far cheaper than growing them: every doubling copies and touches fresh pages).
  void reserve() {
    std::size_t v = 0, vn = 0, vt = 0, f = 0;
    for (const char* line = p_; line < end_;) {
      if (line[0] == 'v' && line + 1 < end_) {
        v += blank(line[1]) ? 1 : 0;
        vn += line[1] == 'n' ? 1 : 0;
        vt += line[1] == 't' ? 1 : 0;
      }
      f += line[0] == 'f' ? 1 : 0;
      const void* next = std::memchr(line, '\n', static_cast<std::size_t>(end_ - line));
      if (next == nullptr) break;
      line = static_cast<const char*>(next) + 1;
    }
    obj_.positions.reserve(3 * v);
    obj_.normals.reserve(3 * vn);
    obj_.texcoords.reserve(3 * vt);
    obj_.faceSizes.reserve(f);
    obj_.vertexIndices.reserve(3 * f);  // triangles; polygons grow it
    if (vn > 0) obj_.normalIndices.reserve(3 * f);
    if (vt > 0) obj_.texcoordIndices.reserve(3 * f);
  }
  static bool digit(char c) { return c >= '0' && c <= '9'; }

  // At the end of a line: moves past it. False when more than blanks is left.
  bool endOfLine() {
    while (p_ < end_ && blank(*p_)) ++p_;
    if (p_ == end_) return true;
    if (*p_ == '\n') {
      ++p_;
      return true;
    }
    if (*p_ == '\r' && p_ + 1 < end_ && p_[1] == '\n') {
      p_ += 2;
      return true;
    }
    return false;
  }

  // Skips a comment's rest of the line; false on a character that would end or continue the
  // line for assimp elsewhere than at its end.
  bool skipRest() {
    while (p_ < end_ && *p_ != '\n') {
      const char c = *p_;
      if (c == '\0' || c == '\f' || c == '\\') return false;
      if (c == '\r' && !(p_ + 1 < end_ && p_[1] == '\n')) return false;
      ++p_;
    }
    if (p_ < end_) ++p_;
    return true;
  }

  bool skipBlanks() {
    const char* start = p_;
    while (p_ < end_ && blank(*p_)) ++p_;
    return p_ != start;
  }

  // One number token, converted by assimp's fast_atof exactly as its OBJ parser converts the word
  // it copied out.
  bool number(float& out) {
    const char* start = p_;
    if (p_ < end_ && (*p_ == '+' || *p_ == '-')) ++p_;
    const char* digits = p_;
    while (p_ < end_ && digit(*p_)) ++p_;
    if (p_ == digits) return false;
    if (p_ < end_ && *p_ == '.') {
      ++p_;
      const char* fraction = p_;
      while (p_ < end_ && digit(*p_)) ++p_;
      if (p_ == fraction) return false;
    }
    if (p_ < end_ && (*p_ == 'e' || *p_ == 'E')) {
      ++p_;
      if (p_ < end_ && (*p_ == '+' || *p_ == '-')) ++p_;
      const char* exponent = p_;
      while (p_ < end_ && digit(*p_)) ++p_;
      if (p_ == exponent) return false;
    }
    // The token must end at a blank or the line's end.
    if (p_ < end_ && !blank(*p_) && *p_ != '\n' && *p_ != '\r') return false;
    const auto length = static_cast<std::size_t>(p_ - start);
    if (length > kMaxNumberLength) return false;
    char word[kMaxNumberLength + 1];
    std::memcpy(word, start, length);
    word[length] = '\0';
    try {
      // Assimp::fast_atof(word), which throws assimp's DeadlyImportError (whose constructor the
      // shared library keeps to itself) where this throws NumberRefused; the same arithmetic.
      ai_real value = 0;
      Assimp::fast_atoreal_move<ai_real, NumberRefused>(word, value);
      out = static_cast<float>(value);
    } catch (const NumberRefused&) {
      return false;  // an exponent or integer part past 64 bits: assimp refuses the file
    }
    return true;
  }

  // Up to `most` numbers after the keyword; their count.
  int numbers(float* out, int most) {
    int n = 0;
    while (skipBlanks() && p_ < end_ && *p_ != '\n' && *p_ != '\r') {
      if (n == most || !number(out[n])) return -1;
      ++n;
    }
    return endOfLine() ? n : -1;
  }

  // A 1-based index as assimp's face parser reads it (atoi, then as many characters as the value
  // has digits): no sign, no leading zero, at most 9 digits.
  bool index(std::uint32_t& out) {
    if (p_ == end_ || *p_ < '1' || *p_ > '9') return false;
    std::uint32_t value = 0;
    int count = 0;
    while (p_ < end_ && digit(*p_)) {
      if (++count > 9) return false;
      value = value * 10 + static_cast<std::uint32_t>(*p_ - '0');
      ++p_;
    }
    out = value - 1;
    return true;
  }

  bool slash() {
    if (p_ < end_ && *p_ == '/') {
      ++p_;
      return true;
    }
    return false;
  }

  bool face() {
    std::uint32_t corners = 0;
    while (skipBlanks() && p_ < end_ && *p_ != '\n' && *p_ != '\r') {
      std::uint32_t v = 0, t = 0, n = 0;
      if (!index(v)) return false;
      CornerForm form = CornerForm::V;
      if (slash()) {
        if (slash()) {
          if (!index(n)) return false;
          form = CornerForm::VN;
        } else {
          if (!index(t)) return false;
          form = slash() ? CornerForm::VTN : CornerForm::VT;
          if (form == CornerForm::VTN && !index(n)) return false;
        }
      }
      if (p_ < end_ && !blank(*p_) && *p_ != '\n' && *p_ != '\r') return false;
      if (form_ == CornerForm::Unknown) form_ = form;
      if (form != form_) return false;
      // A texture index while the file has no texture coordinates yet is read by assimp as a
      // normal index (when there are normals) or kept for none: not in the subset.
      if ((form == CornerForm::VT || form == CornerForm::VTN) && obj_.texcoords.empty()) {
        return false;
      }
      obj_.vertexIndices.push_back(v);
      if (form == CornerForm::VT || form == CornerForm::VTN) obj_.texcoordIndices.push_back(t);
      if (form == CornerForm::VN || form == CornerForm::VTN) obj_.normalIndices.push_back(n);
      ++corners;
    }
    if (corners < 3 || !endOfLine()) return false;
    obj_.faceSizes.push_back(corners);
    return true;
  }

  bool objectName() {
    if (named_ || !obj_.faceSizes.empty() || !skipBlanks()) return false;
    const char* start = p_;
    while (p_ < end_ && !blank(*p_) && *p_ != '\n' && *p_ != '\r') {
      if (*p_ == '\0' || *p_ == '\f' || *p_ == '\\') return false;
      ++p_;
    }
    if (p_ == start) return false;
    obj_.objectName.assign(start, p_);
    named_ = true;
    return endOfLine();
  }

  bool line() {
    const char c = *p_;
    const char next = p_ + 1 < end_ ? p_[1] : '\n';
    if (c == '#' || c == 's') return skipRest();
    if (c == '\n' || c == '\r' || blank(c)) return endOfLine();  // blanks only, else refused
    float values[3] = {0, 0, 0};
    if (c == 'v' && blank(next)) {
      ++p_;
      if (numbers(values, 3) != 3) return false;
      obj_.positions.insert(obj_.positions.end(), values, values + 3);
      return true;
    }
    if (c == 'v' && next == 'n' && p_ + 2 < end_ && blank(p_[2])) {
      p_ += 2;
      if (numbers(values, 3) != 3) return false;
      obj_.normals.insert(obj_.normals.end(), values, values + 3);
      return true;
    }
    if (c == 'v' && next == 't' && p_ + 2 < end_ && blank(p_[2])) {
      p_ += 2;
      const int n = numbers(values, 3);
      if (n != 2 && n != 3) return false;
      // assimp makes texture coordinates that are not finite 0, "the OBJ default value".
      for (float& value : values) {
        if (!std::isfinite(value)) value = 0;
      }
      obj_.texcoords.insert(obj_.texcoords.end(), values, values + 3);
      obj_.texcoordDimension = std::max(obj_.texcoordDimension, static_cast<unsigned>(n));
      return true;
    }
    if (c == 'f' && blank(next)) {
      ++p_;
      return face();
    }
    if (c == 'o' && blank(next)) {
      ++p_;
      return objectName();
    }
    return false;
  }

  std::optional<SimpleObj> finish() {
    if (obj_.faceSizes.empty()) return std::nullopt;  // assimp's point cloud or an empty model
    const auto inRange = [](const std::vector<std::uint32_t>& indices, std::size_t count) {
      for (const std::uint32_t i : indices) {
        if (i >= count) return false;
      }
      return true;
    };
    if (!inRange(obj_.vertexIndices, obj_.positions.size() / 3) ||
        !inRange(obj_.normalIndices, obj_.normals.size() / 3) ||
        !inRange(obj_.texcoordIndices, obj_.texcoords.size() / 3)) {
      return std::nullopt;
    }
    // assimp keeps a mesh's corners in 32 bits (AI_MAX_VERTICES); far past glint's own limits.
    if (obj_.vertexIndices.size() >= 0x7fffffffu) return std::nullopt;
    return std::move(obj_);
  }

  const char* p_;
  const char* end_;
  SimpleObj obj_;
  CornerForm form_ = CornerForm::Unknown;
  bool named_ = false;
};

}  // namespace

std::optional<SimpleObj> parseSimpleObj(std::string_view text) {
  // assimp refuses an OBJ file under 16 bytes; a NUL anywhere ends a line for it.
  if (text.size() < 16) return std::nullopt;
  return Parser(text).run();
}

bool objFastPathDisabled() {
  const char* choice = std::getenv("GLINT_OBJ_READER");
  return choice != nullptr && std::strcmp(choice, "assimp") == 0;
}

}  // namespace glint
