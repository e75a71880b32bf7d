// What the readers of other renderers' scene languages (NFF, Tachyon .dat) share: their text as
// whitespace-separated tokens with the place of each, numbers read as those languages write them,
// and the entities they emit built as ValueTree mappings whose values keep their tokens' places.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "glint/readers/diagnostics.h"
#include "glint/readers/scene_description.h"
#include "glint/readers/value_tree.h"
#include "glint/readers/yaml_scene_reader.h"

namespace glint {

struct Token {
  std::string_view text;
  TextPosition at;
  bool lineStart = false;  // the first token of its line
};

// Splits a text into tokens separated by whitespace. A token starting with '#' starts a comment
// that runs to the end of its line (NFF: "as soon as a # is detected"; Tachyon writes "# text").
// Places are 1-based lines and columns counted in characters (UTF-8), as the YAML reader counts.
class Tokenizer {
 public:
  // A UTF-8 byte-order mark at the start is skipped (an editor's, invisible: columns from 1).
  explicit Tokenizer(std::string_view text)
      : text_(text), pos_(text.starts_with("\xEF\xBB\xBF") ? 3 : 0) {}
  // The next token, or nullopt at the end.
  std::optional<Token> next();
  std::optional<Token> peek();
  // Where the text ends (for "the file ends before ..." messages).
  TextPosition end();
  // Bytes consumed so far (for cancel polling).
  std::size_t consumed() const { return pos_; }

 private:
  void skipSpaceAndComments();
  void advance();  // one byte, keeping line, column and character offset
  std::string_view text_;
  std::size_t pos_ = 0;
  std::uint32_t line_ = 1;
  std::uint32_t column_ = 1;
  std::uint32_t offset_ = 0;  // characters
  bool atLineStart_ = true;
  std::optional<Token> peeked_;
};

// A number as NFF and Tachyon write it (C's %g and %f: 1, -0.5, 1e-05, .5, 5.), parsed as the
// scene factories parse numbers; nullopt for anything else, and for NaN and infinities.
std::optional<double> parseNumber(std::string_view text);

// A number std::from_chars found out of range (`text` as it took it), rounded as C's strtod in
// the "C" locale rounds it (whatever the program's locale): 0 or a subnormal for an underflow,
// an infinity for an overflow.
double outOfRangeNumber(std::string_view text);

// Shortest text that reads back as exactly `value` (for values a reader computes, e.g. kd = Kd ·
// colour); "-0" is written "0".
std::string numberText(double value);

// The scene file a text reader fills: its values, the entities, and the diagnostics; numbers and
// keys are added to file 0's ValueTree with the places of their tokens.
class SceneEmitter {
 public:
  SceneEmitter(SceneDescription& scene, Diagnostics& sink) : scene_(scene), sink_(sink) {}
  ValueTree& tree() { return scene_.files[0]->values; }
  const std::string& fileName() const { return scene_.files[0]->name; }
  Diagnostics& sink() { return sink_; }
  void error(const TextPosition& at, std::string message);
  void warning(const TextPosition& at, std::string message);

  // Mappings: open, then key(...) followed by one value (scalar, list, mapping), then close.
  void openMap(const TextPosition& at) { tree().open(ValueKind::Map, at); }
  void openList(const TextPosition& at) { tree().open(ValueKind::List, at); }
  void close() { tree().close(); }
  void key(std::string_view name, const TextPosition& at) { tree().addScalar(name, at); }
  ValueId scalar(std::string_view text, const TextPosition& at) {
    return tree().addScalar(text, at);
  }
  ValueId scalar(const Token& t) { return tree().addScalar(t.text, t.at); }
  // key: scalar, in one call.
  ValueId entry(std::string_view name, std::string_view text, const TextPosition& at) {
    key(name, at);
    return scalar(text, at);
  }
  ValueId entry(std::string_view name, const Token& value) {
    key(name, value.at);
    return scalar(value);
  }
  // key: [a, b, c] of three tokens (a point, vector or colour as written).
  void triple(std::string_view name, const Token* three);
  // key: [x, y, z] of computed numbers, placed at `at`.
  void computedTriple(std::string_view name, const double* three, const TextPosition& at);

  // Adds an entity whose value is the mapping (or scalar) `value` just closed; for objects and
  // lights `type` is the value of its `type` key, for materials `name` its name.
  void addEntity(EntityKind kind, ValueId value, ValueId type = kNoValue, ValueId name = kNoValue);
  // The id the next value added will get (a mapping opened next).
  ValueId nextId() const { return static_cast<ValueId>(scene_.files[0]->values.valueCount()); }

 private:
  SceneDescription& scene_;
  Diagnostics& sink_;
  std::uint32_t objects_ = 0, lights_ = 0, materials_ = 0;
};

// Reads a whole scene file of another format into memory for a text reader: a regular file no
// larger than kMaxSceneFileBytes, else SceneError naming only the file (as readSceneFile).
// Sets `file`'s bytes.
std::string readWholeSceneFile(const std::filesystem::path& path, const std::string& name,
                               SourceFile& file);

// A scene with its one file, as readers begin.
SceneDescription sceneWithFile(const std::string& name, const std::filesystem::path& base);

// A text reader's statements over a scene that holds its one file.
using StatementReader = ParseResult (*)(std::string_view text, SceneDescription scene,
                                        const std::atomic<bool>* cancel);
// The two entry points every text reader has: `text` in memory as the file `file` (relative paths
// from `baseDirectory`), or the file at `path` shown as `name` (relative paths from its folder).
ParseResult parseSceneText(std::string_view text, const std::string& file,
                           const std::filesystem::path& baseDirectory,
                           const std::atomic<bool>* cancel, StatementReader read);
ParseResult readSceneTextFile(const std::filesystem::path& path, const std::string& name,
                              const std::atomic<bool>* cancel, StatementReader read);

// The closest of `names` to `word` for "did you mean" (case-insensitive), or "".
std::string nearestName(std::string_view word, const std::vector<std::string_view>& names);

}  // namespace glint
