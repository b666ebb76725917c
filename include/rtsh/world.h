/* rtsh — the prepared world: a scene made ready to trace.
 *
 * world_build derives, from a scene model, everything the integrators need:
 * unit camera axes, linear-light colours, per-object inverse transforms and
 * a bounding volume hierarchy (bvh.c). A world is immutable once built and
 * may be shared by any number of render threads. After an edit the front end
 * builds a new world (or the BVH is refitted); the scene model stays the
 * single source of truth.
 */
#ifndef RTSH_WORLD_H
#define RTSH_WORLD_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/math.h"
#include "rtsh/scene.h"
#include "rtsh/srgb.h" /* srgb255_to_linear: scene colours */

/* The material families (material.c): each gives its BSDF, pdf, sampling,
 * albedo and Whitted shading; the integrators never look further. Zero is
 * the seeds' Phong family, so a zeroed mat_lin is a Phong material. */
enum { MAT_PHONG = 0, MAT_PBR = 1, MAT_FAMILY_COUNT };

/* A material in linear light, as the integrators use it. */
typedef struct mat_lin {
	vec3 albedo;       /* linear colour (PBR: the base colour) */
	double ior;        /* Phong: 0 opaque, else glass; PBR: the dielectric's index (1.5 when absent) */
	vec3 emission;     /* emitted radiance (linear) */
	double checker;    /* squares per unit; 0 = none */
	int32_t light;     /* index into world.emitters; -1 when not sampled */
	uint8_t family;    /* MAT_PHONG or MAT_PBR */
	bool thin;         /* PBR: thin-walled transmission */
	const struct mat_tex *tx; /* textures, or NULL (most materials): 8 bytes here */
	union {
		struct { /* the seeds' Phong family (rtsh(5)) */
			double diffuse, specular, shininess, reflective;
			double fuzz, metal;
		};
		struct mat_pbr_lin { /* the PBR family (glTF 2.0 metallic-roughness, scene.h) */
			float roughness;  /* perceptual, [0,1]; GGX alpha = roughness^2 */
			float metallic, transmission; /* [0,1] */
			float clearcoat, clearcoat_roughness; /* [0,1] */
			float specular_factor;   /* [0,1] KHR_materials_specular specularFactor */
			float specular_color[3]; /* linear, its specularColorFactor */
			float sigma_a[3]; /* volume absorption per scene unit, -ln(att colour) / att distance; 0 none */
			bool single;      /* multiscatter=0: no energy compensation */
			bool es_ready;    /* es_avg is set (mat_lin_make); else bsdf_make computes it */
			float es_avg;     /* the plastic's specular layer's hemispherical albedo (bsdf_pbr.c) */
		} pbr;
	};
} mat_lin;

/* The linear material of a scene material (emission = emit x emit_color or
 * colour; a PBR material's absent roughness is 1, its absent ior 1.5). A
 * reader of another format (glTF) fills a `material` and calls this. */
mat_lin mat_lin_make(const material *m);

/* The textures of a material (texture.h; NULL = none), held by the world. */
typedef struct mat_tex {
	const struct texture *tex, *nmap, *bump;
	const struct texture *mr; /* PBR: glTF's metallic-roughness texture (linear; G x roughness, B x metallic) */
	const struct texture *emit; /* glTF's emissive texture (sRGB), x the emission; such a material is not sampled as a light */
	bool tint;         /* tex x albedo (texture= with a colour); else tex alone */
	double bumpscale;
	double uvs[2], uvo[2]; /* uv x uvs + uvo */
	double uvx[2];     /* and the cross terms: u' += uvx[0] v, v' += uvx[1] u (a glTF rotation; 0 none) */
} mat_tex;

typedef struct light_lin {
	vec3 pos;
	vec3 radiance; /* ratio x linear colour; physical lights: ratio x intensity x colour / pi */
	int kind;      /* LIGHT_* (scene.h) */
	vec3 dir;      /* spot, sun: unit, where it shines */
	double cos_outer, cone_scale; /* spot: glTF's smooth cone (KHR_lights_punctual) */
	double range;  /* point, spot: 0 none */
} light_lin;

