#include "glint/readers/text_statements.h"

#include <locale.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <system_error>
#include <utility>

#include <fmt/format.h>
#include <unistd.h>

#include "glint/readers/source_file.h"
#include "glint/readers/spelling.h"

namespace glint {

// --- Tokenizer ---------------------------------------------------------------------------------

void Tokenizer::advance() {
  const auto c = static_cast<unsigned char>(text_[pos_++]);
  // "\n", "\r\n" and a lone "\r" (classic Mac OS files) each end a line.
  if (c == '\n' || (c == '\r' && (pos_ == text_.size() || text_[pos_] != '\n'))) {
    ++line_;
    column_ = 1;
    ++offset_;
    atLineStart_ = true;
    return;
  }
  // A UTF-8 continuation byte belongs to the character before it.
  if ((c & 0xC0) != 0x80) {
    ++column_;
    ++offset_;
  }
}

void Tokenizer::skipSpaceAndComments() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '#') {
      while (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '\r') advance();
    } else if (std::isspace(static_cast<unsigned char>(c)) || c == '\0') {
      advance();
    } else {
      return;
    }
  }
}

std::optional<Token> Tokenizer::next() {
  if (peeked_) {
    std::optional<Token> t = std::move(peeked_);
    peeked_.reset();
    return t;
  }
  skipSpaceAndComments();
  if (pos_ >= text_.size()) return std::nullopt;
  Token token;
  token.at = TextPosition{offset_, line_, column_};
  token.lineStart = atLineStart_;
  atLineStart_ = false;
  const std::size_t start = pos_;
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (std::isspace(static_cast<unsigned char>(c)) || c == '\0') break;
    advance();
  }
  token.text = text_.substr(start, pos_ - start);
  return token;
}

std::optional<Token> Tokenizer::peek() {
  if (!peeked_) peeked_ = next();
  return peeked_;
}

TextPosition Tokenizer::end() {
  if (peeked_) return peeked_->at;
  skipSpaceAndComments();
  return TextPosition{offset_, line_, column_};
}

// --- numbers -----------------------------------------------------------------------------------

std::optional<double> parseNumber(std::string_view text) {
  if (text.size() > 1 && text[0] == '+' && text[1] != '-') text.remove_prefix(1);
  if (text.empty()) return std::nullopt;
  // from_chars would take "inf" and "nan"; neither is a number here.
  const char first = text[0] == '-' && text.size() > 1 ? text[1] : text[0];
  if (!(std::isdigit(static_cast<unsigned char>(first)) || first == '.')) return std::nullopt;
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ptr != end) return std::nullopt;
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves the value unset; an underflow ("1e-400") is 0 or a subnormal, as in YAML
    // scenes (parameter_dictionary), an overflow infinite and refused.
    value = outOfRangeNumber(text);
  } else if (ec != std::errc()) {
    return std::nullopt;
  }
  if (!std::isfinite(value)) return std::nullopt;
  return value;
}

double outOfRangeNumber(std::string_view text) {
  // strtod follows LC_NUMERIC: a library user's "de_DE" locale would stop "1.5e-400" at the '.'.
  static const locale_t cLocale = ::newlocale(LC_ALL_MASK, "C", nullptr);
  const std::string copy(text);
  return cLocale != nullptr ? ::strtod_l(copy.c_str(), nullptr, cLocale)
                            : std::strtod(copy.c_str(), nullptr);
}

std::string numberText(double value) {
  if (value == 0) return "0";
  return fmt::format("{}", value);
}

// --- SceneEmitter ------------------------------------------------------------------------------

namespace {

SourceLocation locationOf(const std::string& file, const TextPosition& at) {
  return at.line == 0
             ? SourceLocation{file, 1, 1}
             : SourceLocation{file, static_cast<int>(at.line), static_cast<int>(at.column)};
}

}  // namespace

void SceneEmitter::error(const TextPosition& at, std::string message) {
  sink_.error(locationOf(fileName(), at), std::move(message));
}

void SceneEmitter::warning(const TextPosition& at, std::string message) {
  sink_.warning(locationOf(fileName(), at), std::move(message));
}

void SceneEmitter::triple(std::string_view name, const Token* three) {
  key(name, three[0].at);
  openList(three[0].at);
  for (int i = 0; i < 3; ++i) scalar(three[i]);
  close();
}

