/* rtsh — what the shape files share (shapes.h): the usual bounds, surface
 * parameterisations and short forms, and the stable quadratic. */
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