/* What light l sends to the point p: the direction *wi to it and its
 * distance *dist (INFINITY for a sun), and the radiance L for which the
 * irradiance at normal incidence is pi L (the miniRT convention: a white
 * Lambertian surface facing a miniRT light sends back ratio x colour). A
 * physical light's irradiance follows the inverse-square law: I / d^2
 * for I candela (times the spot's cone and the range window), E for a sun
 * of E lux. Zero when p gets nothing (behind a spot's cone, at the light). */
static inline vec3 light_at(const light_lin *l, vec3 p, vec3 *wi, double *dist)
{
	if (l->kind == LIGHT_SUN) {
		*wi = v3_neg(l->dir);
		*dist = INFINITY;
		return l->radiance;
	}
	vec3 to = v3_sub(l->pos, p);
	double d2 = v3_dot(to, to), d = sqrt(d2);
	*dist = d;
	*wi = v3(0, 1, 0);
	if (!(d > 0.0))
		return v3(0, 0, 0);
	*wi = v3_scale(to, 1.0 / d);
	if (l->kind == LIGHT_MINIRT)
		return l->radiance;
	double f = 1.0 / d2;
	if (l->range > 0) { /* glTF's recommended window: (1 - (d / range)^4) clamped, squared */
		double q = d / l->range, w = 1.0 - q * q * q * q;
		f *= w > 0 ? w * w : 0;
	}
	if (l->kind == LIGHT_SPOT) {
		double a = (v3_dot(l->dir, v3_neg(*wi)) - l->cos_outer) * l->cone_scale;
		a = a < 0 ? 0 : a > 1 ? 1 : a;
		f *= a * a;
	}
	return v3_scale(l->radiance, f);
}

/* An emissive surface the path tracer samples directly (emitters.h). */
typedef struct emitter emitter;

/* Camera axes: forward, right and up are unit and orthogonal; a pixel's
 * ray direction is fwd + u*half_w*right + v*half_h*up with u, v in [-1,1]. */
typedef struct cam_view {
	vec3 pos, fwd, right, up;
	double tan_half; /* tan(fov / 2), horizontal (vertical when `vertical`) */
	bool vertical;   /* camera.vertical: the fov is the vertical angle */
	double ortho;    /* > 0: orthographic, this half height (camera.ortho) */
} cam_view;

/* tan(horizontal fov / 2) of c on a w x h image; 0 for an orthographic view. */
static inline double cam_tan_x(const cam_view *c, int w, int h)
{
	if (c->ortho > 0)
		return 0;
	return c->vertical ? c->tan_half * w / h : c->tan_half;
}

/* Float or double (measured for issue 5; figures in bench/README.md): rays,
 * primitives and hits are double, as math.h explains. The BVH (bvh.h) keeps
 * its boxes as floats rounded outward, and the slab tests run in single
 * precision with conservative rounding (world.c), four children at a time in
 * one SSE register: with double math the same walk was 10-50% slower (the
 * float-to-double conversions, or twice the node memory), and float halves
 * the tree's memory. Far from the origin float boxes grow coarse (at 2^31 a
 * float step is 256 units): the tree then visits more, but never misses.
 *
 * One traceable primitive, 40 bytes (see world.c). A sphere with a uniform
 * scale and no shear is traced in world space from its centre and radius;
 * every other shape keeps its world-to-object matrix, and a triangle its
 * vertex and edges, in the side arrays `shapes` and `tris` (in the order of
 * the primitives that use them), so that the records the tree walks over
 * stay small. */
typedef enum prim_tag {
	PRIM_SPHERE,   /* u.sph */
	PRIM_TRIANGLE, /* u.index into world.tris */
	PRIM_SHAPE,    /* u.index into world.shapes: a unit shape and its matrix */
	PRIM_MESH,     /* u.index into world.insts: a mesh instance */
} prim_tag;

