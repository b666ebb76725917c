/* rtsh — the plane y = 0 with normal +Y, unbounded. */
#include "shapes.h"

static bool plane_intersect(vec3 o, vec3 d, double tube, double tmin, double tmax, double *t, vec3 *n)
{
	(void)tube;
	if (d.y == 0.0)
		return false;
	double tt = -o.y / d.y;
	if (!(tt > tmin && tt < tmax))
		return false;
	*t = tt;
	*n = v3(0, 1, 0);
	return true;
}

static bool plane_occluded(vec3 o, vec3 d, double tube, double tmin, double tmax)
{
	(void)tube;
	if (d.y == 0.0)
		return false;
	double tt = -o.y / d.y;
	return tt > tmin && tt < tmax;
}

static box plane_bounds(double tube)
{
	(void)tube;
	return (box){v3_splat(-INFINITY), v3_splat(INFINITY)};
}

/* Tiled: u = x, v = z, one repeat per scene unit (the plane's object units
 * are scene units: object_xform does not scale it). */
static void plane_uv(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv)
{
	(void)nl;
	(void)tube;
	*u = q.x;
	*v = q.z;
	*dqdu = v3(1, 0, 0);
	*dqdv = v3(0, 0, 1);
}

static void plane_read(object *o, const double *sizes)
{
	(void)sizes;
	o->scale = v3_splat(1);
}

static bool plane_write(const object *o, double *sizes)
{
	(void)sizes;
	return v3_eq(o->scale, v3_splat(1));
}

const shape_kind plane_kind = {
	.form = {"pl", "plane", true, true, false, 2, "POINT NORMAL", {"point", "normal"}, "pd", plane_read,
	         plane_write},
	.intersect = plane_intersect,
	.occluded = plane_occluded,
	.bounds = plane_bounds,
	.uv = plane_uv,
	.cost = 8,
};
