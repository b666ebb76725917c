/* rtsh — the functions of assimp's C API that rtsh calls, from the library
 * opened on the first model that needs it (base/dynlib.h): a process that
 * reads no .stl or assimp glTF never loads assimp nor libstdc++. */
#ifndef RTSH_AI_LIB_H
#define RTSH_AI_LIB_H

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/scene.h>

#include "rtsh/error.h"

/* The soname the build linked against before (Debian's libassimp5). */
#ifndef RTSH_ASSIMP_SONAME
#define RTSH_ASSIMP_SONAME "libassimp.so.5"
#endif

typedef struct ai_lib {
	const struct aiScene *(*import_file_ex)(const char *file, unsigned int flags, struct aiFileIO *fs);
	void (*release_import)(const struct aiScene *scene);
	const char *(*get_error_string)(void);
	enum aiReturn (*get_material_color)(const struct aiMaterial *mat, const char *key, unsigned int type,
	                                    unsigned int index, struct aiColor4D *out);
	enum aiReturn (*get_material_float_array)(const struct aiMaterial *mat, const char *key, unsigned int type,
	                                          unsigned int index, ai_real *out, unsigned int *max);
	enum aiReturn (*get_material_texture)(const struct aiMaterial *mat, enum aiTextureType type,
	                                      unsigned int index, struct aiString *path,
	                                      enum aiTextureMapping *mapping, unsigned int *uvindex, ai_real *blend,
	                                      enum aiTextureOp *op, enum aiTextureMapMode *mapmode,
	                                      unsigned int *flags);
} ai_lib;

/* assimp's functions, the library opened on the first call (thread-safe);
 * NULL with err set ("PATH: cannot read the model: ...") when it cannot be
 * loaded. */
const ai_lib *ai_lib_get(const char *path, rt_error *err);

#endif
