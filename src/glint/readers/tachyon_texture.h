// The Tachyon reader's token input (case-insensitive keywords, numbers, points mirrored in x) and
// its textures: TEXDEF, TEXALIAS and inline TEXTURE bodies as glint materials (tachyon_reader.h
// gives the mapping). Internal to the Tachyon reader.
#pragma once

#include <array>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "glint/core/vec.h"
#include "glint/readers/text_statements.h"

namespace glint::tachyon {

// A statement could not be read; the reader skips to the next one.
struct SyntaxError {};

// A number as written (or as mirrored: "-1.5" for "1.5"), its place and value.
struct Number {
  std::string text;
  TextPosition at;
  double value = 0;
};

struct Triple {
  std::array<Number, 3> n;
  Vec3 vector() const { return {n[0].value, n[1].value, n[2].value}; }
};

std::string upper(std::string_view text);

class Input {
 public:
  Input(std::string_view text, SceneEmitter& out) : tokens_(text), out_(out) {}
  Tokenizer& tokens() { return tokens_; }
  // The next token of `statement`, which must exist.
  Token need(const Token& statement, std::string_view what);
  // The next token must be `word` (any case).
  void keyword(const Token& statement, std::string_view word);
  void expectWord(const Token& statement, const Token& got, std::string_view word);
  // `got` must be `first` or `second` (any case); returns it in upper case.
  std::string expectEither(const Token& statement, const Token& got, std::string_view first,
                           std::string_view second);
  Number number(const Token& statement, std::string_view what);
  // x, y, z of a point, vector or normal, mirrored in x (tachyon_reader.h).
  Triple point(const Token& statement, std::string_view what);
  Triple color(const Token& statement, std::string_view what);
  // key: value and key: [a, b, c] into the open mapping.
  void emit(std::string_view key, const Number& n);
  void emit(std::string_view key, const Triple& t);

 private:
  Tokenizer tokens_;
  SceneEmitter& out_;
};

// Tachyon's texture functions that glint renders: TEXFUNC 0 (the plain colour), 1 (3D checker,
// exactly: glint's checker with Tachyon's colours, cells of 1/3 and its centre), 3 (marble) and
// 4 (wood), the last two with glint's own marble and wood patterns (a warning says so).
enum class TexFunc { Constant = 0, Checker = 1, Marble = 3, Wood = 4 };

// A texture body: AMBIENT DIFFUSE SPECULAR OPACITY [PHONG PLASTIC|METAL p PHONG_SIZE e] COLOR r g b
// TEXFUNC n [CENTER c ROTATE r SCALE s] (or VCST, for vertex-coloured triangles, whose colour is
// 1).
struct Texture {
  Number ambient, diffuse, specular, opacity, phong, phongSize;
  bool metal = false;
  std::array<Number, 3> color;
  TexFunc function = TexFunc::Constant;
  Triple center;  // mirrored in x, as every point
  Triple scale;
};

class Textures {
 public:
  Textures(Input& in, SceneEmitter& out) : in_(in), out_(out) {}
  // Reads a texture body after TEXTURE or TEXDEF name (`vertexColors`: VCST instead of COLOR).
  Texture body(const Token& statement, bool vertexColors);
  // TEXDEF: the material `name` (a later TEXDEF of the same name is ignored with a warning, as
  // Tachyon keeps the first).
  void define(const std::string& name, const Texture& texture, const TextPosition& at,
              bool transVmd);
  // TEXALIAS: `alias` (written at `at`) names what `original` names (a name already defined is
  // ignored with a warning, as for TEXDEF).
  void alias(const std::string& alias, const TextPosition& at, const Token& original);
  // An object's texture: TEXTURE body or a name; the name of its material.
  std::string reference(const Token& statement, bool vertexColors, bool transVmd);
  // The material of a texture (shared by equal textures).
  std::string material(const Texture& texture, bool transVmd);
  // The same texture with colour 1, for triangles whose vertex colours tint it.
  std::string vertexColored(Texture texture, bool transVmd);
  // Tachyon's default texture (AMBIENT 0.1 DIFFUSE 0.9, white).
  Texture defaultTexture() const;
  // Whether a material was emitted yet.
  bool emittedAny() const { return !materialNames_.empty(); }
  // SHADER_MODE's AMBIENT_OCCLUSION (tachyon_reader.cpp): every material after it has ka = its
  // DIFFUSE·COLOR (lit by the occluded ambient light) and emission = its AMBIENT·COLOR.
  void setAmbientOcclusion(bool on) { ambientOcclusion_ = on; }

 private:
  std::string emitMaterial(const Texture& texture, bool transVmd, const std::string& name);
  // Whether `name` was defined before (by TEXDEF or TEXALIAS): then a warning at `at`; else it is
  // recorded as defined there.
  bool alreadyDefined(std::string_view statement, const std::string& name, const TextPosition& at);
  // key: a glint texture mapping for the texture's TEXFUNC, its colours times `factor`.
  void emitPattern(std::string_view key, const Texture& t, double factor, const TextPosition& at);
  Input& in_;
  SceneEmitter& out_;
  std::map<std::string, std::string> named_;       // TEXDEF and TEXALIAS names → material names
  std::map<std::string, std::string> byValues_;    // a material's values → its name
  std::map<std::string, Texture> definitions_;     // TEXDEF name → its texture (vertex colours)
  std::map<std::string, TextPosition> definedAt_;  // TEXDEF/TEXALIAS name → where it was defined
  void requireRange(const Number& n, double lo, double hi, std::string_view what);

  std::set<std::string> materialNames_;  // every material emitted
  bool ambientOcclusion_ = false;
  // Per TEXDEF name that a material has already (one named for an inline texture: texture1...),
  // the suffix to try next (name_2, name_3...): names are never freed, so every smaller suffix is
  // taken and the next clash costs no search from 2.
  std::map<std::string, int> nextSuffix_;
  std::size_t generated_ = 0;
};

}  // namespace glint::tachyon
