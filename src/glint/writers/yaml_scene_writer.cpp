#include "glint/writers/yaml_scene_writer.h"

#include <cctype>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "glint/readers/text_statements.h"
#include "glint/writers/ply_writer.h"

namespace glint {
namespace {

// Lines longer than this are written in block style.
constexpr std::size_t kFlowWidth = 96;

bool plainWord(std::string_view t) {
  if (t.empty()) return false;
  if (t == "null" || t == "Null" || t == "NULL" || t == "~") return false;
  if (parseNumber(t)) return true;
  const auto first = static_cast<unsigned char>(t[0]);
  if (!(std::isalpha(first) || first == '_')) return false;
  for (const char c : t) {
    const auto u = static_cast<unsigned char>(c);
    if (!(std::isalnum(u) || c == '_' || c == '-' || c == '.' || c == '/')) return false;
  }
  return true;
}

class Writer {
 public:
  Writer(const SceneDescription& scene, const std::filesystem::path& output,
         const SceneWriteOptions& options, WrittenScene& out)
      : scene_(scene), output_(output), options_(options), out_(out) {}

  void write() {
    std::string& y = out_.yaml;
    if (!options_.sourceName.empty()) {
      y += fmt::format("# glint scene converted by `glint convert` from {}\n", options_.sourceName);
    }
    const SourceFile& main = *scene_.files.at(0);
    if (scene_.name != kNoValue) {
      y += "name: " + yamlScalar(main.values.scalar(scene_.name)) + "\n";
    }
    for (const auto& [kind, key] : {std::pair{EntityKind::CameraEntity, "camera"},
                                    std::pair{EntityKind::ImageEntity, "image"},
                                    std::pair{EntityKind::RenderEntity, "render"},
                                    std::pair{EntityKind::BackgroundEntity, "background"},
                                    std::pair{EntityKind::AmbientEntity, "ambient"},
                                    std::pair{EntityKind::FogEntity, "fog"}}) {
      if (const Entity* e = scene_.first(kind)) {
        rebaseFiles(*e, e->value);
        y += std::string(key) + ":" + flowOrBlock(*e, e->value, 1) + "\n";
      }
    }
    // Named textures, materials and groups, those of included files too (the output includes
    // nothing).
    named("textures", EntityKind::TextureEntity);
    named("materials", EntityKind::MaterialEntity);
    named("groups", EntityKind::GroupEntity);
    list("objects", EntityKind::ObjectEntity);
    list("lights", EntityKind::LightEntity);
  }

 private:
  const ValueTree& tree(const Entity& e) const { return scene_.fileOf(e).values; }

  void named(std::string_view key, EntityKind kind) {
    if (scene_.count(kind) == 0) return;
    out_.yaml += std::string(key) + ":\n";
    for (const Entity& e : scene_.entities) {
      if (e.kind != kind) continue;
      rebaseFiles(e, e.value);
      out_.yaml +=
          "  " + yamlScalar(scene_.text(e, e.name)) + ":" + flowOrBlock(e, e.value, 2) + "\n";
    }
  }

  void list(std::string_view key, EntityKind kind) {
    if (scene_.count(kind) == 0) return;
    out_.yaml += std::string(key) + ":\n";
    for (const Entity& e : scene_.entities) {
      if (e.kind != kind) continue;
      out_.yaml += "  - ";
      if (kind == EntityKind::ObjectEntity && asPly(e)) continue;
      rebaseFiles(e, e.value);
      const std::string flow = this->flow(e, e.value);
      out_.yaml += flow.size() + 4 <= kFlowWidth ? flow : block(e, e.value, 4, true);
      out_.yaml += "\n";
    }
  }

  // A value in one line: scalars, [a, b], {k: v}.
  std::string flow(const Entity& e, ValueId v) const {
    const ValueTree& t = tree(e);
    if (const auto it = replaced_.find(v); it != replaced_.end()) return yamlScalar(it->second);
    if (t.isScalar(v)) return yamlScalar(t.scalar(v));
    if (t.isList(v)) {
      std::string s = "[";
      for (std::size_t i = 0; i < t.size(v); ++i) {
        if (i > 0) s += ", ";
        s += flow(e, t.item(v, i));
      }
      return s + "]";
    }
    if (t.isMap(v)) {
      std::string s = "{";
      for (std::size_t i = 0; i < t.size(v); ++i) {
        if (i > 0) s += ", ";
        s += flow(e, t.key(v, i)) + ": " + flow(e, t.value(v, i));
      }
      return s + "}";
    }
    return "null";
  }

  // " value" on the key's line, or the block below it.
  std::string flowOrBlock(const Entity& e, ValueId v, int depth) const {
    const std::string f = flow(e, v);
    if (f.size() + static_cast<std::size_t>(2 * depth) + 12 <= kFlowWidth || tree(e).isScalar(v)) {
      return " " + f;
    }
    return "\n" + block(e, v, 2 * depth, false);
  }

