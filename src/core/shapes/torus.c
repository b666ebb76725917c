/* rtsh — the unit torus: the points within r of the circle of radius R
 * about the Y axis in the plane y = 0, scaled so that R + r = 1 (the
 * outer diameter fills [-1,1] in x and z). The object's tube ratio
 * k = r / R (tube=, > 0) gives R = 1 / (1 + k), r = k / (1 + k): k < 1 is a
 * ring torus, k = 1 a horn torus, k > 1 a spindle torus (the apple-shaped
 * outer surface; the self-intersecting inner sheet lies inside the solid
 * and is not a surface of it).
 *
 * The surface is a root of the quartic
 *   f(p) = (|p|^2 + R^2 - r^2)^2 - 4 R^2 (x^2 + z^2)
 *        = ((rho - R)^2 + y^2 - r^2) ((rho + R)^2 + y^2 - r^2),  rho^2 = x^2 + z^2.
 * Closed-form quartic solvers lose the roots to cancellation at grazing
 * angles (speckles), so the roots are isolated instead: along the ray,
 * inside the bounding sphere, the roots of f'' (a quadratic) cut the chord
 * into pieces where f' is monotone; bisection finds f''s roots there,
 * which cut it into pieces where f is monotone, and bisection finds f's
 * roots in those with a change of sign. Every simple root is found; only an
 * exact tangent (a double root) can be missed. Of f's roots, those of the
 * second factor (the spindle's inner sheet) are left out. */
#include "shapes.h"

/* The polynomial c[0] + c[1] u + ... + c[n] u^n at u. */
static double poly(const double *c, int n, double u)
{
	double v = c[n];
	for (int i = n - 1; i >= 0; i--)
		v = v * u + c[i];
	return v;
}

/* The root of c (degree n) in [lo, hi], where it is monotone and changes
 * sign (f(lo) = flo), by bisection to the last bit. */
static double bisect(const double *c, int n, double lo, double hi, double flo)
{
	for (int i = 0; i < 200; i++) {
		double mid = 0.5 * (lo + hi);
		if (!(mid > lo && mid < hi))
			break;
		double fm = poly(c, n, mid);
		if ((fm < 0.0) == (flo < 0.0)) {
			lo = mid;
			flo = fm;
		} else {
			hi = mid;
		}
	}
	return 0.5 * (lo + hi);
}

/* The roots of c (degree n) in [lo, hi], ascending, given the sorted points
 * cut[0..ncut) inside (lo, hi) between which c is monotone. A value of
 * exactly 0 counts as positive. */
static int roots_between(const double *c, int n, double lo, double hi, const double *cut, int ncut,
                         double *out)
{
	int nr = 0;
	double a = lo, fa = poly(c, n, lo);
	for (int i = 0; i <= ncut; i++) {
		double b = i < ncut ? cut[i] : hi;
		if (!(b > a))
			continue;
		double fb = poly(c, n, b);
		if ((fa < 0.0) != (fb < 0.0))
			out[nr++] = bisect(c, n, a, b, fa);
		a = b;
		fa = fb;
	}
	return nr;
}

/* The roots of the quartic c (c[4] = 1) in (lo, hi), ascending. */
static int quartic_roots(const double *c, double lo, double hi, double *out)
{
	double d1[4] = {c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4]}; /* f' */
	double cut[3];
	int ncut = 0;
	/* f'' = 12 u^2 + 6 c3 u + 2 c2: its roots, stably */
	double t0, t1;
	if (solve_quadratic_half(12.0 * c[4], 3.0 * c[3], 2.0 * c[2], &t0, &t1)) {
		if (t0 > lo && t0 < hi)
			cut[ncut++] = t0;
		if (t1 > lo && t1 < hi && t1 > t0)
			cut[ncut++] = t1;
	}
	double crit[3];
	int ncrit = roots_between(d1, 3, lo, hi, cut, ncut, crit);
	return roots_between(c, 4, lo, hi, crit, ncrit, out);
}

/* The hits of the ray with the torus of tube ratio k in (tmin, tmax), at
 * most 4, ascending. */
