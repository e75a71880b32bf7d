// The factories of the scene-wide entities (DESIGN.md §4, §5, §7): image (the film), render (the
// integrator's settings), ambient light, background and camera. Each reads its entity's keys,
// checks their ranges once and fills its part of SceneParts.
#pragma once

#include "glint/factories/build_context.h"
#include "glint/readers/scene_description.h"

namespace glint {

// image: size, samples, encoding, grid, adaptive sampling; applies the caller's overrides. Sets
// ctx.encoding, ctx.imageOk and ctx.sceneImage.
void buildImage(const SceneDescription& scene, const Entity& image, BuildContext& ctx);
void buildRender(const SceneDescription& scene, const Entity& render, BuildContext& ctx);
// fog: {type: linear | exp | exp2, start, end, density, color, distance: ray | depth}.
void buildFog(const SceneDescription& scene, const Entity& e, BuildContext& ctx);
void buildAmbient(const SceneDescription& scene, const Entity& ambient, BuildContext& ctx);
void buildBackground(const SceneDescription& scene, const Entity& background, BuildContext& ctx);
// camera: after the image (its size, and whether the image is valid).
void buildCamera(const SceneDescription& scene, const Entity& camera, BuildContext& ctx);

}  // namespace glint
