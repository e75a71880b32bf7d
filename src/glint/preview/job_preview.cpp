#include "glint/preview/job_preview.h"

#include <utility>

namespace glint {

void attachPreview(RenderJobEvents& events, PreviewState& state) {
  events.sceneBuilt = [&state, before = std::move(events.sceneBuilt)](const SceneFacts& scene,
                                                                      const PixelRegion& region) {
    if (before) before(scene, region);
    state.sceneBuilt(scene.name, region, scene.image.encoding);
  };
  events.renderStarting = [&state, before = std::move(events.renderStarting)](std::size_t resumed,
                                                                              std::size_t total) {
    if (before) before(resumed, total);
    state.renderStarting(resumed, total);
  };
  // A distributed render gives the rank that rendered the tile as the last argument.
  events.tileFinished = [&state,
                         before = std::move(events.tileFinished)](const FinishedTile& tile) {
    if (before) before(tile);
    state.tileFinished(tile.region, tile.film, tile.done, tile.total, tile.rank);
  };
  events.imageFinished = [&state, before = std::move(events.imageFinished)](const Film& film) {
    if (before) before(film);
    state.imageFinished(film);
  };
}

}  // namespace glint