static int torus_hits(vec3 o, vec3 d, double k, double tmin, double tmax, double *ts, vec3 *ns)
{
	double big = 1.0 / (1.0 + k), small = k / (1.0 + k);
	double len = v3_len(d);
	if (!(len > 0.0) || !(k > 0.0))
		return 0;
	vec3 dn = v3_scale(d, 1.0 / len);
	/* the bounding sphere |p| <= 1, a little wider for rounding */
	double s0, s1;
	if (!solve_quadratic_half(1.0, v3_dot(o, dn), v3_dot(o, o) - 1.0000001, &s0, &s1))
		return 0;
	/* The whole chord is searched whatever (tmin, tmax) are, so that a hit
	 * is the same bits for every query range (the tree narrows tmax). */
	if (!(s1 > tmin * len && s0 < tmax * len))
		return 0;
	/* the origin moved to the sphere's entry, where everything is O(1) */
	vec3 q = v3_madd(o, dn, s0);
	double b = v3_dot(q, dn), K = v3_dot(q, q) + big * big - small * small, R2 = 4.0 * big * big;
	double c[5] = {
		K * K - R2 * (q.x * q.x + q.z * q.z),
		4.0 * b * K - 2.0 * R2 * (q.x * dn.x + q.z * dn.z),
		4.0 * b * b + 2.0 * K - R2 * (dn.x * dn.x + dn.z * dn.z),
		4.0 * b,
		1.0,
	};
	double u[4];
	int nu = quartic_roots(c, 0.0, s1 - s0, u);
	int n = 0;
	for (int i = 0; i < nu; i++) {
		vec3 p = v3_madd(q, dn, u[i]);
		double rho = sqrt(p.x * p.x + p.z * p.z);
		double g = (rho - big) * (rho - big) + p.y * p.y - small * small;
		double h = (rho + big) * (rho + big) + p.y * p.y - small * small;
		if (fabs(g) > fabs(h))
			continue; /* the spindle's inner sheet */
		double t = (s0 + u[i]) / len;
		if (!(t > tmin && t < tmax))
			continue;
		ts[n] = t;
		/* away from the nearest point of the centre circle */
		ns[n] = rho > 0.0 ? v3(p.x - big * p.x / rho, p.y, p.z - big * p.z / rho) : v3(0, p.y, 0);
		n++;
	}
	return n;
}

static bool torus_intersect(vec3 o, vec3 d, double k, double tmin, double tmax, double *t, vec3 *n)
{
	double ts[4];
	vec3 ns[4];
	if (torus_hits(o, d, k, tmin, tmax, ts, ns) == 0)
		return false;
	*t = ts[0];
	*n = ns[0];
	return true;
}

static bool torus_occluded(vec3 o, vec3 d, double k, double tmin, double tmax)
{
	double ts[4];
	vec3 ns[4];
	return torus_hits(o, d, k, tmin, tmax, ts, ns) > 0;
}

/* The tube reaches r = k / (1 + k) above and below the ring's plane. */
static box torus_bounds(double k)
{
	double r = k / (1.0 + k);
	return (box){v3(-1, -r, -1), v3(1, r, 1)};
}

/* to CENTER AXIS DIAMETER TUBE_DIAMETER: the outer diameter D + d in every
 * direction, and the ratio d / D. */
static void torus_read(object *o, const double *sizes)
{
	o->scale = v3_splat(sizes[0] + sizes[1]);
	o->tube = sizes[1] / sizes[0];
}

static bool torus_write(const object *o, double *sizes)
{
	double s = o->scale.x, k = o->tube;
	sizes[0] = s / (1.0 + k);
	sizes[1] = sizes[0] * k;
	/* only when the two numbers read back to exactly this torus */
	return o->scale.x == o->scale.y && o->scale.y == o->scale.z && sizes[0] > 0.0 &&
	       sizes[1] > 0.0 && sizes[0] + sizes[1] == s && sizes[1] / sizes[0] == k;
}

const shape_kind torus_kind = {
	.form = {"to", "torus", false, true, true, 4, "CENTER AXIS DIAMETER TUBE_DIAMETER",
	         {"center", "axis", "diameter", "tube diameter"}, "pdss", torus_read, torus_write},
	.intersect = torus_intersect,
	.occluded = torus_occluded,
	.bounds = torus_bounds,
	/* no uv: the planar default, seen along its axis (rtsh(5)) */
	.cost = 40,
	.recipe = {true, {50, 0, 0}, {100, 0, 0}, 20, 60},
};
