/* rtsh — the triangle, defined by its world-space vertices (no unit shape):
 * its intersection, and its sampling as a light. */
#include "shapes.h"

bool tri_intersect(vec3 v0, vec3 e1, vec3 e2, vec3 o, vec3 d, double tmin, double tmax, double *t)
{
	/* Moller & Trumbore, "Fast, minimum storage ray/triangle intersection", 1997. */
	vec3 p = v3_cross(d, e2);
	double det = v3_dot(e1, p);
	if (det == 0.0)
		return false;
	double inv = 1.0 / det;
	vec3 s = v3_sub(o, v0);
	double u = v3_dot(s, p) * inv;
	if (u < 0.0 || u > 1.0)
		return false;
	vec3 q = v3_cross(s, e1);
	double v = v3_dot(d, q) * inv;
	if (v < 0.0 || u + v > 1.0)
		return false;
	double tt = v3_dot(e2, q) * inv;
	if (!(tt > tmin && tt < tmax))
		return false;
	*t = tt;
	return true;
}

/* As a light: v0 + a e1 + b e2 with a, b >= 0, a + b <= 1; sampled by its
 * solid angle from near points (light.c), uniformly by area beyond. */
static bool triangle_light(const object *o, shape_light *l)
{
	l->c = o->tri[0];
	l->u = v3_sub(o->tri[1], o->tri[0]);
	l->v = v3_sub(o->tri[2], o->tri[0]);
	l->area = 0.5 * v3_len(v3_cross(l->u, l->v));
	return light_flat_finish(l, true);
}

static double triangle_light_pdf(const shape_light *l, vec3 p, vec3 d, double t)
{
	double pdf;
	if (light_near(l, p) && light_tri_solid_pdf(l, p, &pdf))
		return pdf;
	return light_area_pdf(l, d, t); /* far, or degenerate seen from p */
}

static bool triangle_light_sample(const shape_light *l, vec3 p, double u1, double u2, vec3 *wi, double *pdf,
                                  double *t)
{
	if (light_near(l, p) && light_tri_solid_sample(l, p, u1, u2, wi, pdf, t))
		return *pdf > 0.0;
	/* uniform on the triangle (Turk, Graphics Gems 1990) */
	double su = sqrt(u1);
	return light_area_sample(l, p, 1.0 - su, u2 * su, triangle_light_pdf, wi, pdf, t);
}

/* The triangle is defined by its world-space vertices (tri_intersect). */
const shape_kind triangle_kind = {
	.form = {"tr", "triangle", false, false, true, 3, "P1 P2 P3",
	         {"first point", "second point", "third point"}, "ppp", NULL, NULL},
	.bounds = unit_cube_bounds,
	.light = {triangle_light, triangle_light_sample, triangle_light_pdf},
	.recipe = {.use = true}, /* generate.c places the vertices */
};
