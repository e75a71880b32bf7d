// attachPreview: a render job's events feeding a PreviewState, besides whatever else listens.
#pragma once

#include "glint/job/render_job.h"
#include "glint/preview/preview_state.h"

namespace glint {

// Hooks `state` to the scene, the start, every finished tile and the finished image of the job
// that `events` will be given to; callbacks already set there are still called, first. The caller
// reports the end (PreviewState::ended) with its summary. `state` must outlive the job.
void attachPreview(RenderJobEvents& events, PreviewState& state);

}  // namespace glint
