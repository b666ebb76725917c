/* rtsh — the unit sphere, radius 1 at the origin. */
#include "shapes.h"

static bool sphere_intersect(vec3 o, vec3 d, double tube, double tmin, double tmax, double *t, vec3 *n)
{
	(void)tube;
	double t0, t1;
	if (!solve_quadratic_half(v3_dot(d, d), v3_dot(o, d), v3_dot(o, o) - 1.0, &t0, &t1))
		return false;
	double tt = t0 > tmin ? t0 : t1;
	if (!(tt > tmin && tt < tmax))
		return false;
	*t = tt;
	*n = v3_madd(o, d, tt);
	return true;
}

static bool sphere_occluded(vec3 o, vec3 d, double tube, double tmin, double tmax)
{
	(void)tube;
	double t0, t1;
	if (!solve_quadratic_half(v3_dot(d, d), v3_dot(o, d), v3_dot(o, o) - 1.0, &t0, &t1))
		return false;
	return (t0 > tmin && t0 < tmax) || (t1 > tmin && t1 < tmax);
}

static void sphere_uv(vec3 p, double tube, double *u, double *v, vec3 *tangent)
{
	(void)tube;
	*u = around_y(p, tangent);
	double l = v3_len(p);
	*v = l > 0.0 ? 0.5 + asin(clampd(p.y / l, -1.0, 1.0)) / RT_PI : 0.5;
}

const shape_kind sphere_kind = {
	.form = {"sp", "sphere", true, true, false, 2, "CENTER DIAMETER", {"center", "diameter"}, "ps",
	         read_uniform, write_uniform},
	.intersect = sphere_intersect,
	.occluded = sphere_occluded,
	.bounds = unit_cube_bounds,
	.uv = sphere_uv,
	.world_sphere = true,
	.cost = 8,
	.recipe = {.use = true}, /* generate.c sizes spheres itself (the benchmark scenes) */
};
