/* rtsh — the unit capped cylinder x^2 + z^2 <= 1, -1 <= y <= 1. */
#include "shapes.h"

/* Keeps the candidate (tt, nn) when it is nearer than the best so far. */
static void keep(double tt, vec3 nn, double tmin, double *best, vec3 *n)
{
	if (tt > tmin && tt < *best) {
		*best = tt;
		*n = nn;
	}
}

static bool cylinder_intersect(vec3 o, vec3 d, double tube, double tmin, double tmax, double *t, vec3 *n)
{
	(void)tube;
	double best = tmax;
	double a = d.x * d.x + d.z * d.z;
	double t0, t1;
	if (a > 0.0 && solve_quadratic_half(a, o.x * d.x + o.z * d.z, o.x * o.x + o.z * o.z - 1.0, &t0, &t1)) {
		double y0 = o.y + d.y * t0, y1 = o.y + d.y * t1;
		if (y0 >= -1.0 && y0 <= 1.0)
			keep(t0, v3(o.x + d.x * t0, 0, o.z + d.z * t0), tmin, &best, n);
		if (y1 >= -1.0 && y1 <= 1.0)
			keep(t1, v3(o.x + d.x * t1, 0, o.z + d.z * t1), tmin, &best, n);
	}
	if (d.y != 0.0) {
		for (int s = -1; s <= 1; s += 2) {
			double tc = (s - o.y) / d.y;
			double x = o.x + d.x * tc, z = o.z + d.z * tc;
			if (x * x + z * z <= 1.0)
				keep(tc, v3(0, s, 0), tmin, &best, n);
		}
	}
	if (best >= tmax)
		return false;
	*t = best;
	return true;
}

static bool cylinder_occluded(vec3 o, vec3 d, double tube, double tmin, double tmax)
{
	(void)tube;
	double t;
	vec3 n;
	return cylinder_intersect(o, d, tube, tmin, tmax, &t, &n);
}

const shape_kind cylinder_kind = {
	.form = {"cy", "cylinder", true, true, false, 4, "CENTER AXIS DIAMETER HEIGHT",
	         {"center", "axis", "diameter", "height"}, "pdss", read_tube, write_tube},
	.intersect = cylinder_intersect,
	.occluded = cylinder_occluded,
	.bounds = unit_cube_bounds,
	.uv = uv_capped_side,
	.cost = 8,
	.recipe = {true, {40, 60, 0}, {100, 140, 0}, 0, 0},
};
