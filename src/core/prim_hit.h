/* rtsh — the primitive tests that the single-ray walk (world.c) and the
 * packet walk (packet.c) share, so that both give the same bits, and
 * the roundings of a double to the floats the tree's slab tests use.
 * Private to src/core. */
#ifndef RTSH_PRIM_HIT_H
#define RTSH_PRIM_HIT_H

#include <float.h>
#include <math.h>

#include "rtsh/world.h"

/* A float <= v and a float >= v (a step of |f| 2^-23 covers the rounding;
 * cheaper than nextafterf, which is a library call). */
static inline float to_float_down(double v)
{
	float f = (float)v;
	if ((double)f <= v)
		return f;
	return f == INFINITY ? FLT_MAX : f - (fabsf(f) * 0x1p-23f + 0x1p-149f);
}

static inline float to_float_up(double v)
{
	float f = (float)v;
	if ((double)f >= v)
		return f;
	return f == -INFINITY ? -FLT_MAX : f + (fabsf(f) * 0x1p-23f + 0x1p-149f);
}

/* The nearest hit of a world-space sphere in (tmin, tmax); the stable
 * quadratic of Numerical Recipes 5.6. */
static inline bool sphere_hit(const prim *p, const ray *r, double tmin, double tmax, double *t)
{
	vec3 oc = v3_sub(r->o, p->u.sph.c);
	double b = v3_dot(oc, r->d), a = v3_dot(r->d, r->d);
	double c = v3_dot(oc, oc) - p->u.sph.r * p->u.sph.r;
	double disc = b * b - a * c;
	if (disc < 0.0)
		return false;
	double q = -(b + copysign(sqrt(disc), b));
	double t0 = q / a, t1 = q != 0.0 ? c / q : t0;
	if (t0 > t1) {
		double tmp = t0;
		t0 = t1;
		t1 = tmp;
	}
	double tt = t0 > tmin ? t0 : t1;
	if (!(tt > tmin && tt < tmax))
		return false;
	*t = tt;
	return true;
}

/* A plane: the unit plane's test (plane.c) with the ray's object-space
 * height and slope computed from row 1 of the matrix only, in two steps so
 * that rays of one origin (packet.c's camera packets) share the first:
 * plane_oy, the origin's height over the plane, then plane_hit_o, a ray's
 * test from that height. */
static inline double plane_oy(const prim_plane *pl, vec3 o)
{
	const double *h = pl->h;
	return h[0] * o.x + h[1] * o.y + h[2] * o.z + h[3];
}

static inline bool plane_hit_o(const prim_plane *pl, double oy, const ray *r, double tmin, double tmax, double *t)
{
	const double *h = pl->h;
	double dy = h[0] * r->d.x + h[1] * r->d.y + h[2] * r->d.z;
	if (dy == 0.0)
		return false;
	double tt = -oy / dy;
	if (!(tt > tmin && tt < tmax))
		return false;
	*t = tt;
	return true;
}

static inline bool plane_hit(const prim_plane *pl, const ray *r, double tmin, double tmax, double *t)
{
	return plane_hit_o(pl, plane_oy(pl, r->o), r, tmin, tmax, t);
}

/* The nearest hit of any bounded primitive in (tmin, tmax) (world.c's
 * prim_hit): *t and, for a transformed shape or a model, what the hit
 * record is made from (*nl, trace_hit.nl). coherent: r is a camera ray. */
bool world_prim_hit(const world *w, const prim *p, const ray *r, double tmin, double tmax, double *t, vec3 *nl,
                    bool coherent);
/* Whether primitive p lies on r with tmin < t < tmax (world.c's
 * prim_occluded). */
bool world_prim_occluded(const world *w, const prim *p, const ray *r, double tmin, double tmax);
/* Adds n (maybe negative) to the calling thread's count of traced rays
 * (world_rays_traced): a packet counts its rays. */
void world_rays_count(int n);

#endif
