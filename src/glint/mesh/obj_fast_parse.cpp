#include "glint/mesh/obj_fast_parse.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <vector>

#include <assimp/fast_atof.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

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

bool blank(char c) { return c == ' ' || c == '\t'; }

// Lines of a text by their first characters: what sizes the arrays (memchr's pass over the text
// is far cheaper than growing them: every doubling copies and touches fresh pages).
struct LineCounts {
  std::size_t v = 0, vn = 0, vt = 0, f = 0;

  static LineCounts of(std::string_view text) {
    LineCounts n;
    const char* end = text.data() + text.size();
    for (const char* line = text.data(); line < end;) {
      if (line[0] == 'v' && line + 1 < end) {
        n.v += blank(line[1]) ? 1 : 0;
        n.vn += line[1] == 'n' ? 1 : 0;
        n.vt += line[1] == 't' ? 1 : 0;
      }
      n.f += line[0] == 'f' ? 1 : 0;
      const void* next = std::memchr(line, '\n', static_cast<std::size_t>(end - line));
      if (next == nullptr) break;
      line = static_cast<const char*>(next) + 1;
    }
    return n;
  }
  LineCounts& operator+=(const LineCounts& o) {
    v += o.v;
    vn += o.vn;
    vt += o.vt;
    f += o.f;
    return *this;
  }
  void reserve(SimpleObj& obj) const {
    obj.positions.reserve(3 * v);
    obj.normals.reserve(3 * vn);
    obj.texcoords.reserve(3 * vt);
    obj.faceSizes.reserve(f);
    obj.vertexIndices.reserve(3 * f);  // triangles; polygons grow it
    if (vn > 0) obj.normalIndices.reserve(3 * f);
    if (vt > 0) obj.texcoordIndices.reserve(3 * f);
  }
};

// Parses one piece of the text: the whole of it, or one of the chunks (each beginning at the
// start of a line) that parseSimpleObj reads side by side. What a line's validity depends on
// beyond its piece is kept for the merge to decide (ParsedChunk): whether a face with texture
// indices came before any `vt` line of the piece, the piece's corner form, and whether it named
// the object before its first face.
class Parser {
 public:
  explicit Parser(std::string_view text) : p_(text.data()), end_(text.data() + text.size()) {}

  // False at a line outside the subset.
  bool run(SimpleObj& obj) {
    obj_ = &obj;
    while (p_ < end_) {
      if (!line()) return false;
    }
    return true;
  }
  CornerForm form() const { return form_; }
  bool named() const { return named_; }
  bool texturedFaceBeforeTexcoords() const { return texturedFaceBeforeTexcoords_; }

 private:
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
      // normal index (when there are normals) or kept for none: not in the subset. Whether an
      // earlier piece of the file had some, the merge decides.
      if ((form == CornerForm::VT || form == CornerForm::VTN) && obj_->texcoords.empty()) {
        texturedFaceBeforeTexcoords_ = true;
      }
      obj_->vertexIndices.push_back(v);
      if (form == CornerForm::VT || form == CornerForm::VTN) obj_->texcoordIndices.push_back(t);
      if (form == CornerForm::VN || form == CornerForm::VTN) obj_->normalIndices.push_back(n);
      ++corners;
    }
    if (corners < 3 || !endOfLine()) return false;
    obj_->faceSizes.push_back(corners);
    return true;
  }

  bool objectName() {
    if (named_ || !obj_->faceSizes.empty() || !skipBlanks()) return false;
    const char* start = p_;
    while (p_ < end_ && !blank(*p_) && *p_ != '\n' && *p_ != '\r') {
      if (*p_ == '\0' || *p_ == '\f' || *p_ == '\\') return false;
      ++p_;
    }
    if (p_ == start) return false;
    obj_->objectName.assign(start, p_);
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
      obj_->positions.insert(obj_->positions.end(), values, values + 3);
      return true;
    }
    if (c == 'v' && next == 'n' && p_ + 2 < end_ && blank(p_[2])) {
      p_ += 2;
      if (numbers(values, 3) != 3) return false;
      obj_->normals.insert(obj_->normals.end(), values, values + 3);
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
      obj_->texcoords.insert(obj_->texcoords.end(), values, values + 3);
      obj_->texcoordDimension = std::max(obj_->texcoordDimension, static_cast<unsigned>(n));
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

  const char* p_;
  const char* end_;
  SimpleObj* obj_ = nullptr;
  CornerForm form_ = CornerForm::Unknown;
  bool named_ = false;
  bool texturedFaceBeforeTexcoords_ = false;
};

// One piece of the text as its Parser left it.
struct ParsedChunk {
  std::string_view text;
  LineCounts lines;
  SimpleObj obj;
  bool parsed = false;
  CornerForm form = CornerForm::Unknown;
  bool named = false;
  bool texturedFaceBeforeTexcoords = false;
};

// The text cut into `count` pieces of about equal size, each beginning at the start of a line;
// fewer when the text has fewer lines.
std::vector<std::string_view> cutAtLines(std::string_view text, std::size_t count) {
  std::vector<std::string_view> pieces;
  std::size_t begin = 0;
  for (std::size_t k = 1; k <= count && begin < text.size(); ++k) {
    std::size_t end = text.size();
    if (k < count) {
      const std::size_t target = std::max(begin, text.size() / count * k);
      const std::size_t newline = text.find('\n', target);
      end = newline == std::string_view::npos ? text.size() : newline + 1;
    }
    if (end > begin) pieces.push_back(text.substr(begin, end - begin));
    begin = end;
  }
  return pieces;
}

