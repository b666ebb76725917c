/* rtsh — the flat bounded shapes in the plane y = 0: the disc x^2 + z^2 <= 1
 * and the rectangle |x| <= 1, |z| <= 1, both with normal +Y. */
#include "shapes.h"

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

const shape_kind disc_kind = {
	.form = {"di", "disc", false, true, false, 0, NULL, {NULL}, "", NULL, NULL},
	.intersect = disc_intersect,
	.occluded = disc_occluded,
	.bounds = unit_flat_bounds,
	.uv = uv_planar,
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
	.uv = uv_planar,
	.cost = 8,
	.recipe = {true, {50, -1, 50}, {120, 0, 120}, 0, 0},
};
