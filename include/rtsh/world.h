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

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/math.h"
#include "rtsh/scene.h"

/* A material in linear light, as the integrators use it. */
typedef struct mat_lin {
	vec3 albedo;       /* linear colour */
	double diffuse, specular, shininess, reflective;
	double fuzz, metal, ior;
	vec3 emission;     /* emitted radiance (linear) */
	double checker;    /* squares per unit; 0 = none */
	int32_t light;     /* index into world.emitters; -1 when not sampled */
} mat_lin;

typedef struct light_lin {
	vec3 pos;
	vec3 radiance; /* ratio x linear colour */
} light_lin;

/* An emissive surface the path tracer samples directly (emitters.h). */
typedef struct emitter emitter;

/* Camera axes: forward, right and up are unit and orthogonal; a pixel's
 * ray direction is fwd + u*half_w*right + v*half_h*up with u, v in [-1,1]. */
typedef struct cam_view {
	vec3 pos, fwd, right, up;
	double tan_half; /* tan(fov / 2), horizontal */
} cam_view;

/* The traceable primitives and the BVH are the core's own (src/core/prims.h,
 * src/core/bvh.h): callers see only their counts. */
typedef struct prim prim;
typedef struct prim_shape prim_shape;
typedef struct prim_tri prim_tri;
typedef struct prim_plane prim_plane;
typedef struct bvh bvh;

typedef struct world {
	cam_view cam;
	vec3 ambient;   /* linear ambient radiance (ratio x colour) */
	bool has_sky;
	vec3 sky_zenith, sky_horizon; /* linear, already x strength */
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
	mat_lin *mats;   /* indexed by prim.object */
	size_t nmats;
	emitter *emitters; /* sampled in path mode; nemitters = 0 turns that off */
	size_t nemitters;
	bvh *tree;       /* over prims */
	box bounds;      /* of the bounded primitives */
	double eps;      /* self-intersection offset scale for this scene */
} world;

/* A ray-surface hit in world space. */
typedef struct hit {
	double t;
	vec3 p;        /* the point */
	vec3 n;        /* unit geometric normal, outward */
	vec3 local;    /* the point in object space (textures) */
	bool front;    /* the ray arrived on the outward side */
	uint32_t object;
} hit;

/* Builds the world for the scene's active camera; NULL (err set) when out of
 * memory or an object cannot be placed. The scene is not referenced after. */
world *world_build(const scene *s, rt_error *err);
void world_free(world *w);

/* Nearest hit with tmin < t < tmax. */
bool world_intersect(const world *w, const ray *r, double tmin, double tmax, hit *h);
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

/* sRGB (0..255) to linear [0,1], per channel. */
vec3 srgb255_to_linear(vec3 c);

#endif
