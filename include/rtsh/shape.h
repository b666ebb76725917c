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
 *   torus     see torus.c
 *   triangle  in world space (its own vertices), Moller-Trumbore
 */
#ifndef RTSH_SHAPE_H
#define RTSH_SHAPE_H

#include <stdbool.h>

#include "rtsh/math.h"
#include "rtsh/scene.h"

/* A form of a kind's .rt line: the identifier, the fields of its short
 * (42) form between the identifier and R,G,B, and whether the extended form
 * `ID POS ROT SCALE R,G,B ...` is read under the same identifier. */
typedef struct shape_form {
	const char *id;        /* "sp"; NULL: no such form (a kind's own form is NULL
	                        * when the reader has an element of its own for it: mesh) */
	const char *name;      /* in messages: "sphere" */
	bool strict;           /* allowed by --strict (the 42 subject's elements) */
	bool extended;         /* ID POS ROT SCALE ... is read under this id too */
	bool material;         /* [DIFFUSE SPECULAR SHININESS REFLECTIVE] may follow R,G,B */
	int nfields;           /* fields of the short form; 0: none */
	const char *usage;     /* those fields for usage lines: "CENTER DIAMETER" */
	const char *fields[4]; /* their names in messages: "center", "diameter" */
	const char *types;     /* one letter a field: p point, d direction (-> dir),
	                        * s size > 0 (a 0 leaves the object out, with a warning) */
	/* The object's scale (and tube) from the sizes, in order. */
	void (*read)(object *o, const double *sizes);
	/* The sizes that read back to exactly o's; false when the short form
	 * cannot say o (the writer then uses the extended form). */
	bool (*write)(const object *o, double *sizes);
} shape_form;

/* How the random generator (generate.c) sizes a kind: per axis x, y, z, a
 * share of the typical size in percent, uniform in [lo, hi]; lo = 0 copies
 * axis `hi` (0 x, 1 y) instead, lo = -1 fixes the axis at 1. Axes are drawn
 * in order x, y, z. tube_lo..tube_hi (percent, 0: none) draws object.tube. */
typedef struct shape_recipe {
	bool use;              /* generated at all */
	short lo[3], hi[3];
	short tube_lo, tube_hi;
} shape_recipe;

/* An emissive object of one kind in world space, as its kind samples it
 * for the path tracer's direct lighting (emitters.c, path.c). */
typedef struct shape_light {
	vec3 c, u, v;  /* sphere: the centre; flat kinds: c + a u + b v, their
	                * kind saying which a and b */
	vec3 n;        /* flat kinds: the unit normal */
	double r;      /* sphere: the radius */
	double area;   /* flat kinds */
	double reach2; /* flat kinds: sampled by the solid angle they subtend from
	                * points closer to c than sqrt(reach2), by area beyond
	                * (0: always by area) */
} shape_light;

/* How a kind's emissive objects are sampled directly (all NULL: they are
 * found by the paths only). Multiple importance sampling (Veach & Guibas
 * 1995) weighs these samples against the paths', so pdf must be the
 * density sample draws with. */
typedef struct shape_light_ops {
	/* o's light in world space; false when o is not sampled directly (a
	 * sphere scaled unevenly, a degenerate shape): found by the paths only. */
	bool (*make)(const object *o, shape_light *l);
	/* A direction *wi from p towards l from the uniform numbers (u1, u2),
	 * its density *pdf per steradian and the distance *t to l along it;
	 * false when there is none (p inside a sphere, a degenerate sample). */
	bool (*sample)(const shape_light *l, vec3 p, double u1, double u2, vec3 *wi, double *pdf, double *t);
	/* The density per steradian with which sample picks the unit direction
	 * d from p, meeting l at distance t. */
	double (*pdf)(const shape_light *l, vec3 p, vec3 d, double t);
} shape_light_ops;

/* One kind of shape (kinds.def names it, its geometry file defines it). */
typedef struct shape_kind {
	shape_form form;   /* the kind's own identifier */
	shape_form alias;  /* another identifier with its own short form ("sq"), or id NULL */
	/* Nearest hit with tmin < t < tmax in object space: sets *t and the
	 * outward object-space normal *n (not normalised). `tube` is the
	 * object's tube ratio (kinds with KIND_TUBE; others ignore it). NULL for
	 * KIND_VERTICES (tri_intersect) and KIND_MODEL (mesh.h, surface.c). */
	bool (*intersect)(vec3 o, vec3 d, double tube, double tmin, double tmax, double *t, vec3 *n);
	/* Any hit with tmin < t < tmax (shadow rays). */
	bool (*occluded)(vec3 o, vec3 d, double tube, double tmin, double tmax);
	/* The object-space bounds (within [-1,1]^3; infinite when unbounded). */
	box (*bounds)(double tube);
	/* The texture coordinates (rtsh(5), "Texture coordinates") at the
	 * object-space point q of the surface, whose object-space normal there
	 * is nl (as intersect gave it, not normalised): u and v before uvscale
	 * and uvoffset, and the object-space tangents dq/du and dq/dv (normal
	 * and bump maps). NULL: the disc's planar u = (x + 1) / 2, v = (z + 1) / 2
	 * (uv_planar). */
	void (*uv)(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv);
	/* Emissive objects of the kind sampled as lights (path mode). */
	shape_light_ops light;
	/* Traced in world space from its centre and radius when its scale is
	 * uniform with no shear or texture (the sphere). */
	bool world_sphere;
	/* What its test costs, relative to a world-space sphere, for the
	 * BVH's surface area heuristic (a matrix, a call and the test: 8 for
	 * the quadrics and slabs, measured for issue 5). */
	float cost;
	shape_recipe recipe;
} shape_kind;

#define RT_KIND(e, id, name, desc, flags) extern const shape_kind desc;
#include "rtsh/kinds.def"
#undef RT_KIND

/* The descriptors, indexed by obj_kind (from kinds.def). */
extern const shape_kind *const shape_kinds[OBJ_KIND_COUNT];
/* The descriptor of kind k; NULL when k is not a kind. */
const shape_kind *shape_kind_of(obj_kind k);
/* The kind whose form (or alias) has the identifier id, and that form;
 * NULL if none. */
const shape_kind *shape_kind_find(const char *id, obj_kind *k, const shape_form **form);

/* The texture coordinates of kind k at the object-space point q with the
 * object-space normal nl: its uv, or the planar ones when it has none. */
void shape_uv(obj_kind k, vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv);

/* The unit shape's object-space bounds (all of them fit [-1,1]^3). */
box shape_local_bounds(obj_kind k, double tube);

/* Triangle v0 v1 v2 (world space): nearest hit; *n = (v1-v0) x (v2-v0). */
bool tri_intersect(vec3 v0, vec3 e1, vec3 e2, vec3 o, vec3 d, double tmin, double tmax, double *t);

/* World bounds of an object (plane: an infinite box). */
box object_bounds(const object *o);

#endif
