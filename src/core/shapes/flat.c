/* rtsh — the flat bounded shapes in the plane y = 0: the disc x^2 + z^2 <= 1
 * and the rectangle |x| <= 1, |z| <= 1, both with normal +Y. */
#include "shapes.h"

static bool flat_hit(vec3 o, vec3 d, double tmin, double tmax, bool round, double *t)
{
	if (d.y == 0.0)
		return false;
	double tt = -o.y / d.y;
	if (!(tt > tmin && tt < tmax))
		return false;
	double x = o.x + d.x * tt, z = o.z + d.z * tt;
	if (round ? x * x + z * z > 1.0 : (fabs(x) > 1.0 || fabs(z) > 1.0))
		return false;
	*t = tt;
	return true;
}

bool disc_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n)
{
	if (!flat_hit(o, d, tmin, tmax, true, t))
		return false;
	*n = v3(0, 1, 0);
	return true;
}

bool disc_occluded(vec3 o, vec3 d, double tmin, double tmax)
{
	double t;
	return flat_hit(o, d, tmin, tmax, true, &t);
}

bool rect_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n)
{
	if (!flat_hit(o, d, tmin, tmax, false, t))
		return false;
	*n = v3(0, 1, 0);
	return true;
}

bool rect_occluded(vec3 o, vec3 d, double tmin, double tmax)
{
	double t;
	return flat_hit(o, d, tmin, tmax, false, &t);
}
