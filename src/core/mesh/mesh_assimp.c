/* rtsh — glTF 2.0 (.gltf, .glb) and STL through assimp's C API (mesh.h).
 *
 * assimp triangulates and applies the node transforms
 * (aiProcess_PreTransformVertices), so each of its meshes arrives in model
 * space; we copy positions, normals, the first UV set and the material
 * index into our builder, and the materials' base colour, emission,
 * metallic-roughness factors and colour / normal textures. A texture
 * embedded in the file (a .glb's images: assimp names them "*N", or by the
 * name of an image it holds) arrives as an aiTexture: compressed bytes
 * (PNG, JPEG, ..., mHeight 0, the format in achFormatHint) that
 * image_decode_rgb reads from memory, or mWidth x mHeight BGRA texels; it
 * becomes a texture the mesh owns (mesh_mat.tex_kd, tex_norm).
 */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <assimp/postprocess.h>

#include "core/mesh/ai_lib.h"
#include "core/mesh/mesh_io.h"
#include "rtsh/filesrc.h"
#include "rtsh/mesh.h"
#include "rtsh/srgb.h"
#include "rtsh/texture.h"

static double lin(double v)
{
	return v;
}

static const char *short_name(const char *name)
{
	const char *s = strrchr(name, '/'), *b = strrchr(name, '\\');
	if (b && (!s || b > s))
		s = b;
	return s ? s + 1 : name;
}

/* The embedded image a material names: "*N" (N an index in mTextures), or
 * an embedded image whose file name has the same last component. NULL when
 * the name is a file outside the model; *index its place in mTextures. */
static const struct aiTexture *embedded_image(const struct aiScene *sc, const char *name, unsigned *index)
{
	if (name[0] == '*') {
		char *end;
		unsigned long i = strtoul(name + 1, &end, 10);
		*index = (unsigned)i;
		return end != name + 1 && *end == '\0' && i < sc->mNumTextures ? sc->mTextures[i] : NULL;
	}
	for (unsigned i = 0; i < sc->mNumTextures; i++)
		if (sc->mTextures[i]->mFilename.length > 0 &&
		    strcmp(short_name(sc->mTextures[i]->mFilename.data), short_name(name)) == 0) {
			*index = i;
			return sc->mTextures[i];
		}
	return NULL;
}

/* An embedded image decoded into a texture; NULL (err set, naming the model
 * and the image) when it cannot be read. */
static texture *embedded_texture(const struct aiTexture *tx, unsigned index, const char *path, bool srgb,
                                 rt_error *err)
{
	char name[RT_ERROR_FILE_MAX + 64];
	int w = 0, h = 0;
	float *rgb = NULL;
	if (tx->mHeight == 0) {
		/* compressed: mWidth bytes; the hint is the format's extension */
		char hint[sizeof tx->achFormatHint + 1] = {0};
		for (size_t i = 0; i < sizeof tx->achFormatHint && isalnum((unsigned char)tx->achFormatHint[i]); i++)
			hint[i] = (char)tolower((unsigned char)tx->achFormatHint[i]);
		snprintf(name, sizeof name, "%s: embedded image %u.%s", path, index, hint[0] ? hint : "png");
		if (!tx->pcData || tx->mWidth == 0) {
			rt_error_set(err, "%s: no bytes; expected an image", name);
			return NULL;
		}
		rgb = image_decode_rgb(name, (const unsigned char *)tx->pcData, tx->mWidth, srgb, &w, &h, err);
		if (!rgb)
			return NULL;
	} else {
		snprintf(name, sizeof name, "%s: embedded image %u", path, index);
		if (!tx->pcData || tx->mWidth > 65536 || tx->mHeight > 65536) {
			rt_error_set(err, "%s: %u x %u texels; expected at most 65536 x 65536", name, tx->mWidth,
			             tx->mHeight);
			return NULL;
		}
		w = (int)tx->mWidth;
		h = (int)tx->mHeight;
		rgb = malloc((size_t)w * (size_t)h * 3 * sizeof *rgb);
		if (!rgb) {
			rt_error_set(err, "%s: out of memory", name);
			return NULL;
		}
		for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
			const struct aiTexel *t = &tx->pcData[i];
			unsigned char c[3] = {t->r, t->g, t->b};
			for (int k = 0; k < 3; k++)
				rgb[3 * i + (size_t)k] = srgb ? (float)srgb8_to_linear(c[k]) : c[k] / 255.0f;
		}
	}
	return texture_make(rgb, w, h, name, srgb, err);
}

