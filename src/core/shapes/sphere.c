/* rtsh — the unit sphere, radius 1 at the origin. */
#include "shapes.h"

bool sphere_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n)
{
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

bool sphere_occluded(vec3 o, vec3 d, double tmin, double tmax)
{
	double t0, t1;
	if (!solve_quadratic_half(v3_dot(d, d), v3_dot(o, d), v3_dot(o, o) - 1.0, &t0, &t1))
		return false;
	return (t0 > tmin && t0 < tmax) || (t1 > tmin && t1 < tmax);
}
