/* rtsh — triangle meshes: model files, normals and the triangle BVH.
 *
 * A mesh is a list of vertices (position, and optionally a normal and a
 * texture coordinate, all single precision) and of triangles that index
 * them, with a material per triangle when the file has several. The
 * readers (mesh_obj.c, mesh_ply.c, and assimp for glTF 2.0 and STL in
 * mesh_assimp.c) fill one through the builder below; mesh_prepare then
 * derives normals (angle-weighted, split at creases) and builds the BVH
 * (mesh_tree.c: an 8-wide tree over the triangles, in object space), after
 * which a mesh is immutable and may be shared by any number of objects and
 * threads: an instance is a transform and a pointer (world.c).
 *
 * Errors name the file and, where the reader knows it, the line (text
 * formats) or the byte offset (binary formats).
 */
#ifndef RTSH_MESH_H
#define RTSH_MESH_H

#include <stdatomic.h>
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
	 * read and held by the mesh (mesh.texs); the map_ path is NULL then */
	struct texture *tex_kd, *tex_norm;
	/* glTF 2.0 (mesh_gltf.c; zero from the other readers). kd is the base
	 * colour factor and ke the emissive factor x KHR_materials_emissive_strength. */
	bool gltf;        /* the texture is multiplied by kd (glTF), not kd's replacement (MTL) */
	float alpha;      /* baseColorFactor's alpha */
	uint8_t alpha_mode; /* MESH_ALPHA_* */
	float alpha_cutoff; /* MASK: texels of alpha below it are holes (0.5) */
	/* MASK with a base colour texture that has an alpha channel: that
	 * channel (bytes, linear, top row first; only these materials keep it),
	 * its size and its sampler's wrapS, wrapT (MESH_WRAP_*); NULL: alpha is
	 * the factor's alone */
	unsigned char *alpha_map;
	int alpha_w, alpha_h;
	uint8_t alpha_wrap[2];
	float normal_scale; /* normalTexture.scale (1) */
	float transmission; /* KHR_materials_transmission (0) */
	float ior;          /* KHR_materials_ior (1.5) */
	float thickness;    /* KHR_materials_volume: 0 thin-walled */
	float att_dist;     /* ... attenuationDistance, 0: infinite */
	float att_color[3]; /* ... attenuationColor (linear, 1,1,1) */
	float clearcoat, clearcoat_roughness; /* KHR_materials_clearcoat (0, 0) */
	float specular;     /* KHR_materials_specular specularFactor (1) */
	float specular_color[3]; /* ... specularColorFactor (1,1,1) */
	char *map_mr, *map_emit;             /* metallic-roughness, emissive textures */
	struct texture *tex_mr, *tex_emit;   /* ... embedded */
	float uvx[2];         /* ... its rotation's cross terms: u' += uvx[0] v, v' += uvx[1] u */
	float uvs[2], uvo[2]; /* KHR_texture_transform of the base colour texture, in
	                       * rtsh's uv (v up): uv x uvs + uvo; (1,1), (0,0) */
} mesh_mat;

enum { MESH_ALPHA_OPAQUE, MESH_ALPHA_MASK, MESH_ALPHA_BLEND };
enum { MESH_WRAP_REPEAT, MESH_WRAP_CLAMP, MESH_WRAP_MIRROR };

/* Four triangles of a leaf laid out for the leaf test (mesh_trace.c):
 * v[3 * corner + axis][lane] is a vertex coordinate, the same float as the
 * file's, so every test sees the same triangle. A leaf's last block repeats
 * its last triangle in the lanes past its count: a repeat finds the same
 * hit as the lane it copies, and a tie goes to the lower lane. */
typedef struct mesh_tri4 {
	_Alignas(16) float v[9][4];
} mesh_tri4;

/* A node of a mesh's triangle tree (mesh_tree.c): eight children, their
 * boxes b[row][k] as floats rounded outward (rows MESH_LO(axis) and
 * MESH_HI(axis): low x, high x, low y, high y, low z, high z, so that a
 * ray's far row is its near row's neighbour, one bit apart), and a
 * reference each: an inner node's byte offset in the node array (the walk
 * adds it to the array's address: no multiply between a child's reference
 * and its loads), or
 * MESH_LEAF | (blocks - 1) << MESH_LEAF_SHIFT | the leaf's first block.
 * An unused child has an empty box (lo = +inf, hi = -inf). 224 bytes: four
 * cache lines, read by one AVX2 slab test or two SSE ones. */