typedef struct prim {
	uint32_t tag;    /* prim_tag */
	uint32_t object; /* index into the scene's objects */
	union {
		struct {
			vec3 c;
			double r;
		} sph;
		uint32_t index;
	} u;
} prim;

typedef struct prim_shape {
	double inv[3][4]; /* world -> object (the last row is 0 0 0 1) */
	uint32_t kind;    /* obj_kind */
	double tube;      /* object.tube (the torus) */
} prim_shape;

typedef struct prim_tri {
	vec3 v0, e1, e2;
} prim_tri;

/* An unbounded plane, tested beside the tree in world space: its object-space
 * height is y = h[0] x + h[1] y + h[2] z + h[3] (row 1 of its world-to-object
 * matrix, so the test is bit for bit the unit plane's). */
typedef struct prim_plane {
	double h[4];
	vec3 n;         /* the unit normal */
	uint32_t object;
	uint32_t shape; /* its matrix in world.shapes (texture coordinates) */
} prim_plane;

/* An instance of a shared mesh (mesh.h): O(1) memory however many
 * triangles it has. `inv` takes world space to the mesh file's own
 * coordinates (the object's transform after the mesh's bounding box is
 * centred and its longest side scaled to 2, the unit shapes' size), `fwd`
 * back. Sub-materials of the file are mats[mat_base + i]. */
typedef struct prim_inst {
	double inv[3][4], fwd[3][4];
	const struct mesh *mesh;
	uint32_t mat_base;   /* UINT32_MAX: the object's own material */
} prim_inst;

typedef struct bvh bvh;

typedef struct world {
	cam_view cam;
	vec3 ambient;   /* linear ambient radiance (ratio x colour) */
	bool has_sky;
	vec3 sky_zenith, sky_horizon; /* linear, already x strength */
	const struct envmap *env; /* an HDR sky (envmap.h), or NULL */
	light_lin *lights;
	size_t nlights;
	prim *prims;     /* bounded primitives, in BVH order */
	size_t nprims;
	prim_plane *planes; /* unbounded primitives, tested beside the tree */
	size_t nplanes;
	prim_shape *shapes; /* of the PRIM_SHAPE primitives and planes */
	size_t nshapes;
	prim_tri *tris;  /* of the PRIM_TRIANGLE primitives */
	size_t ntris;
	prim_inst *insts; /* of the PRIM_MESH primitives */
	size_t ninsts;
	struct mesh **meshes; /* the distinct meshes the instances share (held) */
	size_t nmeshes;
	struct texture **texs; /* the textures the materials use (held) */
	size_t ntexs;
	mat_tex *mtex;   /* what mat_lin.tx points to */
	size_t nmtex;
	mat_lin *mats;   /* indexed by prim.object */
	size_t nmats;
	emitter *emitters; /* sampled in path mode; nemitters = 0 turns that off */
	size_t nemitters;
	bvh *tree;       /* over prims */
	box bounds;      /* of the bounded primitives */
	double eps;      /* self-intersection offset scale for this scene */
	atomic_long refs; /* references (world_retain / world_release) */
	const atomic_bool *cancel; /* while world_build runs: its flag (NULL: none) */
} world;

/* A ray-surface hit in world space. */
typedef struct hit {
	double t;
	vec3 p;        /* the point */
	vec3 n;        /* unit geometric normal, outward */
	vec3 local;    /* the point in object space (textures) */
	bool front;    /* the ray arrived on the outward side (of the geometric normal) */
	uint32_t object;
	uint32_t mat;  /* index into world.mats (the object's, or a model's own) */
	bool has_uv;   /* u, v, dpdu, dpdv are set */
	double u, v;   /* texture coordinates, uvscale/uvoffset applied */
	vec3 dpdu, dpdv; /* world-space change of the point per unit u and v */
} hit;

/* Builds the world for the scene's active camera; NULL (err set) when out of
 * memory or an object cannot be placed. The scene is not referenced after.
 * The caller holds the one reference. */
