/* rtsh — the plane y = 0 with normal +Y, unbounded. */
#include "shapes.h"

bool plane_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n)
{
	if (d.y == 0.0)
		return false;
	double tt = -o.y / d.y;
	if (!(tt > tmin && tt < tmax))
		return false;
	*t = tt;
	*n = v3(0, 1, 0);
	return true;
}

bool plane_occluded(vec3 o, vec3 d, double tmin, double tmax)
{
	if (d.y == 0.0)
		return false;
	double tt = -o.y / d.y;
	return tt > tmin && tt < tmax;
}