#define MESH_WIDTH 8
#define MESH_LEAF 0x80000000u
#define MESH_LEAF_SHIFT 28
#define MESH_LEAF_BLOCKS 8u               /* blocks a leaf holds at most */
#define MESH_MAX_BLOCKS (1u << MESH_LEAF_SHIFT)
#define MESH_LO(axis) (2 * (axis))
#define MESH_HI(axis) (2 * (axis) + 1)
typedef struct mesh_node {
	_Alignas(32) float b[6][MESH_WIDTH];
	uint32_t child[MESH_WIDTH];
} mesh_node;
/* Nodes a tree may have: their byte offsets stay below MESH_LEAF. */
#define MESH_MAX_NODES (MESH_LEAF / sizeof(mesh_node))

typedef struct mesh {
	char *path;
	uint32_t nverts, ntris;
	float (*p)[3];     /* positions; NULL once prepared (blk holds them) */
	float (*n)[3];     /* unit normals, NULL: flat shading */
	float (*uv)[2];    /* texture coordinates, NULL: none */
	uint32_t (*tri)[3]; /* NULL once prepared when there are neither
	                       normals nor uv to interpolate */
	uint16_t *tmat;    /* material per triangle, NULL when nmats <= 1 */
	mesh_mat *mats;
	uint32_t nmats;
	struct texture **texs; /* the embedded images the materials point to (owned) */
	uint32_t ntexs;
	box bounds;        /* of the positions */
	mesh_node *nodes;  /* the tree (mesh_prepare): node 0 is the root */
	uint32_t nnodes;
	mesh_tri4 *blk;    /* the leaves' triangles, 4 to a block */
	uint32_t (*btri)[4]; /* the triangle (index in tri) in each lane */
	uint32_t nblk;
	uint32_t nrefs;    /* triangles in leaves: ntris, more where spatial
	                      splits put one triangle in several leaves */
	float eps;         /* self-hit guard in object units */
	size_t refs;       /* users in the cache (mesh_cache_get) */
	char *warning;     /* the reader's first warning ("FILE:LINE: ..."), NULL: none (owned) */
	/* Some material is an alphaMode MASK cut-out or BLEND (glTF): the walk
	 * asks mesh_cut_hole of each triangle hit it would accept. False: the
	 * walk never asks (one test where a block finds a hit, nothing else). */
	bool cuts;
} mesh;

/* --- loading --- */

/* Reads a model by its extension (.obj .ply .gltf .glb .stl, any case).
 * NULL (err set: "FILE:LINE: ..." or "FILE: byte N: ...") on failure,
 * including a file with no triangle. */
mesh *mesh_load(const char *path, rt_error *err);
mesh *mesh_read_obj(const char *path, rt_error *err);
mesh *mesh_read_ply(const char *path, rt_error *err);
mesh *mesh_read_assimp(const char *path, rt_error *err);
mesh *mesh_read_gltf(const char *path, rt_error *err);
/* Only the triangles of node `node` (an index into the file's nodes, placed
 * by its scene) with the node's whole transform, all the file's materials:
 * a glTF node as an object of its own. node < 0: the whole scene. */
mesh *mesh_read_gltf_node(const char *path, long node, rt_error *err);
mesh *mesh_parse_gltf_node(const char *name, const char *dir, const char *buf, size_t len, long node, rt_error *err);
/* The same readers on a buffer, `name` used in messages (fuzzing, tests). */
mesh *mesh_parse_obj(const char *name, const char *dir, const char *buf, size_t len, rt_error *err);
mesh *mesh_parse_ply(const char *name, const char *buf, size_t len, rt_error *err);
/* dir NULL: a buffer or image outside the bytes is not read (an error). */
mesh *mesh_parse_gltf(const char *name, const char *dir, const char *buf, size_t len, rt_error *err);
/* True when the extension is one mesh_load reads. */
bool mesh_format_known(const char *path);

