/* rtsh — small sampling helpers shared by the path tracer (path.c) and the
 * emitters (emitters.c): an orthonormal basis, a point of the unit disc. */
#ifndef RTSH_WARP_H
#define RTSH_WARP_H

#include "rtsh/math.h"
#include "sampler.h"

/* An orthonormal basis (t, b) around the unit vector n (Duff et al.,
 * "Building an orthonormal basis, revisited", JCGT 2017). */
static inline void basis(vec3 n, vec3 *t, vec3 *b)
{
	double sign = copysign(1.0, n.z);
	double a = -1.0 / (sign + n.z), c = n.x * n.y * a;
	*t = v3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
	*b = v3(c, sign + n.y * n.y * a, -n.y);
}

/* max(v, 0), NaN to 0 (plain comparisons: fmax is a library call). */
static inline double pos(double v)
{
	return v > 0.0 ? v : 0.0;
}

/* The largest component (plain comparisons: fmax is a library call). */
static inline double max3(vec3 v)
{
	double m = v.x > v.y ? v.x : v.y;
	return m > v.z ? m : v.z;
}

/* A uniform point (x, y) of the unit disc, by rejection from the square
 * (no trigonometry; on average 2.55 random numbers). *r2 = x^2 + y^2 > 0. */
static inline void disc_point(rng *g, double *x, double *y, double *r2)
{
	for (;;) {
		double a = 2.0 * rng_next(g) - 1.0, c = 2.0 * rng_next(g) - 1.0, s = a * a + c * c;
		if (s < 1.0 && s > 0.0) {
			*x = a;
			*y = c;
			*r2 = s;
			return;
		}
	}
}

#endif
