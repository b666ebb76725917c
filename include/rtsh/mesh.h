/* rtsh — triangle meshes: model files, normals and the triangle BVH.
 *
 * A mesh is a list of vertices (position, and optionally a normal and a
 * texture coordinate, all single precision) and of triangles that index
 * them, with a material per triangle when the file has several. The
 * readers (mesh_obj.c, mesh_ply.c, and assimp for glTF 2.0 and STL in
 * mesh_assimp.c) fill one through the builder below; mesh_prepare then
 * derives normals (angle-weighted, split at creases) and builds the BVH
 * (bvh.c's 4-wide tree over the triangles, in object space), after which a
 * mesh is immutable and may be shared by any number of objects and
 * threads: an instance is a transform and a pointer (world.c).
 *
 * Errors name the file and, where the reader knows it, the line (text
 * formats) or the byte offset (binary formats).
 */
#ifndef RTSH_MESH_H
#define RTSH_MESH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/math.h"

/* A material of the file (MTL, glTF). Paths are resolved against the
 * model's folder; NULL when absent. */
typedef struct mesh_mat {
	char *name;
	float kd[3];      /* linear base colour */
	float ke[3];      /* linear emission */
	float metallic, roughness; /* glTF; 0 and 1 otherwise */
	char *map_kd;     /* colour texture (sRGB) */
	char *map_bump;   /* height map */
	char *map_norm;   /* tangent-space normal map */
	float bump_scale; /* -bm, 1 by default */
	/* images embedded in the model file (a .glb's), decoded when it is
	 * read and owned by the mesh; the map_ path is NULL then */
	struct texture *tex_kd, *tex_norm;
} mesh_mat;

/* Four triangles of a leaf laid out for the leaf test (mesh_trace.c):
 * v[3 * corner + axis][lane] is a vertex coordinate, the same float as in
 * mesh.p, so both tests see the same triangle. Lanes past a leaf's count
 * repeat its last triangle and are masked off. */
typedef struct mesh_tri4 {
	_Alignas(16) float v[9][4];
} mesh_tri4;

typedef struct mesh {
	char *path;
	uint32_t nverts, ntris;
	float (*p)[3];     /* positions; NULL once prepared (blk holds them) */
	float (*n)[3];     /* unit normals, NULL: flat shading */
	float (*uv)[2];    /* texture coordinates, NULL: none */
	uint32_t (*tri)[3];
	uint16_t *tmat;    /* material per triangle, NULL when nmats <= 1 */
	mesh_mat *mats;
	uint32_t nmats;
	box bounds;        /* of the positions */
	struct bvh *tree;  /* over tri, in tree order (mesh_prepare); a leaf's
	                      child is its first block in blk */
	mesh_tri4 *blk;    /* the leaves' triangles, 4 to a block */
	uint32_t *bfirst;  /* the triangle in lane 0 of each block */
	uint32_t nblk;
	float eps;         /* self-hit guard in object units */
	size_t refs;       /* users in the cache (mesh_cache_get) */
} mesh;

/* --- loading --- */

/* Reads a model by its extension (.obj .ply .gltf .glb .stl, any case).
 * NULL (err set: "FILE:LINE: ..." or "FILE: byte N: ...") on failure,
 * including a file with no triangle. */
mesh *mesh_load(const char *path, rt_error *err);
mesh *mesh_read_obj(const char *path, rt_error *err);
mesh *mesh_read_ply(const char *path, rt_error *err);
mesh *mesh_read_assimp(const char *path, rt_error *err);
/* The same readers on a buffer, `name` used in messages (fuzzing, tests). */
mesh *mesh_parse_obj(const char *name, const char *dir, const char *buf, size_t len, rt_error *err);
mesh *mesh_parse_ply(const char *name, const char *buf, size_t len, rt_error *err);
/* True when the extension is one mesh_load reads. */
bool mesh_format_known(const char *path);

/* Derives what the file lacks and builds the tree. smooth = false: flat
 * faces (file normals dropped); otherwise file normals are kept, or
 * computed weighted by corner angle and split where faces meet at more
 * than crease_deg degrees. False (err set) when out of memory. */
