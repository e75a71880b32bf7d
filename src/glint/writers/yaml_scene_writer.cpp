#include "glint/writers/yaml_scene_writer.h"

#include <algorithm>
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
      // A comment ends at a line break: one in the file's name would start a line of YAML. So do
      // for libyaml NEL (U+0085), LINE SEPARATOR and PARAGRAPH SEPARATOR (U+2028, U+2029).
      std::string name;
      const std::string_view source = options_.sourceName;
      for (std::size_t i = 0; i < source.size(); ++i) {
        const std::string_view rest = source.substr(i);
        if (rest.starts_with("\xC2\x85")) {
          name += '?';
          i += 1;
        } else if (rest.starts_with("\xE2\x80\xA8") || rest.starts_with("\xE2\x80\xA9")) {
          name += '?';
          i += 2;
        } else {
          const char c = source[i];
          name += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
        }
      }
      y += fmt::format("# glint scene converted by `glint convert` from {}\n", name);
    }
    collectInputs();
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
      rebaseFiles(e, e.value);  // also the texture files of a mesh written as PLY
      if (kind == EntityKind::ObjectEntity && asPly(e)) continue;
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
      for (std::size_t i = 0; i < t.size(v); ++i) {
        const ValueId item = t.item(v, i);
        const std::string f = flow(e, item);
        if (t.isScalar(item) || f.size() + 2 + static_cast<std::size_t>(indent) <= kFlowWidth) {
          line(i, "- " + f);
        } else {
          line(i, "- " + block(e, item, indent + 2, true));
        }
      }
    } else {
      line(0, flow(e, v));
    }
    if (!s.empty()) s.pop_back();
    return s;
  }

  // Calls visit(value) for every `file` in the entity's value, at any depth (a mesh object's file,
  // an image texture's, inline or named, an image background's).
  template <class Visit>
  void forEachFile(const Entity& e, ValueId v, const Visit& visit) const {
    const ValueTree& t = tree(e);
    if (t.isList(v)) {
      for (std::size_t i = 0; i < t.size(v); ++i) forEachFile(e, t.item(v, i), visit);
      return;
    }
    if (!t.isMap(v)) return;
    for (std::size_t i = 0; i < t.size(v); ++i) {
      const ValueId key = t.key(v, i);
      const ValueId value = t.value(v, i);
      if (t.isScalar(key) && t.scalar(key) == "file" && t.isScalar(value)) {
        visit(value);
      } else {
        forEachFile(e, value, visit);
      }
    }
  }

  // The absolute path a `file` value of the entity names.
  std::filesystem::path fileTarget(const Entity& e, ValueId file) const {
    const std::filesystem::path written(std::string(tree(e).scalar(file)));
    if (written.is_absolute()) return written.lexically_normal();
    return std::filesystem::absolute(scene_.fileOf(e).baseDirectory / written).lexically_normal();
  }

  // Every file the scene reads: the scene's own files (the scene itself and the included ones,
  // by their paths) and every file a value names. The PLY files written must not replace one of
  // them (a bare mesh x_mesh1.ply converted to x.yaml).
  void collectInputs() {
    for (std::size_t i = 0; i < scene_.files.size(); ++i) {
      out_.inputs.push_back(std::filesystem::absolute(scene_.files[i]->name).lexically_normal());
    }
    for (const Entity& e : scene_.entities) {
      forEachFile(e, e.value, [&](ValueId file) { out_.inputs.push_back(fileTarget(e, file)); });
    }
  }

  // Every `file` in the entity's value written relative to the output's folder: the same file as
  // seen from the folder of the file that names it.
  void rebaseFiles(const Entity& e, ValueId v) {
    forEachFile(e, v, [&](ValueId file) {
      if (std::filesystem::path(std::string(tree(e).scalar(file))).is_absolute()) return;
      namespace fs = std::filesystem;
      const fs::path target = fileTarget(e, file);
      fs::path folder = output_.parent_path();
      if (folder.empty()) folder = ".";
      const fs::path relative = target.lexically_relative(fs::absolute(folder).lexically_normal());
      replaced_[file] = relative.empty() ? target.string() : relative.generic_string();
    });
  }

  // The name of the next PLY file: the output's stem, "_mesh" and a number, skipping any name
  // the scene reads (converting a scene whose mesh files are named so must not replace them).
  std::string nextPlyName() {
    namespace fs = std::filesystem;
    fs::path folder = output_.parent_path();
    if (folder.empty()) folder = ".";
    while (true) {
      ++plyNumber_;
      std::string name = fmt::format("{}_mesh{}.ply", output_.stem().string(), plyNumber_);
      const fs::path target = fs::absolute(folder / name).lexically_normal();
      if (std::find(out_.inputs.begin(), out_.inputs.end(), target) == out_.inputs.end()) {
        return name;
      }
    }
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
    const std::string name = nextPlyName();
    out_.files.push_back({name, binaryPly(mesh)});
    std::string s = "{type: mesh, file: " + yamlScalar(name);
    // An inline mesh without normals is flat whatever its `smooth` says; a mesh file without
    // normals would get generated ones.
    const bool flat = mesh.normals.empty();
    if (flat) s += ", smooth: false";
    for (std::size_t i = 0; i < t.size(e.value); ++i) {
      const std::string_view key = t.scalar(t.key(e.value, i));
      if (key == "type" || key == "positions" || key == "normals" || key == "indices") continue;
      if (flat && key == "smooth") continue;
      s += ", " + std::string(key) + ": " + flow(e, t.value(e.value, i));
    }
    out_.yaml += s + "}\n";
    return true;
  }

  const SceneDescription& scene_;
  const std::filesystem::path& output_;
  const SceneWriteOptions& options_;
  WrittenScene& out_;
  std::size_t plyNumber_ = 0;
  std::map<ValueId, std::string> replaced_;  // scalars written with another text
};

}  // namespace

std::string yamlScalar(std::string_view text) {
  if (plainWord(text)) return std::string(text);
  std::string s = "\"";
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    // C1 control characters (U+0080 to U+009F: 0xC2 0x80–0x9F in UTF-8), which the reader refuses
    // written as they are, escaped like the C0 ones.
    const auto next = i + 1 < text.size() ? static_cast<unsigned char>(text[i + 1]) : 0u;
    if (static_cast<unsigned char>(c) == 0xC2 && next >= 0x80 && next <= 0x9F) {
      s += fmt::format("\\u{:04x}", next);
      ++i;
      continue;
    }
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
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
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
