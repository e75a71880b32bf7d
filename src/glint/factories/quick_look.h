// Quick look (DESIGN.md §13): `glint render model.glb` — a bare mesh file (.obj .ply .stl .gltf
// .glb) becomes a scene that frames the model: a camera from the front-right-above (+z is the
// front, +y up, +x right, as glTF defines them) at the distance where the model's bounding sphere
// fills the 35° field of view, a three-light rig (key from the front-right-above, fill from the
// front-left, rim from behind), a little ambient light and a grey ground plane under the model's
// lowest point. The model keeps its own materials.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "glint/factories/scene_loader.h"
#include "glint/readers/yaml_scene_reader.h"

namespace glint {

// Whether `file`'s extension is a mesh file's (quick look).
bool isQuickLookFile(const std::filesystem::path& file);

// What to add to a refusal of a file the bare mesh file `model` names outside its own folder: how
// to use such a layout (a scene file above both, naming the model); "" for any other reason.
std::string bareMeshFileHint(std::string_view refusal, const std::filesystem::path& model);

// The quick-look scene of a mesh file, as entities (the mesh is read to find its bounds; a file
// that cannot be read throws SceneError naming only the file).
ParseResult describeQuickLook(const std::filesystem::path& file, const LoadOptions& options = {});

}  // namespace glint
