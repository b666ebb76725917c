/* rtsh — private declarations shared by the unit-shape files. */
#ifndef RTSH_SHAPES_PRIV_H
#define RTSH_SHAPES_PRIV_H

#include "rtsh/shape.h"

/* Solves a t^2 + 2 b t + c = 0 (note the half b) stably; false when there is
 * no real root. t0 <= t1. */
bool solve_quadratic_half(double a, double b, double c, double *t0, double *t1);

/* Keeps the candidate hit (tt, nn) when it lies beyond tmin and nearer than
 * the best so far (cone, cylinder). */
static inline void shape_keep(double tt, vec3 nn, double tmin, double *best, vec3 *n)
{
	if (tt > tmin && tt < *best) {
		*best = tt;
		*n = nn;
	}
}

/* The cap of radius 1 in the plane y = yc, its normal (0, yc, 0) (yc = 1 or
 * -1): kept when the ray crosses it inside the disc (d.y != 0). */
static inline void shape_cap(vec3 o, vec3 d, double yc, double tmin, double *best, vec3 *n)
{
	double tc = (yc - o.y) / d.y;
	double x = o.x + d.x * tc, z = o.z + d.z * tc;
	if (x * x + z * z <= 1.0)
		shape_keep(tc, v3(0, yc, 0), tmin, best, n);
}

/* The cube [-1,1]^3 (the bounds of most unit shapes). */
box unit_cube_bounds(double tube);
/* The square [-1,1] x {0} x [-1,1] (flat shapes). */
box unit_flat_bounds(double tube);

/* Texture coordinates (shape_kind.uv). The planar u = (x + 1) / 2,
 * v = (z + 1) / 2: the disc, the rectangle, the caps (and kinds with no uv
 * of their own). */
void uv_planar(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv);
/* The cylinder's and cone's: around the side the sphere's u and
 * v = (y + 1) / 2, the caps planar. */
void uv_capped_side(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv);

/* Lights (shape_light_ops, light.c). A flat light c + a u + b v with its
 * area set: its unit normal and reach (triangle: a, b >= 0, a + b <= 1;
 * else a parallelogram's a, b in [-1,1]); false when it is degenerate. */
bool light_flat_finish(shape_light *l, bool triangle);
/* p is close enough to l to sample it by solid angle. */
static inline bool light_near(const shape_light *l, vec3 p)
{
	return v3_len2(v3_sub(l->c, p)) < l->reach2;
}
/* The density per steradian of area sampling, direction d, distance t. */
static inline double light_area_pdf(const shape_light *l, vec3 d, double t)
{
	double cos_l = fabs(v3_dot(l->n, d));
	return cos_l > 0.0 ? t * t / (cos_l * l->area) : 0.0;
}
/* The direction from p to the point c + a u + b v of l, its distance and
 * its density by the kind's pdf; false when degenerate or of density 0. */
bool light_area_sample(const shape_light *l, vec3 p, double a, double b,
                       double (*pdf)(const shape_light *, vec3, vec3, double), vec3 *wi, double *pdf_out, double *t);
/* By the solid angle of the rectangle (u, v orthogonal) or triangle seen
 * from p: its density, or a sample (disc: from the square around it, a
 * point outside the disc has *pdf 0). False when degenerate seen from p. */
bool light_rect_solid_pdf(const shape_light *l, vec3 p, double *pdf);
bool light_rect_solid_sample(const shape_light *l, vec3 p, double u1, double u2, bool disc, vec3 *wi, double *pdf,
                             double *t);
bool light_tri_solid_pdf(const shape_light *l, vec3 p, double *pdf);
bool light_tri_solid_sample(const shape_light *l, vec3 p, double u1, double u2, vec3 *wi, double *pdf, double *t);

/* The short-form reader and writer of kinds sized by one number in every
 * direction (the sphere: DIAMETER; scale = that x 3). */
void read_uniform(object *o, const double *sizes);
bool write_uniform(const object *o, double *sizes);
/* DIAMETER HEIGHT: scale (d, h, d) (cylinder, cone). */
void read_tube(object *o, const double *sizes);
bool write_tube(const object *o, double *sizes);
/* Their short form (its id, name and whether --strict allows it) and their
 * generator recipe. */
#define TUBE_FORM(id, name, strict)                                                                               \
	{id, name, strict, true, false, 4, "CENTER AXIS DIAMETER HEIGHT", {"center", "axis", "diameter", "height"}, \
	 "pdss", read_tube, write_tube}
#define TUBE_RECIPE {true, {40, 60, 0}, {100, 140, 0}, 0, 0}

#endif
