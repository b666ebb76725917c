/* rtsh — what the shape files share (shapes.h): the usual bounds, surface
 * texture coordinates and short forms, and the stable quadratic. */
#include "shapes.h"

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

void uv_planar(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv)
{
	(void)nl;
	(void)tube;
	*u = (q.x + 1) / 2;
	*v = (q.z + 1) / 2;
	*dqdu = v3(2, 0, 0);
	*dqdv = v3(0, 0, 2);
}

void uv_capped_side(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv)
{
	double ax = fabs(nl.x), ay = fabs(nl.y), az = fabs(nl.z);
	if (ay > fmax(ax, az) * 4 && fabs(q.y) > 0.999) {
		uv_planar(q, nl, tube, u, v, dqdu, dqdv);
		return;
	}
	*u = 0.5 + atan2(q.x, -q.z) / (2 * M_PI);
	*v = (q.y + 1) / 2;
	*dqdu = v3_scale(v3(-q.z, 0, q.x), 2 * M_PI);
	*dqdv = v3(0, 2, 0);
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
