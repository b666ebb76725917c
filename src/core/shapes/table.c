/* rtsh — the shape table, solver and bounds (shape.h). */
#include "shapes.h"

#include <string.h>

const shape_kind *const shape_kinds[OBJ_KIND_COUNT] = {
#define RT_KIND(e, id, name, desc, flags) [OBJ_##e] = &desc,
#include "rtsh/kinds.def"
#undef RT_KIND
};

const shape_kind *shape_kind_of(obj_kind k)
{
	return (unsigned)k < OBJ_KIND_COUNT ? shape_kinds[k] : NULL;
}

const shape_kind *shape_kind_find(const char *id, obj_kind *k, const shape_form **form)
{
	for (int i = 0; i < OBJ_KIND_COUNT; i++) {
		const shape_kind *d = shape_kinds[i];
		const shape_form *f = strcmp(d->form.id, id) == 0                    ? &d->form
		                      : d->alias.id && strcmp(d->alias.id, id) == 0 ? &d->alias
		                                                                    : NULL;
		if (f) {
			*k = (obj_kind)i;
			*form = f;
			return d;
		}
	}
	return NULL;
}

/* The triangle is defined by its world-space vertices (tri_intersect). */
const shape_kind triangle_kind = {
	.form = {"tr", "triangle", false, false, true, 3, "P1 P2 P3",
	         {"first point", "second point", "third point"}, "ppp", NULL, NULL},
	.bounds = unit_cube_bounds,
	.recipe = {.use = true}, /* generate.c places the vertices */
};

box unit_cube_bounds(double tube)
{
	(void)tube;
	return (box){v3(-1, -1, -1), v3(1, 1, 1)};
}

box unit_flat_bounds(double tube)
{
	(void)tube;
	return (box){v3(-1, 0, -1), v3(1, 0, 1)};
}

double around_y(vec3 p, vec3 *tangent)
{
	double rho = sqrt(p.x * p.x + p.z * p.z);
	*tangent = rho > 0.0 ? v3(-p.z / rho, 0, p.x / rho) : v3(1, 0, 0);
	double u = atan2(p.z, p.x) / (2.0 * RT_PI);
	return u < 0.0 ? u + 1.0 : u;
}

void uv_flat(vec3 p, double tube, double *u, double *v, vec3 *tangent)
{
	(void)tube;
	*u = clampd(0.5 * (p.x + 1.0), 0.0, 1.0);
	*v = clampd(0.5 * (p.z + 1.0), 0.0, 1.0);
	*tangent = v3(1, 0, 0);
}

void read_uniform(object *o, const double *sizes)
{
	o->scale = v3_splat(sizes[0]);
}

bool write_uniform(const object *o, double *sizes)
{
	sizes[0] = o->scale.x;
	return o->scale.x == o->scale.y && o->scale.y == o->scale.z;
}

void read_tube(object *o, const double *sizes)
{
	o->scale = v3(sizes[0], sizes[1], sizes[0]);
}

bool write_tube(const object *o, double *sizes)
{
	sizes[0] = o->scale.x;
	sizes[1] = o->scale.y;
	return o->scale.x == o->scale.z;
}

bool solve_quadratic_half(double a, double b, double c, double *t0, double *t1)
{
	double disc = b * b - a * c;
	if (disc < 0.0 || a == 0.0)
		return false;
	/* q = -(b + sign(b) sqrt(disc)) avoids cancellation (Numerical Recipes 5.6). */
	double q = -(b + copysign(sqrt(disc), b));
	double r0 = q / a;
	double r1 = q != 0.0 ? c / q : r0;
	*t0 = fmin(r0, r1);
	*t1 = fmax(r0, r1);
	return true;
}

box shape_local_bounds(obj_kind k, double tube)
{
	return shape_kinds[k]->bounds(tube);
}

box object_bounds(const object *o)
{
	unsigned f = obj_kind_flags(o->kind);
	if (f & KIND_VERTICES)
		return box_add(box_add(box_point(o->tri[0]), o->tri[1]), o->tri[2]);
	if (f & KIND_UNBOUNDED)
		return shape_local_bounds(o->kind, o->tube);
	xform x;
	if (!object_xform(o, &x))
		return box_empty();
	return xf_box(&x, shape_local_bounds(o->kind, o->tube));
}

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
