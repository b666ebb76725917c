/* rtsh — the unit sphere, radius 1 at the origin. */
#include "shapes.h"

#include "core/warp.h"

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

/* As a light: a sphere scaled evenly with no shear, sampled by the cone it
 * subtends. */
static bool sphere_light(const object *o, shape_light *l)
{
	for (int k = 0; k < 6; k++)
		if (o->shear[k] != 0.0)
			return false;
	if (!(o->scale.x == o->scale.y && o->scale.y == o->scale.z))
		return false;
	l->c = o->pos;
	l->r = 0.5 * o->scale.x;
	return l->r > 0.0;
}

/* 1 - cos(theta_max) of the cone that the sphere subtends from a point at
 * squared distance d2 > r^2, without cancellation for small spheres. */
static double cone_gap(double r2, double d2)
{
	double s2 = r2 / d2;
	return s2 / (1.0 + sqrt(1.0 - s2));
}

static double sphere_light_pdf(const shape_light *l, vec3 p, vec3 d, double t)
{
	(void)d;
	(void)t;
	double d2 = v3_len2(v3_sub(l->c, p)), r2 = l->r * l->r;
	return d2 > r2 ? 1.0 / (2.0 * RT_PI * cone_gap(r2, d2)) : 0.0;
}

static bool sphere_light_sample(const shape_light *l, vec3 p, double u1, double u2, vec3 *wi, double *pdf, double *t)
{
	vec3 pc = v3_sub(l->c, p);
	double d2 = v3_len2(pc), r2 = l->r * l->r;
	if (!(d2 > r2))
		return false; /* inside: left to the paths */
	double gap = cone_gap(r2, d2), cos_a = 1.0 - u1 * gap;
	double x, y;
	warp_circle(u2, &x, &y);
	double k2 = sqrt(pos(1.0 - cos_a * cos_a));
	vec3 ax = v3_scale(pc, 1.0 / sqrt(d2)), tu, tv;
	basis(ax, &tu, &tv);
	*wi = v3_add(v3_add(v3_scale(tu, x * k2), v3_scale(tv, y * k2)), v3_scale(ax, cos_a));
	*pdf = 1.0 / (2.0 * RT_PI * gap);
	/* the near side of the sphere along wi: |p + t wi - c| = r */
	double along = v3_dot(pc, *wi);
	*t = along - sqrt(pos(along * along - (d2 - r2)));
	return true;
}

const shape_kind sphere_kind = {
	.form = {"sp", "sphere", true, true, false, 2, "CENTER DIAMETER", {"center", "diameter"}, "ps",
	         read_uniform, write_uniform},
	.intersect = sphere_intersect,
	.occluded = sphere_occluded,
	.bounds = unit_cube_bounds,
	.uv = sphere_uv,
	.light = {sphere_light, sphere_light_sample, sphere_light_pdf},
	.world_sphere = true,
	.cost = 8,
	.recipe = {.use = true}, /* generate.c sizes spheres itself (the benchmark scenes) */
};
