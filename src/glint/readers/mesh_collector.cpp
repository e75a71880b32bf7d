#include "glint/readers/mesh_collector.h"

#include <fmt/format.h>

#include <string>
#include <utility>

namespace glint {

std::uint32_t MeshCollector::vertexIndex(const ValueTree& tree, Group& g,
                                         const CollectedVertex& v) {
  // Vertices written with the same text are one vertex (an exact test: the same text is the same
  // number).
  std::string key;
  for (const auto* part : {&v.position, &v.normal, &v.color}) {
    if ((*part)[0] == kNoValue) continue;
    for (const ValueId id : *part) {
      key += tree.scalar(id);
      key += ' ';
    }
    key += '|';
  }
  const auto [it, inserted] = g.shared.try_emplace(std::move(key), 0);
  if (inserted) {
    it->second = static_cast<std::uint32_t>(g.vertices.size());
    g.vertices.push_back(v);
  }
  return it->second;
}

void MeshCollector::add(ValueTree& tree, const std::string& material, const CollectedVertex& a,
                        const CollectedVertex& b, const CollectedVertex& c,
                        const TextPosition& at) {
  const bool normals = a.normal[0] != kNoValue;
  const bool colors = a.color[0] != kNoValue;
  const std::string key = material + (normals ? "\n1" : "\n0") + (colors ? "1" : "0");
  auto [it, inserted] = groupOf_.try_emplace(key, groups_.size());
  if (inserted) {
    Group g;
    g.material = material;
    g.normals = normals;
    g.colors = colors;
    g.first = at;
    groups_.push_back(std::move(g));
  }
  Group& g = groups_[it->second];
  tree.noteLine(at);
  for (const CollectedVertex* v : {&a, &b, &c}) g.indices.push_back(vertexIndex(tree, g, *v));
  g.triangleAt.push_back(at);
  ++triangles_;
}

void MeshCollector::emit(SceneEmitter& out) {
  ValueTree& tree = out.tree();
  for (Group& g : groups_) {
    // Vertices written alike are one vertex: triangles on fewer than three distinct points have
    // no area anywhere. Said here, in the file's terms, rather than as a mesh of too few
    // positions.
    if (g.vertices.size() < 3) {
      out.warning(g.first, fmt::format("{} degenerate triangle{} (no area: {} distinct vertices) "
                                       "left out",
                                       g.triangleAt.size(), g.triangleAt.size() == 1 ? "" : "s",
                                       g.vertices.size()));
      g = Group{};
      continue;
    }
    const ValueId map = out.nextId();
    out.openMap(g.first);
    const ValueId type = out.entry("type", "mesh", g.first);
    const auto arrays = [&](std::string_view name, auto member) {
      out.key(name, g.first);
      out.openList(g.first);
      for (const CollectedVertex& v : g.vertices) {
        const std::array<ValueId, 3>& ids = v.*member;
        out.openList(tree.position(ids[0]));
        for (const ValueId id : ids) tree.attach(id);
        out.close();
      }
      out.close();
    };
    arrays("positions", &CollectedVertex::position);
    if (g.normals) arrays("normals", &CollectedVertex::normal);
    if (g.colors) arrays("colors", &CollectedVertex::color);
    out.key("indices", g.first);
    out.openList(g.first);
    for (std::size_t t = 0; t < g.triangleAt.size(); ++t) {
      out.openList(g.triangleAt[t]);
      for (int k = 0; k < 3; ++k) {
        out.scalar(std::to_string(g.indices[3 * t + static_cast<std::size_t>(k)]), g.triangleAt[t]);
      }
      out.close();
    }
    out.close();
    out.entry("smooth", g.normals ? "true" : "false", g.first);
    if (!g.material.empty()) out.entry("material", g.material, g.first);
    out.close();
    out.addEntity(EntityKind::ObjectEntity, map, type);
    g = Group{};  // its memory is no longer needed
  }
  groups_.clear();
  groupOf_.clear();
}

}  // namespace glint