world *world_build(const scene *s, rt_error *err);
/* world_build that stops, NULL with err "stopped", soon after *cancel is set
 * (NULL: never): between objects, in a model's normals and tree, in the
 * BVH (Ctrl-C in the shell). */
world *world_build_cancel(const scene *s, const atomic_bool *cancel, rt_error *err);
/* world_build_cancel whose tree is built by up to `threads` threads (the
 * two halves below its top nodes at once: the same world, to the byte, for
 * any count; 1 or less: the calling thread alone). */
world *world_build_threads(const scene *s, int threads, const atomic_bool *cancel, rt_error *err);
/* Worlds are reference-counted, so that no thread renders from a world
 * another may free: whoever keeps a world beyond a call (a render thread, a
 * cache, key mode) holds a reference. world_retain takes one more and
 * returns w; world_release drops one and frees the world with the last.
 * Both are thread-safe and take NULL. */
const world *world_retain(const world *w);
void world_release(const world *w);
/* world_release: for the one owner that built the world. */
void world_free(world *w);

/* Nearest hit with tmin < t < tmax. */
bool world_intersect(const world *w, const ray *r, double tmin, double tmax, hit *h);
/* The same hit, for camera rays traced in pixel order: a model's walk
 * takes its copies specialised by the direction's octant, which repeats
 * from one camera ray to the next (mesh_intersect_world_coherent). */
bool world_intersect_coherent(const world *w, const ray *r, double tmin, double tmax, hit *h);
/* world_intersect in its two stages. world_trace finds the nearest hit:
 * its distance, primitive and what the primitive's test left (a shape's
 * normal in its own space; on a model, the triangle and its barycentric
 * weights), what a ray-tracing kernel such as Embree's rtcIntersect1
 * returns; world_finish makes the hit record shading needs from it (point,
 * unit normals, side, object-space point, material, texture coordinates).
 * world_trace_ng is the hit's geometric normal in world space, not unit
 * (Embree's Ng). The benchmark times both stages (bench/README.md). */
typedef struct trace_hit {
	double t;
	const prim *prim;        /* NULL when the hit is on a plane */
	const prim_plane *plane; /* NULL when on a primitive */
	vec3 nl;
} trace_hit;
bool world_trace(const world *w, const ray *r, double tmin, double tmax, trace_hit *th);
bool world_trace_coherent(const world *w, const ray *r, double tmin, double tmax, trace_hit *th);
void world_finish(const world *w, const ray *r, const trace_hit *th, hit *h);
vec3 world_trace_ng(const world *w, const ray *r, const trace_hit *th);
/* Any hit with tmin < t < tmax (shadow rays). */
bool world_occluded(const world *w, const ray *r, double tmin, double tmax);
/* The same queries without the tree: every primitive tested (tests, bench). */
bool world_intersect_brute(const world *w, const ray *r, double tmin, double tmax, hit *h);
bool world_occluded_brute(const world *w, const ray *r, double tmin, double tmax);

/* Camera axes for c; the image's aspect is applied per ray. */
cam_view cam_view_make(const camera *c);
/* The primary ray through the image point (fx, fy) in pixels of a w x h
 * image, (0,0) the top-left corner, (w,h) the bottom-right. */
ray cam_ray(const cam_view *c, double fx, double fy, int w, int h);
/* cam_ray through the centre of each pixel of the block [x0, x1) x [y0, y1)
 * of a w x h image, row by row, into r[0 .. (x1-x0)(y1-y0)): the same rays to
 * the bit, made faster (the render's packets, the packet rows of bench). */
#define CAM_BLOCK_MAX 16
void cam_block_rays(const cam_view *c, int x0, int y0, int x1, int y1, int w, int h, ray *r);

/* For the benchmark (bench/bench.c) and rtsh-mpi's counts: the rays
 * world_intersect and world_occluded traced in the calling thread since the
 * last reset (a thread-local count, so no cache line is shared between
 * threads), and the bytes a world holds beyond its struct. */
void world_rays_reset(void);
uint64_t world_rays_traced(void);
size_t world_memory(const world *w);

#endif
