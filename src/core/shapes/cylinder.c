/* rtsh — the unit capped cylinder x^2 + z^2 <= 1, -1 <= y <= 1. */
#include "shapes.h"

static bool cylinder_intersect(vec3 o, vec3 d, double tube, double tmin, double tmax, double *t, vec3 *n)
{
	(void)tube;
	double best = tmax;
	double a = d.x * d.x + d.z * d.z;
	double t0, t1;
	if (a > 0.0 && solve_quadratic_half(a, o.x * d.x + o.z * d.z, o.x * o.x + o.z * o.z - 1.0, &t0, &t1)) {
		double y0 = o.y + d.y * t0, y1 = o.y + d.y * t1;
		if (y0 >= -1.0 && y0 <= 1.0)
			shape_keep(t0, v3(o.x + d.x * t0, 0, o.z + d.z * t0), tmin, &best, n);
		if (y1 >= -1.0 && y1 <= 1.0)
			shape_keep(t1, v3(o.x + d.x * t1, 0, o.z + d.z * t1), tmin, &best, n);
	}
	if (d.y != 0.0) {
		shape_cap(o, d, -1.0, tmin, &best, n);
		shape_cap(o, d, 1.0, tmin, &best, n);
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
	.form = TUBE_FORM("cy", "cylinder", true),
	.intersect = cylinder_intersect,
	.occluded = cylinder_occluded,
	.bounds = unit_cube_bounds,
	.uv = uv_capped_side,
	.cost = 8,
	.recipe = TUBE_RECIPE,
};
