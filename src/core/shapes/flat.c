/* rtsh — the flat bounded shapes in the plane y = 0: the disc x^2 + z^2 <= 1
 * and the rectangle |x| <= 1, |z| <= 1, both with normal +Y. Their texture coordinates are the planar
 * default (no uv). */
#include "shapes.h"

#include "core/warp.h"

static bool flat_hit(vec3 o, vec3 d, double tmin, double tmax, bool round, double *t)
{
	if (d.y == 0.0)
		return false;
	double tt = -o.y / d.y;
	if (!(tt > tmin && tt < tmax))
		return false;
	double x = o.x + d.x * tt, z = o.z + d.z * tt;
	if (round ? x * x + z * z > 1.0 : (fabs(x) > 1.0 || fabs(z) > 1.0))
		return false;
	*t = tt;
	return true;
}

static bool disc_intersect(vec3 o, vec3 d, double tube, double tmin, double tmax, double *t, vec3 *n)
{
	(void)tube;
	if (!flat_hit(o, d, tmin, tmax, true, t))
		return false;
	*n = v3(0, 1, 0);
	return true;
}

static bool disc_occluded(vec3 o, vec3 d, double tube, double tmin, double tmax)
{
	(void)tube;
	double t;
	return flat_hit(o, d, tmin, tmax, true, &t);
}

static bool rect_intersect(vec3 o, vec3 d, double tube, double tmin, double tmax, double *t, vec3 *n)
{
	(void)tube;
	if (!flat_hit(o, d, tmin, tmax, false, t))
		return false;
	*n = v3(0, 1, 0);
	return true;
}

static bool rect_occluded(vec3 o, vec3 d, double tube, double tmin, double tmax)
{
	(void)tube;
	double t;
	return flat_hit(o, d, tmin, tmax, false, &t);
}

/* sq CENTER NORMAL SIDE: scale (side, 1, side). */
static void square_read(object *o, const double *sizes)
{
	o->scale = v3(sizes[0], 1, sizes[0]);
}

static bool square_write(const object *o, double *sizes)
{
	sizes[0] = o->scale.x;
	return o->scale.x == o->scale.z && o->scale.y == 1;
}

/* As lights: the unit shape's axes X and Z carried into the world, c + a u
 * + b v with a, b in [-1,1] (the disc: a^2 + b^2 <= 1); sampled by the solid
 * angle of the rectangle (the disc: of its square) from near points
 * (light.c), by area beyond. */
static bool flat_light(const object *o, bool round, shape_light *l)
{
	xform x;
	if (!object_xform(o, &x))
		return false;
	l->c = m4_point(&x.m, v3(0, 0, 0));
	l->u = m4_vector(&x.m, v3(1, 0, 0));
	l->v = m4_vector(&x.m, v3(0, 0, 1));
	double a = v3_len(v3_cross(l->u, l->v));
	l->area = round ? RT_PI * a : 4.0 * a;
	return light_flat_finish(l, false);
}

static bool disc_light(const object *o, shape_light *l)
{
	return flat_light(o, true, l);
}

static bool rect_light(const object *o, shape_light *l)
{
	return flat_light(o, false, l);
}

/* The disc's density is its square's inside the disc. */
static double flat_light_pdf(const shape_light *l, vec3 p, vec3 d, double t)
{
	double pdf;
	if (light_near(l, p) && light_rect_solid_pdf(l, p, &pdf))
		return pdf;
	return light_area_pdf(l, d, t); /* far, or degenerate seen from p */
}

static bool rect_light_sample(const shape_light *l, vec3 p, double u1, double u2, vec3 *wi, double *pdf, double *t)
{
	if (light_near(l, p) && light_rect_solid_sample(l, p, u1, u2, false, wi, pdf, t))
		return *pdf > 0.0;
	return light_area_sample(l, p, 2.0 * u1 - 1.0, 2.0 * u2 - 1.0, flat_light_pdf, wi, pdf, t);
}

static bool disc_light_sample(const shape_light *l, vec3 p, double u1, double u2, vec3 *wi, double *pdf, double *t)
{
	if (light_near(l, p) && light_rect_solid_sample(l, p, u1, u2, true, wi, pdf, t))
		return *pdf > 0.0;
	double a, b;
	warp_disc(u1, u2, &a, &b);
	return light_area_sample(l, p, a, b, flat_light_pdf, wi, pdf, t);
}

const shape_kind disc_kind = {
	.form = {"di", "disc", false, true, false, 0, NULL, {NULL}, "", NULL, NULL},
	.intersect = disc_intersect,
	.occluded = disc_occluded,
	.bounds = unit_flat_bounds,
	.light = {disc_light, disc_light_sample, flat_light_pdf},
	.cost = 8,
	.recipe = {true, {50, -1, 0}, {100, 0, 0}, 0, 0},
};

const shape_kind rect_kind = {
	.form = {"rc", "rectangle", false, true, false, 0, NULL, {NULL}, "", NULL, NULL},
	.alias = {"sq", "square", false, false, false, 3, "CENTER NORMAL SIDE", {"center", "normal", "side"},
	          "pds", square_read, square_write},
	.intersect = rect_intersect,
	.occluded = rect_occluded,
	.bounds = unit_flat_bounds,
	.light = {rect_light, rect_light_sample, flat_light_pdf},
	.cost = 8,
	.recipe = {true, {50, -1, 50}, {120, 0, 120}, 0, 0},
};
