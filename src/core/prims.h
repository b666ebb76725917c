/* rtsh — private to the core: the layout of the traceable primitives
 * (world.c builds them, bvh.c orders them; world.h only names them). */
#ifndef RTSH_PRIMS_H
#define RTSH_PRIMS_H

#include <stdint.h>

#include "rtsh/world.h"

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
} prim_tag;

struct prim {
	uint32_t tag;    /* prim_tag */
	uint32_t object; /* index into the scene's objects */
	union {
		struct {
			vec3 c;
			double r;
		} sph;
		uint32_t index;
	} u;
};

struct prim_shape {
	double inv[3][4]; /* world -> object (the last row is 0 0 0 1) */
	uint32_t kind;    /* obj_kind */
	double tube;      /* object.tube (the torus) */
};

struct prim_tri {
	vec3 v0, e1, e2;
};

/* An unbounded plane, tested beside the tree in world space: its object-space
 * height is y = h[0] x + h[1] y + h[2] z + h[3] (row 1 of its world-to-object
 * matrix, so the test is bit for bit the unit plane's). */
struct prim_plane {
	double h[4];
	vec3 n;         /* the unit normal */
	uint32_t object;
	uint32_t shape; /* its matrix in world.shapes (texture coordinates) */
};

#endif
