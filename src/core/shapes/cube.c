/* rtsh — the unit cube [-1,1]^3, by the slab method (Kay & Kajiya 1986). */
#include "shapes.h"

/* Entry and exit parameters of the ray through the cube; false if it misses. */
static bool slabs(vec3 o, vec3 d, double *t0, double *t1, int *axis0, int *axis1)
{
	double lo = -INFINITY, hi = INFINITY;
	const double oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
	for (int i = 0; i < 3; i++) {
		if (dd[i] == 0.0) {
			if (oo[i] < -1.0 || oo[i] > 1.0)
				return false;
			continue;
		}
		double inv = 1.0 / dd[i];
		double a = (-1.0 - oo[i]) * inv, b = (1.0 - oo[i]) * inv;
		if (a > b) {
			double tmp = a;
			a = b;
			b = tmp;
		}
		if (a > lo) {
			lo = a;
			*axis0 = i;
		}
		if (b < hi) {
			hi = b;
			*axis1 = i;
		}
	}
	if (lo > hi)
		return false;
	*t0 = lo;
	*t1 = hi;
	return true;
}

static vec3 face_normal(int axis, double coord)
{
	double s = coord < 0.0 ? -1.0 : 1.0;
	return axis == 0 ? v3(s, 0, 0) : axis == 1 ? v3(0, s, 0) : v3(0, 0, s);
}

static bool cube_intersect(vec3 o, vec3 d, double tube, double tmin, double tmax, double *t, vec3 *n)
{
	(void)tube;
	double t0, t1;
	int a0 = 0, a1 = 0;
	if (!slabs(o, d, &t0, &t1, &a0, &a1))
		return false;
	double tt;
	int axis;
	if (t0 > tmin && t0 < tmax) {
		tt = t0;
		axis = a0;
	} else if (t1 > tmin && t1 < tmax) {
		tt = t1;
		axis = a1;
	} else {
		return false;
	}
	*t = tt;
	*n = face_normal(axis, v3_get(v3_madd(o, d, tt), axis));
	return true;
}

static bool cube_occluded(vec3 o, vec3 d, double tube, double tmin, double tmax)
{
	(void)tube;
	double t0, t1;
	int a0 = 0, a1 = 0;
	if (!slabs(o, d, &t0, &t1, &a0, &a1))
		return false;
	return (t0 > tmin && t0 < tmax) || (t1 > tmin && t1 < tmax);
}

/* Each face the whole image: the X faces (z, y), the Y faces (x, z), the Z
 * faces (x, y), each from [-1,1] to [0,1]; the face is the normal's
 * largest axis. */
static void cube_uv(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv)
{
	(void)tube;
	double ax = fabs(nl.x), ay = fabs(nl.y), az = fabs(nl.z);
	if (ax >= ay && ax >= az) {
		*u = (q.z + 1) / 2, *v = (q.y + 1) / 2;
		*dqdu = v3(0, 0, 2), *dqdv = v3(0, 2, 0);
	} else if (ay >= az) {
		*u = (q.x + 1) / 2, *v = (q.z + 1) / 2;
		*dqdu = v3(2, 0, 0), *dqdv = v3(0, 0, 2);
	} else {
		*u = (q.x + 1) / 2, *v = (q.y + 1) / 2;
		*dqdu = v3(2, 0, 0), *dqdv = v3(0, 2, 0);
	}
}

const shape_kind cube_kind = {
	.form = {"cu", "cube", false, true, false, 0, NULL, {NULL}, "", NULL, NULL},
	.intersect = cube_intersect,
	.occluded = cube_occluded,
	.bounds = unit_cube_bounds,
	.uv = cube_uv,
	.cost = 8,
	.recipe = {true, {50, 50, 50}, {100, 100, 100}, 0, 0},
};
