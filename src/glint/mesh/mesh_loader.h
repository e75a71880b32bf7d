// The mesh loader's public API in one include: mesh files read and instanced (mesh_file.h), their
// size estimated before reading (mesh_size_estimate.h), and cached and budgeted per scene load
// (mesh_cache.h).
#pragma once

#include "glint/mesh/mesh_cache.h"
#include "glint/mesh/mesh_file.h"
#include "glint/mesh/mesh_size_estimate.h"
