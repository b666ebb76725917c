/* rtsh — private to the core: the emissive surfaces the path tracer samples
 * directly (emitters.c); world_build collects them, path.c samples them and
 * weighs the samples against its own paths by multiple importance sampling
 * (Veach & Guibas 1995). */
#ifndef RTSH_EMITTERS_H
#define RTSH_EMITTERS_H

#include <stdbool.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/world.h"
#include "sampler.h"

/* An emissive surface the path tracer samples directly (emitters.c): spheres
 * with a uniform scale and no shear, rectangles, discs and triangles. */
typedef enum emitter_shape {
	EMITTER_SPHERE,
	EMITTER_RECT,     /* c + a u + b v, a and b in [-1,1] */
	EMITTER_DISC,     /* the same with a^2 + b^2 <= 1 */
	EMITTER_TRIANGLE, /* c + a u + b v, a, b >= 0, a + b <= 1 */
} emitter_shape;

struct emitter {
	uint32_t object; /* the scene object (UINT32_MAX: a model's triangle) */
	uint32_t mat;    /* its material in world.mats */
	uint32_t run;    /* the first emitter of a material: the emitters of that
	                  * material from here (a model's triangles); else 1 */
	uint32_t shape;  /* emitter_shape */
	vec3 c, u, v;    /* sphere: centre; flat shapes: see emitter_shape */
	vec3 n;          /* flat shapes: unit normal */
	double r;        /* sphere radius */
	double area;     /* flat shapes */
	double reach2;   /* flat shapes: sampled by solid angle from points closer
	                  * to c than sqrt(reach2), by area beyond (0: always by
	                  * area) */
};

/* Fills w->emitters with the scene's emissive spheres, rectangles, discs
 * and triangles and points their materials at them (world_build calls it
 * last). False (err set) when out of memory. */
bool emitters_build(world *w, const scene *s, rt_error *err);

/* The emitter of material m (m->light = first) that a path met at p: the
 * one of its run whose triangle holds p (a model's lamp of several
 * triangles), else first's. */
const emitter *emitter_at(const world *w, int32_t first, vec3 p);

/* The density (per steradian) with which emitter_sample picks the
 * direction d (unit) from p towards e, whose surface it meets at distance t
 * (flat shapes); the choice of the emitter is not included. */
double emitter_pdf(const emitter *e, vec3 p, vec3 d, double t);

/* A direction *wi from p towards e made from the uniform numbers (u1, u2),
 * from the solid angle a sphere subtends (uniform in its cone) or the area
 * of a flat shape, with its density *pdf (per steradian) and the distance
 * *t to the emitter's surface along it. False when p is inside the sphere
 * or the sample is degenerate. */
bool emitter_sample(const emitter *e, vec3 p, double u1, double u2, vec3 *wi, double *pdf, double *t);

#endif