void SceneEmitter::computedTriple(std::string_view name, const double* three,
                                  const TextPosition& at) {
  key(name, at);
  openList(at);
  for (int i = 0; i < 3; ++i) scalar(numberText(three[i]), at);
  close();
}

void SceneEmitter::addEntity(EntityKind kind, ValueId value, ValueId type, ValueId name) {
  Entity e;
  e.kind = kind;
  e.file = 0;
  e.value = value;
  e.place = value;
  e.type = type;
  e.name = name;
  switch (kind) {
    case EntityKind::ObjectEntity:
      e.index = objects_++;
      break;
    case EntityKind::LightEntity:
      e.index = lights_++;
      break;
    case EntityKind::MaterialEntity:
      e.index = materials_++;
      break;
    default:
      break;
  }
  scene_.entities.push_back(e);
}

// --- files -------------------------------------------------------------------------------------

std::string readWholeSceneFile(const std::filesystem::path& path, const std::string& name,
                               SourceFile& file) {
  const ReadableFile opened = openRegularFile(path, name);
  const auto refuse = [&name](const std::string& why) {
    return SceneError({{Diagnostic::Severity::Error, {name, 0, 0}, why}});
  };
  if (opened.size > kMaxSceneFileBytes) {
    throw refuse("the file is larger than 256 MiB; a scene file holds a scene description");
  }
  std::string text;
  text.resize(static_cast<std::size_t>(opened.size));
  std::size_t got = 0;
  for (;;) {
    if (got == text.size()) text.resize(text.size() + 65536);
    const ssize_t n = ::read(opened.fd, text.data() + got, text.size() - got);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw refuse("cannot read file: " + std::generic_category().message(errno));
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
    if (got > kMaxSceneFileBytes) {
      throw refuse("the file is larger than 256 MiB; a scene file holds a scene description");
    }
  }
  text.resize(got);
  file.bytes = got;
  return text;
}

SceneDescription sceneWithFile(const std::string& name, const std::filesystem::path& base) {
  SceneDescription scene;
  scene.addFile(name, base);
  return scene;
}

// A NUL byte is no text: refused at its place (it would otherwise read as a blank, joining or
// splitting the words around it without a word said). The error, as the readers give theirs: in
// the result's diagnostics, with a description marked incomplete.
std::optional<ParseResult> refusedForNulByte(std::string_view text, SceneDescription& scene,
                                             const std::string& file) {
  const std::size_t at = text.find('\0');
  if (at == std::string_view::npos) return std::nullopt;
  int line = 1;
  int column = 1;
  for (std::size_t i = text.starts_with("\xEF\xBB\xBF") ? 3 : 0; i < at; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n' || (c == '\r' && (i + 1 == text.size() || text[i + 1] != '\n'))) {
      ++line;
      column = 1;
    } else if ((c & 0xC0) != 0x80) {
      ++column;
    }
  }
  ParseResult result;
  scene.complete = false;
  result.description = std::move(scene);
  result.diagnostics.push_back({Diagnostic::Severity::Error,
                                {file, line, column},
                                "the file holds a NUL byte here; a scene file is text"});
  return result;
}

ParseResult parseSceneText(std::string_view text, const std::string& file,
                           const std::filesystem::path& baseDirectory,
                           const std::atomic<bool>* cancel, StatementReader read) {
  SceneDescription scene = sceneWithFile(file, baseDirectory);
  if (std::optional<ParseResult> refused = refusedForNulByte(text, scene, file)) {
    return std::move(*refused);
  }
  scene.files[0]->bytes = text.size();
  scene.files[0]->values.reserveForText(text.size());  // as the YAML reader: no regrowth
  return read(text, std::move(scene), cancel);
}

ParseResult readSceneTextFile(const std::filesystem::path& path, const std::string& name,
                              const std::atomic<bool>* cancel, StatementReader read) {
  std::filesystem::path base = path.parent_path();
  if (base.empty()) base = ".";
  SceneDescription scene = sceneWithFile(name, base);
  const std::string text = readWholeSceneFile(path, name, *scene.files[0]);
  if (std::optional<ParseResult> refused = refusedForNulByte(text, scene, name)) {
    return std::move(*refused);
  }
  scene.files[0]->values.reserveForText(text.size());  // as the YAML reader: no regrowth
  return read(text, std::move(scene), cancel);
}

std::string nearestName(std::string_view word, const std::vector<std::string_view>& names) {
  return closestName(word, names);
}

}  // namespace glint
