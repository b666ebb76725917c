/* rtsh — the shape table, solver and bounds (shape.h). */
#include "shapes.h"

#include "rtsh/world.h"

const shape_ops shape_table[OBJ_KIND_COUNT] = {
	[OBJ_SPHERE] = {sphere_intersect, sphere_occluded, true},
	[OBJ_PLANE] = {plane_intersect, plane_occluded, false},
	[OBJ_CYLINDER] = {cylinder_intersect, cylinder_occluded, true},
	[OBJ_CONE] = {cone_intersect, cone_occluded, true},
	[OBJ_CUBE] = {cube_intersect, cube_occluded, true},
	[OBJ_DISC] = {disc_intersect, disc_occluded, true},
	[OBJ_RECT] = {rect_intersect, rect_occluded, true},
	[OBJ_TRIANGLE] = {NULL, NULL, true},
};

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

box shape_local_bounds(obj_kind k)
{
	switch (k) {
	case OBJ_PLANE:
		return (box){v3_splat(-INFINITY), v3_splat(INFINITY)};
	case OBJ_DISC:
	case OBJ_RECT:
		return (box){v3(-1, 0, -1), v3(1, 0, 1)};
	default:
		return (box){v3(-1, -1, -1), v3(1, 1, 1)};
	}
}

box object_bounds(const object *o)
{
	if (o->kind == OBJ_TRIANGLE)
		return box_add(box_add(box_point(o->tri[0]), o->tri[1]), o->tri[2]);
	if (o->kind == OBJ_PLANE)
		return shape_local_bounds(OBJ_PLANE);
	xform x;
	if (!object_xform(o, &x))
		return box_empty();
	return xf_box(&x, shape_local_bounds(o->kind));
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
