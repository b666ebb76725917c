/* rtsh — the unit cone: apex (0,1,0), base of radius 1 at y = -1, capped.
 * Its side is x^2 + z^2 = k^2 (y - 1)^2 with k = 1/2, for -1 <= y <= 1. */
#include "shapes.h"

static void side(vec3 o, vec3 d, double tt, double tmin, double *best, vec3 *n)
{
	double y = o.y + d.y * tt;
	if (!(y >= -1.0 && y <= 1.0))
		return;
	double x = o.x + d.x * tt, z = o.z + d.z * tt;
	/* The gradient of x^2 + z^2 - k^2 (y-1)^2, halved; at the apex it
	 * vanishes and the axis stands in. */
	vec3 g = v3(x, -0.25 * (y - 1.0), z);
	if (v3_len2(g) == 0.0)
		g = v3(0, 1, 0);
	shape_keep(tt, g, tmin, best, n);
}

static bool cone_intersect(vec3 o, vec3 d, double tube, double tmin, double tmax, double *t, vec3 *n)
{
	(void)tube;
	const double k2 = 0.25;
	double best = tmax;
	double oy = o.y - 1.0;
	double a = d.x * d.x + d.z * d.z - k2 * d.y * d.y;
	double b = o.x * d.x + o.z * d.z - k2 * oy * d.y;
	double c = o.x * o.x + o.z * o.z - k2 * oy * oy;
	double t0, t1;
	if (fabs(a) > 1e-12 * v3_dot(d, d)) {
		if (solve_quadratic_half(a, b, c, &t0, &t1)) {
			side(o, d, t0, tmin, &best, n);
			side(o, d, t1, tmin, &best, n);
		}
	} else if (b != 0.0) {
		/* The ray runs parallel to a generatrix: one root of 2bt + c = 0. */
		side(o, d, -c / (2.0 * b), tmin, &best, n);
	}
	if (d.y != 0.0)
		shape_cap(o, d, -1.0, tmin, &best, n);
	if (best >= tmax)
		return false;
	*t = best;
	return true;
}

static bool cone_occluded(vec3 o, vec3 d, double tube, double tmin, double tmax)
{
	(void)tube;
	double t;
	vec3 n;
	return cone_intersect(o, d, tube, tmin, tmax, &t, &n);
}

const shape_kind cone_kind = {
	.form = TUBE_FORM("co", "cone", false),
	.intersect = cone_intersect,
	.occluded = cone_occluded,
	.bounds = unit_cube_bounds,
	.uv = uv_capped_side,
	.cost = 8,
	.recipe = TUBE_RECIPE,
};