/* The model's own image files (an MTL's maps, a glTF's images) are there
 * (looked up with stat, not decoded); else false with err naming the model
 * (path), the material and the image. The model viewer's load and a .rt's
 * mesh line check them, so that a missing one fails the load. */
bool mesh_images_ok(const char *path, const mesh *m, rt_error *err);
/* The extensions mesh_load reads as a message lists them (".obj, .ply, ...
 * or .stl"), into buf (truncated to size). */
void mesh_format_list(char *buf, size_t size);

/* Bytes a triangle takes at the peak of mesh_prepare, with the mesh it
 * holds (measured: 136-142 on a 1M-triangle torus, flat or smooth; the
 * estimate checked against the memory limit before it starts). */
#define MESH_PREPARE_BYTES 200.0
/* Derives what the file lacks and builds the tree. smooth = false: flat
 * faces (file normals dropped); otherwise file normals are kept, or
 * computed weighted by corner angle and split where faces meet at more
 * than crease_deg degrees. False (err set) when out of memory, or when its
 * estimate (MESH_PREPARE_BYTES a triangle) exceeds the memory limit. */
bool mesh_prepare(mesh *m, bool smooth, double crease_deg, rt_error *err);
/* mesh_prepare that stops, false with err "stopped", soon after *cancel is
 * set (NULL: never): Ctrl-C in the shell. */
bool mesh_prepare_cancel(mesh *m, bool smooth, double crease_deg, const atomic_bool *cancel, rt_error *err);
void mesh_free(mesh *m);
/* Bytes held by a prepared mesh (benchmark: bytes per triangle). */
size_t mesh_memory(const mesh *m);

/* A prepared mesh shared by every user of the same file, normals options
 * and file version (size and mtime): loaded once. mesh_cache_put releases
 * one reference. Thread-safe. */
mesh *mesh_cache_get(const char *path, bool smooth, double crease_deg, const atomic_bool *cancel, rt_error *err);
/* The same for node `node` of a glTF file (mesh_read_gltf_node); node < 0:
 * the whole file (mesh_cache_get). */
mesh *mesh_cache_get_node(const char *path, long node, bool smooth, double crease_deg, const atomic_bool *cancel,
                          rt_error *err);
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
	uint64_t *th;  size_t cth;       /* hash per triangle (its corners' values), nf of them */
	mesh_mat *mats; size_t nmats, cmats;
	struct texture **texs; size_t ntexs, ctexs; /* embedded images (mb_texture) */
	uint16_t cur_mat;
	size_t bytes;      /* what the arrays above hold */
	bool over;         /* a growth was refused by the memory limit */
	char *warning;     /* the first warning, handed to the mesh (owned) */
	rt_error limit;    /* ... and how (memory.h) */
	/* the last triangles kept, by hash (tag << 32 | index + 1; 0: none):
	 * a copy of one of them is dropped as it comes (mb_triangle), so that
	 * N copies of a face cost no memory; mb_finish drops the rest */
	uint64_t recent[1024];
	size_t ndup;       /* copies dropped so */
} mesh_builder;

/* Why an mb_ call failed: the memory limit's message ("the model X needs
 * about 5 GiB of memory; expected at most ..."), or "out of memory". The
 * builder's arrays are checked against the limit (memory.h) each time they
 * grow, so a model too large for the machine is refused while it is read,
 * not when the machine runs out. */
const char *mb_failure(const mesh_builder *b);

bool mb_vertex(mesh_builder *b, const float p[3]);
bool mb_uv(mesh_builder *b, const float t[2]);
bool mb_normal(mesh_builder *b, const float n[3]);
/* A triangle of three corners, each (position, uv, normal), -1 absent. */
bool mb_triangle(mesh_builder *b, int32_t c[3][3]);
/* Gives the builder (then the mesh) an embedded image to hold; false when
 * out of memory (t is freed then). */
bool mb_texture(mesh_builder *b, struct texture *t);
/* Welds the corners into vertices; NULL (err set) on failure. Frees b's
 * arrays in every case. */
mesh *mb_finish(mesh_builder *b, rt_error *err);
void mb_free(mesh_builder *b);

