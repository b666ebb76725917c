/* rtsh — small sampling helpers shared by the path tracer (path.c) and the
 * emitters (emitters.c): an orthonormal basis, and warps from uniform
 * numbers to points of the circle and the disc that keep the numbers'
 * stratification and call no library function. */
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

/* cos and sin of x in [-pi/4, pi/4] by their Taylor series to x^12, error
 * below 1e-11; the polynomials in x^2 evaluated in pairs (Estrin's scheme)
 * for a short chain of dependent operations. */
static inline void sincos_small(double x, double *c, double *s)
{
	double x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
	double s01 = 1.0 - x2 * (1.0 / 6), s23 = 1.0 / 120 - x2 * (1.0 / 5040);
	double s45 = 1.0 / 362880 - x2 * (1.0 / 39916800);
	*s = x * (s01 + x4 * s23 + x8 * s45);
	double c01 = 1.0 - x2 * 0.5, c23 = 1.0 / 24 - x2 * (1.0 / 720);
	double c45 = 1.0 / 40320 - x2 * (1.0 / 3628800), c6 = 1.0 / 479001600;
	*c = c01 + x4 * c23 + x8 * (c45 + x4 * c6);
}

/* The point at angle 2 pi t of the unit circle (t in [0, 1]). */
static inline void warp_circle(double t, double *c, double *s)
{
	double q4 = 4.0 * t, q = (double)(long)(q4 + 0.5), cr, sr;
	sincos_small((q4 - q) * 1.5707963267948966, &cr, &sr);
	switch ((int)q & 3) {
	case 0: *c = cr; *s = sr; break;
	case 1: *c = -sr; *s = cr; break;
	case 2: *c = -cr; *s = -sr; break;
	default: *c = sr; *s = -cr; break;
	}
}

/* A uniform point (x, y) of the unit disc from (u, v) in [0,1)^2 by the
 * concentric map (Shirley & Chiu, "A low distortion map between disk and
 * square", 1997), which keeps the stratification of (u, v). */
static inline void warp_disc(double u, double v, double *x, double *y)
{
	/* branch-free: the two halves of the square only swap roles */
	double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0, c, s;
	int m = a * a > b * b;
	double r = m ? a : b, t = m ? b : a;
	sincos_small(0.7853981633974483 * (r != 0.0 ? t / r : 0.0), &c, &s);
	double x1 = r * c, y1 = r * s;
	*x = m ? x1 : y1;
	*y = m ? y1 : x1;
}

/* Cosine-weighted about n, pdf cos / pi: a uniform point of the unit disc
 * lifted onto the hemisphere (Malley's method). */
static inline vec3 warp_cosine(vec3 n, double u, double v)
{
	double x, y;
	warp_disc(u, v, &x, &y);
	vec3 t, b;
	basis(n, &t, &b);
	return v3_add(v3_add(v3_scale(t, x), v3_scale(b, y)), v3_scale(n, sqrt(pos(1.0 - x * x - y * y))));
}

#endif
