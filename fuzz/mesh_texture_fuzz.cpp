// libFuzzer target: the texture part of the mesh readers — a mesh file's materials naming
// textures (OBJ/MTL map_*, glTF images: files, data: URIs, .glb buffers), carried across the import
// child's answer and read by the scene builder (path rules, embedded images decoded, bindings,
// UVs and tangents), through glint::loadSceneFromString of a scene holding the mesh. An input
// starting with "glTF" is written as input.glb, any other as input.obj with the bytes after the
// side-file separator as input.mtl; the folder also holds tex.png, a small valid texture the files
// may name. Any bytes give a scene or a SceneError; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "glint/factories/scene_loader.h"
#include "glint/image/image_writer.h"
#include "glint/render/film.h"
#include "mesh_fuzz.h"

namespace {

const std::filesystem::path& folderWithTexture() {
  static const std::filesystem::path folder = [] {
    const std::filesystem::path f = glint::fuzz::workFolder();
    glint::Film film(4, 4, glint::PixelRegion{0, 0, 4, 4});
    film.at(1, 2) = glint::Color(1, 0.5, 0);
    glint::writeImage(film, f / "tex.png", glint::Encoding::Srgb);
    return f;
  }();
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path& folder = folderWithTexture();
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  std::string_view main = bytes;
  std::string_view side;
  const std::size_t at = bytes.find(glint::fuzz::kSideSeparator);
  if (!binary && at != std::string_view::npos) {
    main = bytes.substr(0, at);
    side = bytes.substr(at + glint::fuzz::kSideSeparator.size());
  }
  const std::string name = binary ? "input.glb" : "input.obj";
  glint::fuzz::writeFile(folder / name, main);
  glint::fuzz::writeFile(folder / "input.mtl", side);
  const std::string scene =
      "camera: {position: [0, 0, 5], look_at: [0, 0, 0], fov: 40}\n"
      "image: {width: 8, height: 8}\n"
      "objects:\n  - {type: mesh, file: " +
      name + "}\n";
  try {
    const glint::LoadedScene loaded = glint::loadSceneFromString(scene, "fuzz.yaml", folder);
    for (const glint::TriangleMesh& mesh : loaded.parts.meshes) {
      glint::fuzz::require(mesh.uvs.empty() || mesh.uvs.size() == mesh.positions.size());
      glint::fuzz::require(mesh.tangents.empty() || mesh.tangents.size() == mesh.positions.size());
    }
  } catch (const glint::SceneError& e) {
    glint::fuzz::require(!e.diagnostics().empty());
  }
  return 0;
}
