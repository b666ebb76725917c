/* rtsh — glTF 2.0 (.gltf, .glb) and STL through assimp's C API (mesh.h).
 *
 * assimp triangulates and applies the node transforms
 * (aiProcess_PreTransformVertices), so each of its meshes arrives in model
 * space; we copy positions, normals, the first UV set and the material
 * index into our builder, and the materials' base colour, emission,
 * metallic-roughness factors and colour / normal textures. Textures
 * embedded in a .glb ("*0") are not read: the base colour stands in.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "core/mesh/mesh_io.h"
#include "rtsh/filesrc.h"
#include "rtsh/mesh.h"

static double lin(double v)
{
	return v;
}

static char *texture_path(const struct aiMaterial *m, enum aiTextureType type, const char *dir)
{
	struct aiString s;
	if (aiGetMaterialTexture(m, type, 0, &s, NULL, NULL, NULL, NULL, NULL, NULL) != AI_SUCCESS)
		return NULL;
	if (s.length == 0 || s.data[0] == '*')
		return NULL;
	return path_join(dir, s.data);
}

mesh *mesh_read_assimp(const char *path, rt_error *err)
{
	/* every file assimp opens is read through the file source */
	const struct aiScene *sc = rt_file_ai_import(
	    path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType, err);
	if (!sc)
		return NULL;
	mesh_builder b = {.name = path};
	char *dir = path_dir(path);
	bool ok = dir != NULL;
	/* materials */
	if (ok && sc->mNumMaterials > 0 && sc->mNumMaterials < 65536) {
		b.mats = calloc(sc->mNumMaterials, sizeof *b.mats);
		ok = b.mats != NULL;
		for (unsigned i = 0; ok && i < sc->mNumMaterials; i++) {
			const struct aiMaterial *am = sc->mMaterials[i];
			mesh_mat *m = &b.mats[b.nmats++];
			struct aiColor4D c;
			m->kd[0] = m->kd[1] = m->kd[2] = 0.64f;
			m->roughness = 1.0f;
			m->bump_scale = 1.0f;
			if (aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &c) == AI_SUCCESS ||
			    aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &c) == AI_SUCCESS) {
				/* glTF factors are linear */
				m->kd[0] = (float)lin(c.r);
				m->kd[1] = (float)lin(c.g);
				m->kd[2] = (float)lin(c.b);
			}
			if (aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &c) == AI_SUCCESS) {
				m->ke[0] = c.r;
				m->ke[1] = c.g;
				m->ke[2] = c.b;
			}
			ai_real v;
			if (aiGetMaterialFloatArray(am, AI_MATKEY_METALLIC_FACTOR, &v, NULL) == AI_SUCCESS)
				m->metallic = (float)v;
			if (aiGetMaterialFloatArray(am, AI_MATKEY_ROUGHNESS_FACTOR, &v, NULL) == AI_SUCCESS)
				m->roughness = (float)v;
			m->map_kd = texture_path(am, aiTextureType_BASE_COLOR, dir);
			if (!m->map_kd)
				m->map_kd = texture_path(am, aiTextureType_DIFFUSE, dir);
			m->map_norm = texture_path(am, aiTextureType_NORMALS, dir);
		}
	}
	bool has_uv = true, has_n = true;
	for (unsigned i = 0; i < sc->mNumMeshes; i++) {
		has_uv &= sc->mMeshes[i]->mTextureCoords[0] != NULL;
		has_n &= sc->mMeshes[i]->mNormals != NULL;
	}
	for (unsigned i = 0; ok && i < sc->mNumMeshes; i++) {
		const struct aiMesh *am = sc->mMeshes[i];
		if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
			continue;
		int32_t base = (int32_t)b.nv;
		for (unsigned k = 0; ok && k < am->mNumVertices; k++) {
			const struct aiVector3D *p = &am->mVertices[k];
			float fp[3] = {p->x, p->y, p->z};
			for (int a = 0; a < 3; a++)
				if (!isfinite(fp[a]) || fabsf(fp[a]) > (float)MESH_COORD_MAX) {
					rt_error_set(err, "%s: mesh %u vertex %u: coordinate %g is not a finite number; "
					             "expected |value| <= 1e15", path, i, k, (double)fp[a]);
					ok = false;
					break;
				}
			ok = ok && mb_vertex(&b, fp);
			if (ok && has_n) {
				float fn[3] = {am->mNormals[k].x, am->mNormals[k].y, am->mNormals[k].z};
				ok = mb_normal(&b, fn);
			}
			if (ok && has_uv) {
				float ft[2] = {am->mTextureCoords[0][k].x, am->mTextureCoords[0][k].y};
				ok = mb_uv(&b, ft);
			}
		}
		b.cur_mat = (uint16_t)(am->mMaterialIndex < b.nmats ? am->mMaterialIndex : 0);
		for (unsigned k = 0; ok && k < am->mNumFaces; k++) {
			const struct aiFace *fc = &am->mFaces[k];
			if (fc->mNumIndices != 3)
				continue;
			int32_t t[3][3];
			for (int c = 0; c < 3; c++) {
				if (fc->mIndices[c] >= am->mNumVertices) {
					rt_error_set(err, "%s: mesh %u face %u: index %u is out of range; expected 0..%u", path,
					             i, k, fc->mIndices[c], am->mNumVertices - 1);
					ok = false;
					break;
				}
				int32_t v = base + (int32_t)fc->mIndices[c];
				t[c][0] = v;
				t[c][1] = has_uv ? v : -1;
				t[c][2] = has_n ? v : -1;
			}
			ok = ok && mb_triangle(&b, t);
		}
	}
	aiReleaseImport(sc);
	free(dir);
	if (!ok) {
		if (err && !err->msg[0])
			rt_error_set(err, "%s: out of memory reading the model", path);
		mb_free(&b);
		return NULL;
	}
	if (b.nc == 0) {
		mb_free(&b);
		rt_error_set(err, "%s: no triangles in the model; expected at least one", path);
		return NULL;
	}
	return mb_finish(&b, err);
}
