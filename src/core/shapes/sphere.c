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

/* Equirectangular: u = 1/2 + atan2(x, -z) / 2pi, v = 1/2 + asin(y) / pi (the
 * image's middle column faces -Z, where the default camera is; north is +Y). */
static void sphere_uv(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv)
{
	(void)nl;
	(void)tube;
	double len = v3_len(q);
	vec3 s = len > 0 ? v3_scale(q, 1.0 / len) : v3(0, 1, 0);
	double c = sqrt(s.x * s.x + s.z * s.z);
	*u = 0.5 + atan2(s.x, -s.z) / (2 * M_PI);
	*v = 0.5 + asin(clampd(s.y, -1, 1)) / M_PI;
	*dqdu = v3_scale(v3(-q.z, 0, q.x), 2 * M_PI);
	*dqdv = c > 0 ? v3_scale(v3(-s.x * s.y / c, c, -s.z * s.y / c), M_PI * len) : v3(0, 0, 0);
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