// The pieces joined into the one SimpleObj of the whole file (in chunks[0]'s arrays, sized for
// all of them), or nothing where a piece depends on an earlier one in a way the subset refuses:
// the serial parser's answer for the whole text. `inParallel` runs the arrays' appends (each a
// task) side by side, or one after the other.
template <class InParallel>
std::optional<SimpleObj> merge(std::vector<ParsedChunk>& chunks, const InParallel& inParallel) {
  CornerForm form = CornerForm::Unknown;
  bool texcoordsSoFar = false;
  bool namedOrFacesSoFar = false;
  for (const ParsedChunk& c : chunks) {
    if (!c.parsed) return std::nullopt;
    if (c.texturedFaceBeforeTexcoords && !texcoordsSoFar) return std::nullopt;
    if (c.named && namedOrFacesSoFar) return std::nullopt;
    if (c.form != CornerForm::Unknown) {
      if (form != CornerForm::Unknown && c.form != form) return std::nullopt;
      form = c.form;
    }
    texcoordsSoFar = texcoordsSoFar || !c.obj.texcoords.empty();
    namedOrFacesSoFar = namedOrFacesSoFar || c.named || !c.obj.faceSizes.empty();
  }
  SimpleObj& out = chunks[0].obj;
  // Each array of the later pieces appended to the first piece's (whose capacity holds them all).
  const auto appender = [&chunks](auto member) {
    return [&chunks, member] {
      auto& to = chunks[0].obj.*member;
      for (std::size_t k = 1; k < chunks.size(); ++k) {
        const auto& from = chunks[k].obj.*member;
        to.insert(to.end(), from.begin(), from.end());
      }
    };
  };
  inParallel(appender(&SimpleObj::positions), appender(&SimpleObj::normals),
             appender(&SimpleObj::texcoords), appender(&SimpleObj::faceSizes),
             appender(&SimpleObj::vertexIndices), appender(&SimpleObj::texcoordIndices),
             appender(&SimpleObj::normalIndices));
  for (std::size_t k = 1; k < chunks.size(); ++k) {
    out.texcoordDimension = std::max(out.texcoordDimension, chunks[k].obj.texcoordDimension);
    if (chunks[k].named) out.objectName = chunks[k].obj.objectName;
  }
  return std::move(out);
}

// The checks on the whole file's arrays.
std::optional<SimpleObj> finish(std::optional<SimpleObj> obj) {
  // No face: assimp's point cloud or an empty model.
  if (!obj || obj->faceSizes.empty()) return std::nullopt;
  const auto inRange = [](const std::vector<std::uint32_t>& indices, std::size_t count) {
    for (const std::uint32_t i : indices) {
      if (i >= count) return false;
    }
    return true;
  };
  if (!inRange(obj->vertexIndices, obj->positions.size() / 3) ||
      !inRange(obj->normalIndices, obj->normals.size() / 3) ||
      !inRange(obj->texcoordIndices, obj->texcoords.size() / 3)) {
    return std::nullopt;
  }
  // assimp keeps a mesh's corners in 32 bits (AI_MAX_VERTICES); far past glint's own limits.
  if (obj->vertexIndices.size() >= 0x7fffffffu) return std::nullopt;
  return obj;
}

}  // namespace

std::optional<SimpleObj> parseSimpleObjInChunks(std::string_view text, std::size_t chunkCount,
                                                unsigned threads) {
  // assimp refuses an OBJ file under 16 bytes; a NUL anywhere ends a line for it.
  if (text.size() < 16) return std::nullopt;
  std::vector<ParsedChunk> chunks;
  for (const std::string_view piece : cutAtLines(text, std::max<std::size_t>(chunkCount, 1))) {
    chunks.emplace_back().text = piece;
  }
  const bool parallel = threads > 1 && chunks.size() > 1;
  std::optional<tbb::task_arena> arena;
  if (parallel) arena.emplace(static_cast<int>(std::min<std::size_t>(threads, chunks.size())));
  const auto forEachChunk = [&](const auto& body) {
    if (!parallel) {
      for (ParsedChunk& c : chunks) body(c);
      return;
    }
    arena->execute([&] {
      tbb::parallel_for(std::size_t{0}, chunks.size(), [&](std::size_t k) { body(chunks[k]); });
    });
  };
  const auto inParallel = [&](const auto&... tasks) {
    if (!parallel) {
      (tasks(), ...);
      return;
    }
    arena->execute([&] { tbb::parallel_invoke(tasks...); });
  };
  forEachChunk([](ParsedChunk& c) { c.lines = LineCounts::of(c.text); });
  // The first piece's arrays take the others' at the merge: sized for the whole file.
  LineCounts total;
  for (const ParsedChunk& c : chunks) total += c.lines;
  forEachChunk([&](ParsedChunk& c) {
    (&c == &chunks[0] ? total : c.lines).reserve(c.obj);
    Parser parser(c.text);
    c.parsed = parser.run(c.obj);
    c.form = parser.form();
    c.named = parser.named();
    c.texturedFaceBeforeTexcoords = parser.texturedFaceBeforeTexcoords();
  });
  return finish(merge(chunks, inParallel));
}

std::optional<SimpleObj> parseSimpleObj(std::string_view text, unsigned threads) {
  // Pieces of kParallelParseBytes or more, one per thread at most.
  const std::size_t pieces =
      std::clamp<std::size_t>(text.size() / kParallelParseBytes, 1, std::max(threads, 1u));
  return parseSimpleObjInChunks(text, pieces, threads);
}

bool objFastPathDisabled() {
  const char* choice = std::getenv("GLINT_OBJ_READER");
  return choice != nullptr && std::strcmp(choice, "assimp") == 0;
}

}  // namespace glint
