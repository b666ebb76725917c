/* rtsh — what the model readers share (private to src/core/mesh). */
#ifndef RTSH_MESH_IO_H
#define RTSH_MESH_IO_H

#include "base/readhelp.h"
#include "rtsh/error.h"

/* Largest coordinate a model may hold: beyond it a bounding box, a BVH in
 * float and an eps make no sense. */
#define MESH_COORD_MAX 1e15

/* assimp's aiImportFile, with every file assimp opens (the model, and a
 * .gltf's buffers) read through rt_file_read (rtsh/filesrc.h). NULL with
 * err set ("PATH: cannot read the model: reason") on failure; free with
 * ai_lib_get()->release_import (core/mesh/ai_lib.h). */
struct aiScene;
const struct aiScene *rt_file_ai_import(const char *path, unsigned flags, rt_error *err);

#endif
