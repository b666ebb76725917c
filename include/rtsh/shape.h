/* rtsh — the unit shapes, intersected in object space.
 *
 * Every shape but the triangle is defined once, at unit size, centred on the
 * origin with its axis along +Y; an object's transform (scene.h,
 * object_xform) places it. A ray is carried into object space by the
 * inverse transform (its direction is not renormalised, so the ray
 * parameter t is the same in both spaces), the unit shape is hit there and
 * the normal comes back by the inverse transpose.
 *
 *   sphere    radius 1
 *   plane     y = 0, normal +Y, unbounded
 *   cylinder  x^2 + z^2 <= 1, -1 <= y <= 1, capped
 *   cone      apex (0,1,0), base radius 1 at y = -1, capped at the base
 *   cube      [-1,1]^3
 *   disc      y = 0, x^2 + z^2 <= 1
 *   rect      y = 0, |x| <= 1, |z| <= 1
 *   triangle  in world space (its own vertices), Moller-Trumbore
 */
#ifndef RTSH_SHAPE_H
#define RTSH_SHAPE_H

#include <stdbool.h>

#include "rtsh/math.h"
#include "rtsh/scene.h"

typedef struct shape_ops {
	/* Nearest hit with tmin < t < tmax: sets *t and the outward object-space
	 * normal *n (not normalised). */
	bool (*intersect)(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n);
	/* Any hit with tmin < t < tmax (shadow rays). */
	bool (*occluded)(vec3 o, vec3 d, double tmin, double tmax);
	bool bounded; /* false for the plane */
} shape_ops;

/* Indexed by obj_kind; the triangle's entry is unused (see tri_*). */
extern const shape_ops shape_table[OBJ_KIND_COUNT];

/* The unit shape's object-space bounds (all of them fit [-1,1]^3). */
box shape_local_bounds(obj_kind k);

/* Triangle v0 v1 v2 (world space): nearest hit; *n = (v1-v0) x (v2-v0). */
bool tri_intersect(vec3 v0, vec3 e1, vec3 e2, vec3 o, vec3 d, double tmin, double tmax, double *t);

/* World bounds of an object (plane: an infinite box). */
box object_bounds(const object *o);

#endif