/* A material's texture of `type`: a file beside the model (*file) or an
 * image embedded in it (*tex). False (err set) when an embedded image
 * cannot be read. */
static bool material_texture(const ai_lib *ai, mesh_builder *b, const struct aiScene *sc, const struct aiMaterial *m,
                             enum aiTextureType type, const char *path, const char *dir, bool srgb, char **file,
                             texture **tex, rt_error *err)
{
	struct aiString s;
	*file = NULL;
	*tex = NULL;
	if (ai->get_material_texture(m, type, 0, &s, NULL, NULL, NULL, NULL, NULL, NULL) != AI_SUCCESS || s.length == 0)
		return true;
	unsigned index = 0;
	const struct aiTexture *tx = embedded_image(sc, s.data, &index);
	if (tx) {
		*tex = embedded_texture(tx, index, path, srgb, err);
		if (*tex && !mb_texture(b, *tex)) {
			*tex = NULL;
			rt_error_set(err, "%s: out of memory", path);
		}
		return *tex != NULL;
	}
	if (s.data[0] == '*') /* names an image the file does not hold */
		return true;
	*file = path_join(dir, s.data);
	return true;
}

mesh *mesh_read_assimp(const char *path, rt_error *err)
{
	/* every file assimp opens is read through the file source */
	const struct aiScene *sc = rt_file_ai_import(
	    path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType, err);
	if (!sc)
		return NULL;
	const ai_lib *ai = ai_lib_get(path, err); /* loaded: the import above used it */
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
			if (ai->get_material_color(am, AI_MATKEY_BASE_COLOR, &c) == AI_SUCCESS ||
			    ai->get_material_color(am, AI_MATKEY_COLOR_DIFFUSE, &c) == AI_SUCCESS) {
				/* glTF factors are linear */
				m->kd[0] = (float)lin(c.r);
				m->kd[1] = (float)lin(c.g);
				m->kd[2] = (float)lin(c.b);
			}
			if (ai->get_material_color(am, AI_MATKEY_COLOR_EMISSIVE, &c) == AI_SUCCESS) {
				m->ke[0] = c.r;
				m->ke[1] = c.g;
				m->ke[2] = c.b;
			}
			ai_real v;
			if (ai->get_material_float_array(am, AI_MATKEY_METALLIC_FACTOR, &v, NULL) == AI_SUCCESS)
				m->metallic = (float)v;
			if (ai->get_material_float_array(am, AI_MATKEY_ROUGHNESS_FACTOR, &v, NULL) == AI_SUCCESS)
				m->roughness = (float)v;
			ok = material_texture(ai, &b, sc, am, aiTextureType_BASE_COLOR, path, dir, true, &m->map_kd, &m->tex_kd, err);
			if (ok && !m->map_kd && !m->tex_kd)
				ok = material_texture(ai, &b, sc, am, aiTextureType_DIFFUSE, path, dir, true, &m->map_kd, &m->tex_kd,
				                      err);
			ok = ok &&
			     material_texture(ai, &b, sc, am, aiTextureType_NORMALS, path, dir, false, &m->map_norm, &m->tex_norm, err);
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
	ai->release_import(sc);
	free(dir);
	if (!ok) {
		if (err && !err->msg[0])
			rt_error_set(err, "%s: %s", path, b.over ? b.limit.msg : "out of memory reading the model");
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