bool mesh_prepare(mesh *m, bool smooth, double crease_deg, rt_error *err);
void mesh_free(mesh *m);
/* Bytes held by a prepared mesh (benchmark: bytes per triangle). */
size_t mesh_memory(const mesh *m);

/* A prepared mesh shared by every user of the same file, normals options
 * and file version (size and mtime): loaded once. mesh_cache_put releases
 * one reference. Thread-safe. */
mesh *mesh_cache_get(const char *path, bool smooth, double crease_deg, rt_error *err);
void mesh_cache_put(mesh *m);

/* --- the builder the readers share --- */

typedef struct mesh_builder {
	const char *name;  /* for messages */
	float (*v)[3];  size_t nv, cv;   /* positions as read */
	float (*vt)[2]; size_t nvt, cvt; /* texture coordinates as read */
	float (*vn)[3]; size_t nvn, cvn; /* normals as read */
	/* corners: index triples (position, uv or -1, normal or -1) */
	int32_t (*c)[3]; size_t nc, cc;
	uint16_t *fm;  size_t nf, cf;    /* material per triangle */
	mesh_mat *mats; size_t nmats, cmats;
	uint16_t cur_mat;
} mesh_builder;

bool mb_vertex(mesh_builder *b, const float p[3]);
bool mb_uv(mesh_builder *b, const float t[2]);
bool mb_normal(mesh_builder *b, const float n[3]);
/* A triangle of three corners, each (position, uv, normal), -1 absent. */
bool mb_triangle(mesh_builder *b, int32_t c[3][3]);
/* Welds the corners into vertices; NULL (err set) on failure. Frees b's
 * arrays in every case. */
mesh *mb_finish(mesh_builder *b, rt_error *err);
void mb_free(mesh_builder *b);

/* --- ray queries (object space, single precision) --- */

/* A prepared mesh names a triangle by its slot in the blocks, 4 * block +
 * lane: what mesh_intersect returns and mesh_surface takes. */
static inline uint32_t mesh_slot_tri(const mesh *m, uint32_t slot)
{
	return m->bfirst[slot >> 2] + (slot & 3); /* its index in tri and tmat */
}
/* The corners of the triangle in a slot. */
void mesh_corners(const mesh *m, uint32_t slot, vec3 c[3]);

typedef struct mesh_ray {
	float o[3], d[3];
	int kx, ky, kz;      /* watertight test: axes, kz the largest |d| */
	float sx, sy, sz;    /* shear constants */
} mesh_ray;

void mesh_ray_make(mesh_ray *r, vec3 o, vec3 d);
/* The nearest triangle with tmin < t < *tmax: sets *tmax, *tri (its slot)
 * and the barycentric weights b[3] of its corners. */
bool mesh_intersect(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3]);
bool mesh_occluded(const mesh *m, const mesh_ray *r, float tmin, float tmax);
/* The same walk with each leaf block tested one lane at a time in scalar
 * code (on machines without SSE2 it is the only path); tests check that it
 * finds the very same hits as the SSE path. */
bool mesh_intersect_scalar(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3]);
bool mesh_occluded_scalar(const mesh *m, const mesh_ray *r, float tmin, float tmax);
/* Lays the leaves' triangles out in blocks of four (mesh_prepare calls it
 * once the tree and the triangle order are final). False when out of
 * memory. */
bool mesh_make_blocks(mesh *m);
/* The same without the tree, on a mesh not prepared (positions and
 * triangles as read; *tri an index in tri): the tests' reference. */
bool mesh_intersect_brute(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3]);

/* What shading needs at a hit on a prepared mesh (object space, the
 * triangle by its slot): geometric normal (unit),
 * shading normal (unit, the same side as ng), texture coordinates and the
 * tangents along u and v (zero when there are none). */
typedef struct mesh_surf {
	vec3 ng, ns, dpdu, dpdv;
	double u, v;
	int mat; /* material of the file, -1 none */
} mesh_surf;
void mesh_surface(const mesh *m, uint32_t slot, const float b[3], mesh_surf *s);

#endif
