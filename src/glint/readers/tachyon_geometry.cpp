#include "glint/readers/tachyon_geometry.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include <fmt/format.h>

namespace glint::tachyon {

namespace {
// Most elements reserved up front for a count read from the file (a million: 88 MB of vertices).
constexpr std::size_t kReserveLimit = std::size_t{1} << 20;
}  // namespace

void Geometry::shape(const Token& t, const std::string& word) {
  std::vector<std::pair<std::string_view, Triple>> vectors;
  std::vector<std::pair<std::string_view, Number>> numbers;
  std::string_view type;
  if (word == "SPHERE") {
    type = "sphere";
    in_.keyword(t, "CENTER");
    vectors.emplace_back("center", in_.point(t, "center"));
    in_.keyword(t, "RAD");
    numbers.emplace_back("radius", in_.number(t, "radius"));
  } else if (word == "FCYLINDER") {
    type = "cone";
    in_.keyword(t, "BASE");
    vectors.emplace_back("base", in_.point(t, "base"));
    in_.keyword(t, "APEX");
    vectors.emplace_back("apex", in_.point(t, "apex"));
    in_.keyword(t, "RAD");
    const Number radius = in_.number(t, "radius");
    numbers.emplace_back("base_radius", radius);
    numbers.emplace_back("apex_radius", radius);
  } else if (word == "CYLINDER") {
    type = "tube";
    in_.keyword(t, "CENTER");
    vectors.emplace_back("origin", in_.point(t, "center"));
    in_.keyword(t, "AXIS");
    vectors.emplace_back("axis", in_.point(t, "axis"));
    in_.keyword(t, "RAD");
    numbers.emplace_back("radius", in_.number(t, "radius"));
  } else if (word == "RING") {
    type = "disk";
    in_.keyword(t, "CENTER");
    vectors.emplace_back("center", in_.point(t, "center"));
    in_.keyword(t, "NORMAL");
    vectors.emplace_back("normal", in_.point(t, "normal"));
    in_.keyword(t, "INNER");
    const Number inner = in_.number(t, "inner radius");
    in_.keyword(t, "OUTER");
    numbers.emplace_back("radius", in_.number(t, "outer radius"));
    if (inner.value != 0) numbers.emplace_back("inner_radius", inner);
  } else if (word == "PLANE") {
    type = "plane";
    in_.keyword(t, "CENTER");
    vectors.emplace_back("point", in_.point(t, "center"));
    in_.keyword(t, "NORMAL");
    vectors.emplace_back("normal", in_.point(t, "normal"));
  } else {  // BOX
    type = "box";
    in_.keyword(t, "MIN");
    Triple lo = in_.point(t, "min");
    in_.keyword(t, "MAX");
    Triple hi = in_.point(t, "max");
    // Mirrored in x, the box's x extent runs from −max.x to −min.x.
    std::swap(lo.n[0], hi.n[0]);
    vectors.emplace_back("min", lo);
    vectors.emplace_back("max", hi);
  }
  const std::string material = textures_.reference(t, false, transVmd_);
  const ValueId map = out_.nextId();
  out_.openMap(t.at);
  const ValueId typeValue = out_.entry("type", type, t.at);
  for (const auto& [key, v] : vectors) in_.emit(key, v);
  for (const auto& [key, n] : numbers) in_.emit(key, n);
  out_.entry("material", material, t.at);
  out_.close();
  out_.addEntity(EntityKind::ObjectEntity, map, typeValue);
}

std::array<ValueId, 3> Geometry::addTriple(const Triple& t) {
  std::array<ValueId, 3> ids;
  for (int k = 0; k < 3; ++k) ids[k] = out_.scalar(t.n[k].text, t.n[k].at);
  return ids;
}

// Adds a triangle, its winding turned to agree with its vertex normals (Tachyon's triangles are
// double-sided; glint uses a smooth normal only on the side of the geometric normal).
void Geometry::addTriangle(const std::string& material, VertexData a, VertexData b, VertexData c,
                           const TextPosition& at) {
  if (a.ids.normal[0] != kNoValue) {
    const Vec3 n = cross(b.position - a.position, c.position - a.position);
    if (dot(n, a.normal + b.normal + c.normal) < 0) std::swap(b, c);
  }
  meshes_.add(out_.tree(), material, a.ids, b.ids, c.ids, at);
}

void Geometry::triangle(const Token& t, const std::string& word) {
  const bool normals = word != "TRI";
  const bool colors = word == "VCSTRI";
  std::array<VertexData, 3> v;
  for (int i = 0; i < 3; ++i) {
    in_.keyword(t, fmt::format("V{}", i));
    const Triple p = in_.point(t, "vertex");
    v[i].ids.position = addTriple(p);
    v[i].position = p.vector();
  }
  if (normals) {
    for (int i = 0; i < 3; ++i) {
      in_.keyword(t, fmt::format("N{}", i));
      const Triple n = in_.point(t, "normal");
      v[i].ids.normal = addTriple(n);
      v[i].normal = n.vector();
    }
  }
  if (colors) {
    for (int i = 0; i < 3; ++i) {
      in_.keyword(t, fmt::format("C{}", i));
      v[i].ids.color = addTriple(in_.color(t, "vertex color"));
    }
  }
  const std::string material = colors ? textures_.vertexColored(textures_.body(t, true), transVmd_)
                                      : textures_.reference(t, false, transVmd_);
  addTriangle(material, v[0], v[1], v[2], t.at);
}

void Geometry::vertexArray(const Token& t) {
  in_.keyword(t, "NUMVERTS");
  const Number count = in_.number(t, "vertex count");
  if (!(count.value >= 0 && count.value == std::floor(count.value) && count.value < 1e9)) {
    out_.error(
        count.at,
        fmt::format("VERTEXARRAY: NUMVERTS must be a whole number below 1e9, got {}", count.text));
    throw SyntaxError{};
  }
  const auto n = static_cast<std::size_t>(count.value);
  // The count is the file's claim: the vertices are appended as they are read, so a 40-byte file
  // claiming 900 million vertices ends at its last number instead of allocating gigabytes first.
  std::vector<VertexData> vertices;
  vertices.reserve(std::min<std::size_t>(n, kReserveLimit));
  in_.keyword(t, "COORDS");
  for (std::size_t i = 0; i < n; ++i) {
    const Triple p = in_.point(t, "vertex");
    VertexData& v = vertices.emplace_back();
    v.ids.position = addTriple(p);
    v.position = p.vector();
  }
  in_.keyword(t, "NORMALS");
  for (VertexData& v : vertices) {
    const Triple p = in_.point(t, "normal");
    v.ids.normal = addTriple(p);
    v.normal = p.vector();
  }
  bool colored = false;
  std::optional<Texture> texture;
  for (;;) {
    const Token block = in_.need(t, "COLORS, TEXTURE, TRISTRIP, TRIMESH or END_VERTEXARRAY");
    const std::string b = upper(block.text);
    if (b == "END_VERTEXARRAY") return;
    if (b == "COLORS") {
      for (VertexData& v : vertices) v.ids.color = addTriple(in_.color(t, "vertex color"));
      colored = true;
    } else if (b == "TEXTURE") {
      texture = textures_.body(t, false);
    } else if (b == "TRIMESH" || b == "TRISTRIP") {
      const std::string material =
          colored
              ? textures_.vertexColored(texture ? *texture : textures_.defaultTexture(), transVmd_)
          : texture ? textures_.material(*texture, transVmd_)
                    : textures_.material(textures_.defaultTexture(), transVmd_);
      const bool strip = b == "TRISTRIP";
      const Number m = in_.number(t, strip ? "strip length" : "triangle count");
      if (!(m.value >= 0 && m.value == std::floor(m.value) && m.value < 1e9)) {
        out_.error(
            m.at, fmt::format("{}: expected a whole number below 1e9, got {}", block.text, m.text));
        throw SyntaxError{};
      }
      const auto items = static_cast<std::size_t>(m.value) * (strip ? 1 : 3);
      std::vector<std::size_t> index;  // appended as read, like the vertices above
      index.reserve(std::min<std::size_t>(items, kReserveLimit));
      for (std::size_t i = 0; i < items; ++i) {
        const Number k = in_.number(t, "vertex index");
        if (!(k.value >= 0 && k.value < static_cast<double>(n) && k.value == std::floor(k.value))) {
          out_.error(k.at, fmt::format("{}: vertex index {} is not one of the {} vertices "
                                       "(0 to {})",
                                       block.text, k.text, n, n == 0 ? 0 : n - 1));
          throw SyntaxError{};
        }
        index.push_back(static_cast<std::size_t>(k.value));
      }
      if (strip) {
        // Tachyon's winding: v0 v1 v2, then v2 v1 v3, v2 v3 v4, …
        for (std::size_t s = 0; s + 2 < items; ++s) {
          const bool odd = (s & 1) != 0;
          addTriangle(material, vertices[index[s + (odd ? 1 : 0)]],
                      vertices[index[s + (odd ? 0 : 1)]], vertices[index[s + 2]], block.at);
        }
      } else {
        for (std::size_t s = 0; s + 2 < items; s += 3) {
          addTriangle(material, vertices[index[s]], vertices[index[s + 1]], vertices[index[s + 2]],
                      block.at);
        }
      }
    } else {
      out_.error(block.at, fmt::format("VERTEXARRAY: expected COLORS, TEXTURE, TRISTRIP, "
                                       "TRIMESH or END_VERTEXARRAY, got {}",
                                       quoteForMessage(block.text)));
      throw SyntaxError{};
    }
  }
}

}  // namespace glint::tachyon