/* --- ray queries (object space, single precision) --- */

/* A prepared mesh names a triangle by its slot in the blocks, 4 * block +
 * lane: what mesh_intersect returns and mesh_surface takes. */
static inline uint32_t mesh_slot_tri(const mesh *m, uint32_t slot)
{
	return m->btri[slot >> 2][slot & 3]; /* its index in tri and tmat */
}
/* The corners of the triangle in a slot. */
static inline void mesh_corners(const mesh *m, uint32_t slot, vec3 c[3])
{
	const mesh_tri4 *q = &m->blk[slot >> 2];
	uint32_t l = slot & 3;
	for (int k = 0; k < 3; k++)
		c[k] = v3(q->v[3 * k][l], q->v[3 * k + 1][l], q->v[3 * k + 2][l]);
}

typedef struct mesh_ray {
	float o[3], d[3];
	float inv[3];        /* 1 / d: the slab tests */
	int kx, ky, kz;      /* watertight test: axes, kz the largest |d| */
	float sx, sy, sz;    /* shear constants: d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz] */
} mesh_ray;

void mesh_ray_make(mesh_ray *r, vec3 o, vec3 d);
/* The nearest triangle with tmin < t < *tmax: sets *tmax, *tri (its slot)
 * and the barycentric weights b[3] of its corners. A hit in a cut-out's
 * hole (mesh.cuts, mesh_cut_hole) is no hit, here and in every query
 * below but mesh_intersect_brute. */
bool mesh_intersect(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3]);
bool mesh_occluded(const mesh *m, const mesh_ray *r, float tmin, float tmax);
/* The same for a world-space ray r on an instance of m, `inv` taking world
 * space to the model's coordinates (3x4, row-major): t in (tmin, tmax) in
 * the ray's own units. The ray is traced in the model's coordinates in
 * single precision, and tmin is raised past the model's rounding (m->eps)
 * so that a ray leaving its surface does not find it again. */
bool mesh_intersect_world(const mesh *m, const double (*inv)[4], const ray *r, double tmin, double tmax, double *t,
                          uint32_t *slot, float b[3]);
/* mesh_intersect_world for a ray whose neighbours run in nearly the same
 * direction (camera rays, taken in pixel order): the same hit to the bit,
 * by copies of the walk specialised for each octant of directions, faster
 * when the octant repeats and slower when it does not (bench/README.md).
 * Embree's "coherent" intersect context is the same kind of hint. */
bool mesh_intersect_world_coherent(const mesh *m, const double (*inv)[4], const ray *r, double tmin, double tmax,
                                   double *t, uint32_t *slot, float b[3]);
bool mesh_occluded_world(const mesh *m, const double (*inv)[4], const ray *r, double tmin, double tmax);
/* The most rays mesh_intersect_world_packet takes at once. */
#define MESH_PACKET_MAX 16
/* mesh_intersect_world_coherent for rays r[0..n) (n <= MESH_PACKET_MAX)
 * at once, each in (tmin, tmax_each[i]) (tmax_each NULL: (tmin, tmax) for
 * all): bit i of *found says whether ray i hit, t[i], slot[i] and b[i]
 * what (set only for the rays that hit), the same floats as the single
 * ray's. Bit i of *tie: ray i met two triangles at exactly its nearest
 * distance, where the single ray keeps the first it meets in its own
 * order; the caller traces it alone. False when the packet is not traced
 * (the rays' directions do not share each axis's sign, a component is zero
 * or not finite, or the vector unit in use has no packet walk): then the
 * caller traces each ray alone. The rays walk the tree once, culled by
 * interval tests for the packet and their own slab tests at the leaves
 * (mesh_trace.c). */
bool mesh_intersect_world_packet(const mesh *m, const double (*inv)[4], int n, const ray *r, double tmin,
                                 double tmax, const double *tmax_each, double *t, uint32_t *slot, float (*b)[3],
                                 unsigned *found, unsigned *tie);
/* mesh_occluded_world for rays r[0..n) at once, each in (tmin, tmax[i]):
 * bit i of *occ set when something lies on ray i there (the same answers as
 * the single rays'). False when the packet is not traced, as above. */
