// glint's public API in one include: render jobs (scene file or scene built in code → image),
// scene checks and conversions, loading and building scenes, the renderer, image writers and the
// preview server.
// Programs built against an installed glint use find_package(glint CONFIG) and glint::glint.
#pragma once

#include "glint/factories/scene_loader.h"
#include "glint/image/image_writer.h"
#include "glint/job/job_error.h"
#include "glint/job/render_job.h"
#include "glint/job/scene_check.h"
#include "glint/job/scene_convert.h"
#include "glint/preview/job_preview.h"
#include "glint/preview/preview_server.h"
#include "glint/preview/preview_state.h"
#include "glint/render/film.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"
#include "glint/scene/seed_scene.h"