  // A mapping or list in block style, `indent` spaces in; `firstInline`: the first line continues
  // a "- " already written.
  std::string block(const Entity& e, ValueId v, int indent, bool firstInline) const {
    const ValueTree& t = tree(e);
    const std::string pad(static_cast<std::size_t>(indent), ' ');
    std::string s;
    const auto line = [&](std::size_t i, const std::string& text) {
      s += (i == 0 && firstInline) ? text : pad + text;
      s += '\n';
    };
    if (t.isMap(v)) {
      for (std::size_t i = 0; i < t.size(v); ++i) {
        const ValueId value = t.value(v, i);
        const std::string key = flow(e, t.key(v, i)) + ":";
        const std::string f = flow(e, value);
        if (t.isScalar(value) ||
            f.size() + key.size() + 1 + static_cast<std::size_t>(indent) <= kFlowWidth) {
          line(i, key + " " + f);
        } else {
          line(i, key);
          s += block(e, value, indent + 2, false);
          s += '\n';
        }
      }
    } else if (t.isList(v)) {
      for (std::size_t i = 0; i < t.size(v); ++i) line(i, "- " + flow(e, t.item(v, i)));
    } else {
      line(0, flow(e, v));
    }
    if (!s.empty()) s.pop_back();
    return s;
  }

  // Every `file` in the entity's value, at any depth (a mesh object's file, an image texture's,
  // inline or named, an image background's), written relative to the folder of the file that
  // names it: the same file from the output's folder.
  void rebaseFiles(const Entity& e, ValueId v) {
    const ValueTree& t = tree(e);
    if (t.isList(v)) {
      for (std::size_t i = 0; i < t.size(v); ++i) rebaseFiles(e, t.item(v, i));
      return;
    }
    if (!t.isMap(v)) return;
    for (std::size_t i = 0; i < t.size(v); ++i) {
      const ValueId key = t.key(v, i);
      const ValueId value = t.value(v, i);
      if (t.isScalar(key) && t.scalar(key) == "file" && t.isScalar(value)) {
        rebase(e, value);
      } else {
        rebaseFiles(e, value);
      }
    }
  }

  void rebase(const Entity& e, ValueId file) {
    const std::filesystem::path written(std::string(tree(e).scalar(file)));
    if (written.is_absolute()) return;
    namespace fs = std::filesystem;
    const fs::path target =
        fs::absolute(scene_.fileOf(e).baseDirectory / written).lexically_normal();
    fs::path folder = output_.parent_path();
    if (folder.empty()) folder = ".";
    const fs::path relative = target.lexically_relative(fs::absolute(folder).lexically_normal());
    replaced_[file] = relative.empty() ? target.string() : relative.generic_string();
  }

  // An inline mesh large enough for a PLY file: written, and its YAML entry names the file.
  bool asPly(const Entity& e) {
    const ValueTree& t = tree(e);
    const ValueId positions = scene_.parameter(e, "positions");
    const ValueId indices = scene_.parameter(e, "indices");
    if (positions == kNoValue || indices == kNoValue || scene_.parameter(e, "colors") != kNoValue ||
        t.size(indices) < options_.plyTriangles) {
      return false;
    }
    const auto numbers = [&](ValueId list) {
      std::vector<double> out;
      out.reserve(3 * t.size(list));
      for (std::size_t i = 0; i < t.size(list); ++i) {
        const ValueId item = t.item(list, i);
        for (std::size_t k = 0; k < t.size(item); ++k) {
          out.push_back(parseNumber(t.scalar(t.item(item, k))).value_or(0));
        }
      }
      return out;
    };
    PlyMesh mesh;
    mesh.positions = numbers(positions);
    if (const ValueId normals = scene_.parameter(e, "normals"); normals != kNoValue) {
      mesh.normals = numbers(normals);
    }
    for (const double i : numbers(indices)) mesh.indices.push_back(static_cast<std::uint32_t>(i));
    ++plyFiles_;
    const std::string name = fmt::format("{}_mesh{}.ply", output_.stem().string(), plyFiles_);
    out_.files.push_back({name, binaryPly(mesh)});
    std::string s = "{type: mesh, file: " + yamlScalar(name);
    for (std::size_t i = 0; i < t.size(e.value); ++i) {
      const std::string_view key = t.scalar(t.key(e.value, i));
      if (key == "type" || key == "positions" || key == "normals" || key == "indices") continue;
      s += ", " + std::string(key) + ": " + flow(e, t.value(e.value, i));
    }
    out_.yaml += s + "}\n";
    return true;
  }

  const SceneDescription& scene_;
  const std::filesystem::path& output_;
  const SceneWriteOptions& options_;
  WrittenScene& out_;
  std::size_t plyFiles_ = 0;
  std::map<ValueId, std::string> replaced_;  // scalars written with another text
};

}  // namespace

std::string yamlScalar(std::string_view text) {
  if (plainWord(text)) return std::string(text);
  std::string s = "\"";
  for (const char c : text) {
    switch (c) {
      case '"':
        s += "\\\"";
        break;
      case '\\':
        s += "\\\\";
        break;
      case '\n':
        s += "\\n";
        break;
      case '\t':
        s += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          s += fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
        } else {
          s += c;
        }
    }
  }
  return s + "\"";
}

WrittenScene writeSceneYaml(const SceneDescription& scene, const std::filesystem::path& output,
                            const SceneWriteOptions& options) {
  WrittenScene out;
  Writer(scene, output, options, out).write();
  return out;
}

}  // namespace glint