bool mesh_occluded_world_packet(const mesh *m, const double (*inv)[4], int n, const ray *r, double tmin,
                                const double *tmax, unsigned *occ);
/* The vector unit the walk uses: AVX2 where the processor has it (one slab
 * test for a node's eight children; with AVX-512's registers where it has
 * those too), else SSE2 (two), else scalar code. Each finds the very same
 * hits. mesh_isa_force picks one for tests and benchmarks (false when the
 * machine lacks it); MESH_ISA_BEST goes back to the best one. */
typedef enum mesh_isa { MESH_ISA_SCALAR, MESH_ISA_SSE2, MESH_ISA_AVX2, MESH_ISA_AVX512, MESH_ISA_BEST } mesh_isa;
mesh_isa mesh_isa_active(void);
bool mesh_isa_force(mesh_isa isa);
/* The same walk with each leaf block tested one lane at a time in scalar
 * code (on machines without SSE2 it is the only path); tests check that it
 * finds the very same hits as the SSE path. */
bool mesh_intersect_scalar(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3]);
bool mesh_occluded_scalar(const mesh *m, const mesh_ray *r, float tmin, float tmax);
/* Builds the tree and its blocks from p and tri (mesh_prepare calls it).
 * False (err set) when out of memory or the mesh is too large, or
 * "stopped" when *cancel (NULL: never) was set. */
bool mesh_build_tree(mesh *m, const atomic_bool *cancel, rt_error *err);
/* The same without the tree, on a mesh not prepared (positions and
 * triangles as read; *tri an index in tri): the tests' reference. */
bool mesh_intersect_brute(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3]);

/* What shading needs at a hit on a prepared mesh (object space, the
 * triangle by its slot): the geometric normal (not unit: twice the
 * triangle's area long, the side its corners' order gives), the shading
 * normal (not unit either, on ng's side; ng itself for flat faces),
 * texture coordinates and the tangents along u and v (zero when there are
 * none). The caller transforms the normals first and then makes them unit,
 * once. */
typedef struct mesh_surf {
	vec3 ng, ns, dpdu, dpdv;
	double u, v;
	int mat; /* material of the file, -1 none */
	/* Smooth meshes: where rays leaving the hit should start, less the hit
	 * (object space; zero on flat faces). Hanika, "Hacking the Shadow
	 * Terminator" (Ray Tracing Gems II, 2021): the hit point moved to the
	 * tangent planes of the corners' normals, as far as it lies below them,
	 * weighted by the barycentrics, so that shadow and bounce rays leave
	 * from the smooth surface the normals describe, not from the flat
	 * triangle, whose neighbours would shadow it along the terminator. */
	vec3 shift;
} mesh_surf;
void mesh_surface(const mesh *m, uint32_t slot, const float b[3], mesh_surf *s);

/* glTF alpha coverage: true when the hit on the triangle in `slot` at
 * barycentrics b falls in a hole of its material. alpha = baseColorFactor's
 * alpha x the base colour texture's alpha at the hit's uv
 * (KHR_texture_transform, the sampler's wrap, bilinear on the finest
 * level). alphaMode MASK: a hole where alpha < alphaCutoff. BLEND: with
 * mesh_alpha_hashed on, where alpha < a number in [0, 1) hashed from the
 * hit (so a ray passes with probability 1 - alpha: stochastic
 * transparency, right on average over a pixel's samples), else as MASK at
 * 0.5. OPAQUE: never. The walk (mesh_trace.c) skips such hits, for every
 * kind of ray. */
bool mesh_cut_hole(const mesh *m, uint32_t slot, const float b[3]);
/* BLEND's hashed alpha on or off in the calling thread (off at first): the
 * renderer turns it on for the integrators that sample (path mode). */
void mesh_alpha_hashed(bool on);
/* The same for the lanes in `lanes` (a bit each) of block `blk` hit with
 * edge functions u, v, w and 1 / det inv (the walk's floats; b = u inv, v
 * inv, w inv): `lanes` less those in holes. */
unsigned mesh_cut_lanes(const mesh *m, uint32_t blk, unsigned lanes, const float u[4], const float v[4],
                        const float w[4], const float inv[4]);

#endif
