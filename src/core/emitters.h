/* rtsh — private to the core: the emissive surfaces the path tracer samples
 * directly (emitters.c); world_build collects them, path.c samples them and
 * weighs the samples against its own paths by multiple importance sampling
 * (Veach & Guibas 1995). */
#ifndef RTSH_EMITTERS_H
#define RTSH_EMITTERS_H

#include <stdbool.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/shape.h"
#include "rtsh/world.h"
#include "sampler.h"

/* An emissive object the path tracer samples directly: one whose kind
 * can (shape.h, shape_light_ops). */
struct emitter {
	uint32_t object; /* the scene object (UINT32_MAX: a model's triangle) */
	uint32_t kind;   /* its obj_kind, whose light ops sample it */
	uint32_t mat;    /* its material in world.mats */
	uint32_t run;    /* the first emitter of a material: the emitters of that
	                  * material from here (a model's triangles); else 1 */
	shape_light l;   /* its geometry in world space */
};

/* Fills w->emitters with the scene's emissive objects whose kinds sample
 * them (spheres scaled evenly, rectangles, discs and triangles) and points
 * their materials at them (world_build calls it last). False (err set)
 * when out of memory. */
bool emitters_build(world *w, const scene *s, rt_error *err);

/* The emitter of a material (first = its light) that a path met at p: the
 * one of its run whose triangle holds p (a model's lamp of several
 * triangles), else first's. */
const emitter *emitter_at(const world *w, int32_t first, vec3 p);

/* The density (per steradian) with which emitter_sample picks the
 * direction d (unit) from p towards e, whose surface it meets at distance t;
 * the choice of the emitter is not included. */
static inline double emitter_pdf(const emitter *e, vec3 p, vec3 d, double t)
{
	return shape_kinds[e->kind]->light.pdf(&e->l, p, d, t);
}

/* A direction *wi from p towards e made from the uniform numbers (u1, u2),
 * with its density *pdf (per steradian) and the distance *t to the
 * emitter's surface along it. False when there is none (p inside a sphere,
 * a degenerate sample). */
static inline bool emitter_sample(const emitter *e, vec3 p, double u1, double u2, vec3 *wi, double *pdf, double *t)
{
	return shape_kinds[e->kind]->light.sample(&e->l, p, u1, u2, wi, pdf, t);
}

#endif
