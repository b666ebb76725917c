/* rtsh — what the emissive kinds share to be sampled as lights (shapes.h,
 * shape_light_ops): flat lights by area or by the solid angle they subtend,
 * spherical rectangles and triangles. The path tracer weighs these samples
 * against its own paths by multiple importance sampling (Veach & Guibas,
 * "Optimally combining sampling techniques for Monte Carlo rendering",
 * SIGGRAPH 1995). */
#include "shapes.h"

#include "core/warp.h"

/* Flat lights are sampled by the solid angle they subtend from points
 * within SOLID_ANGLE_REACH of their size, where the density of area
 * sampling (t^2 / (cos area)) varies most across them; farther, area
 * sampling is nearly as good and cheaper. */
#define SOLID_ANGLE_REACH 2.0

bool light_flat_finish(shape_light *l, bool triangle)
{
	vec3 nn = v3_cross(l->u, l->v);
	if (!(l->area > 0.0) || !v3_finite(nn))
		return false;
	l->n = v3_norm(nn);
	double uu = v3_len2(l->u), vv = v3_len2(l->v), uv = v3_dot(l->u, l->v);
	if (triangle) {
		double w2 = v3_len2(v3_sub(l->u, l->v));
		double big = uu > vv ? uu : vv;
		big = big > w2 ? big : w2;
		l->reach2 = SOLID_ANGLE_REACH * SOLID_ANGLE_REACH * big;
	} else if (fabs(uv) > 1e-9 * sqrt(uu * vv)) {
		/* rectangles (and the square around a disc) need square corners: a
		 * sheared one stays with area sampling */
		l->reach2 = 0.0;
	} else {
		l->reach2 = SOLID_ANGLE_REACH * SOLID_ANGLE_REACH * (uu + vv);
	}
	return true;
}

bool light_area_sample(const shape_light *l, vec3 p, double a, double b,
                       double (*pdf)(const shape_light *, vec3, vec3, double), vec3 *wi, double *pdf_out, double *t)
{
	vec3 q = v3_add(l->c, v3_add(v3_scale(l->u, a), v3_scale(l->v, b)));
	vec3 d = v3_sub(q, p);
	*t = v3_len(d);
	if (!(*t > 0.0))
		return false;
	*wi = v3_scale(d, 1.0 / *t);
	*pdf_out = pdf(l, p, *wi, *t);
	return *pdf_out > 0.0;
}

/* --- spherical rectangles (Urena, Fajardo & King, "An area-preserving
 * parametrization for spherical rectangles", EGSR 2013) ---
 * The rectangle c + a u + b v (a, b in [-1,1], u and v orthogonal) seen
 * from o, in the frame x = u / |u|, y = v / |v|, z facing away from o. */
typedef struct sph_rect {
	vec3 o, x, y, z;
	double x0, x1, y0, y1, z0;
	double b0, b1, ck, sk, s; /* cos k, sin k; s: the solid angle */
} sph_rect;

/* e^(i g) for the angle g in [0, pi] whose cosine is c. */
static void unit_angle(double c, double *re, double *im)
{
	c = c < -1.0 ? -1.0 : c > 1.0 ? 1.0 : c;
	*re = c;
	*im = sqrt(1.0 - c * c);
}

static bool sph_rect_make(sph_rect *r, const shape_light *e, vec3 o)
{
	double lu = v3_len(e->u), lv = v3_len(e->v);
	r->o = o;
	r->x = v3_scale(e->u, 1.0 / lu);
	r->y = v3_scale(e->v, 1.0 / lv);
	r->z = v3_cross(r->x, r->y);
	vec3 d = v3_sub(v3_sub(v3_sub(e->c, e->u), e->v), o); /* corner - o */
	double z0 = v3_dot(d, r->z);
	if (z0 > 0.0) {
		r->z = v3_neg(r->z);
		z0 = -z0;
	}
	r->z0 = z0;
	r->x0 = v3_dot(d, r->x);
	r->y0 = v3_dot(d, r->y);
	r->x1 = r->x0 + 2.0 * lu;
	r->y1 = r->y0 + 2.0 * lv;
	if (!(z0 < 0.0))
		return false; /* o in the rectangle's plane */
	/* The planes through o and each edge have the normals n0..n3; the
	 * spherical rectangle's inner angles are g_i = acos(-n_i . n_i+1).
	 * Only sums of them are needed, as products of e^(i g): no acos. */
	double z2 = z0 * z0;
	double l0 = sqrt(z2 + r->y0 * r->y0), l1 = sqrt(z2 + r->x1 * r->x1);
	double l2 = sqrt(z2 + r->y1 * r->y1), l3 = sqrt(z2 + r->x0 * r->x0);
	double c0, s0, c1, s1, c2, s2, c3, s3;
	unit_angle(r->y0 * r->x1 / (l0 * l1), &c0, &s0);
	unit_angle(-r->x1 * r->y1 / (l1 * l2), &c1, &s1);
	unit_angle(r->x0 * r->y1 / (l2 * l3), &c2, &s2);
	unit_angle(-r->x0 * r->y0 / (l3 * l0), &c3, &s3);
	double c01 = c0 * c1 - s0 * s1, s01 = s0 * c1 + c0 * s1; /* g0 + g1 */
	double c23 = c2 * c3 - s2 * s3, s23 = s2 * c3 + c2 * s3; /* g2 + g3 */
	r->b0 = -r->y0 / l0;
	r->b1 = r->y1 / l2;
	/* k = 2 pi - g2 - g3; the solid angle s = g0 + g1 + g2 + g3 - 2 pi,
	 * in (0, 2 pi) */
	r->ck = c23;
	r->sk = -s23;
	double s = atan2(s01 * c23 + c01 * s23, c01 * c23 - s01 * s23);
	r->s = s < 0.0 ? s + 2.0 * RT_PI : s;
	return r->s > 0.0;
}

/* The point of the rectangle for (u, v), uniform in solid angle. */
static vec3 sph_rect_point(const sph_rect *r, double u, double v)
{
	/* au = u s + k */
	double cs, ss;
	warp_circle(u * r->s * (0.5 / RT_PI), &cs, &ss);
	double ca = cs * r->ck - ss * r->sk, sa = ss * r->ck + cs * r->sk;
	double fu = (ca * r->b0 - r->b1) / sa;
	double cu = copysign(1.0, fu) / sqrt(fu * fu + r->b0 * r->b0);
	cu = cu < -1.0 ? -1.0 : cu > 1.0 ? 1.0 : cu;
	double sq = sqrt(pos(1.0 - cu * cu));
	double xu = sq > 0.0 ? -(cu * r->z0) / sq : (cu > 0.0 ? r->x1 : r->x0);
	xu = xu < r->x0 ? r->x0 : xu > r->x1 ? r->x1 : xu;
	double dd = sqrt(xu * xu + r->z0 * r->z0);
	double h0 = r->y0 / sqrt(dd * dd + r->y0 * r->y0), h1 = r->y1 / sqrt(dd * dd + r->y1 * r->y1);
	double hv = h0 + v * (h1 - h0), hv2 = hv * hv;
	double yv = hv2 < 1.0 - 1e-12 ? hv * dd / sqrt(1.0 - hv2) : r->y1;
	yv = yv < r->y0 ? r->y0 : yv > r->y1 ? r->y1 : yv;
	return v3_add(r->o, v3_add(v3_add(v3_scale(r->x, xu), v3_scale(r->y, yv)), v3_scale(r->z, r->z0)));
}

bool light_rect_solid_pdf(const shape_light *l, vec3 p, double *pdf)
{
	sph_rect sr;
	if (!sph_rect_make(&sr, l, p))
		return false;
	*pdf = 1.0 / sr.s;
	return true;
}

bool light_rect_solid_sample(const shape_light *l, vec3 p, double u1, double u2, bool disc, vec3 *wi, double *pdf,
                             double *t)
{
	sph_rect sr;
	if (!sph_rect_make(&sr, l, p))
		return false;
	vec3 q = sph_rect_point(&sr, u1, u2);
	vec3 d = v3_sub(q, p);
	*t = v3_len(d);
	*pdf = 0.0;
	if (!(*t > 0.0))
		return true;
	*wi = v3_scale(d, 1.0 / *t);
	if (disc) {
		/* inside the disc: |a| and |b| of q - c on u, v as a^2 + b^2 <= 1 */
		vec3 qc = v3_sub(q, l->c);
		double a = v3_dot(qc, l->u) / v3_len2(l->u), b = v3_dot(qc, l->v) / v3_len2(l->v);
		if (a * a + b * b > 1.0)
			return true;
	}
	*pdf = 1.0 / sr.s;
	return true;
}

/* --- spherical triangles (Arvo, "Stratified sampling of spherical
 * triangles", SIGGRAPH 1995) --- the triangle's vertices seen from o as
 * unit vectors a, b, c. */
typedef struct sph_tri {
	vec3 a, b, c;
	double ca, sa, s; /* cos and sin of the angle at a; s: the solid angle */
} sph_tri;

static bool sph_tri_make(sph_tri *t, const shape_light *e, vec3 o)
{
	vec3 pa = v3_sub(e->c, o), pb = v3_add(pa, e->u), pc = v3_add(pa, e->v);
	double la = v3_len(pa), lb = v3_len(pb), lc = v3_len(pc);
	t->a = v3_scale(pa, 1.0 / la);
	t->b = v3_scale(pb, 1.0 / lb);
	t->c = v3_scale(pc, 1.0 / lc);
	/* the solid angle (van Oosterom & Strackee, IEEE TBME 1983) */
	double num = fabs(v3_dot(t->a, v3_cross(t->b, t->c)));
	double den = 1.0 + v3_dot(t->a, t->b) + v3_dot(t->b, t->c) + v3_dot(t->c, t->a);
	t->s = 2.0 * atan2(num, den);
	/* the angle at a between the great circles through a, b and a, c */
	vec3 nab = v3_cross(t->a, t->b), nac = v3_cross(t->a, t->c);
	double lab = v3_len(nab), lac = v3_len(nac);
	if (!(t->s > 0.0) || !(lab > 0.0) || !(lac > 0.0))
		return false;
	unit_angle(v3_dot(nab, nac) / (lab * lac), &t->ca, &t->sa);
	return true;
}

/* The direction for (u1, u2), uniform in solid angle. */
static vec3 sph_tri_dir(const sph_tri *t, double u1, double u2)
{
	/* the sub-triangle of area u1 s: sin and cos of (u1 s - alpha) */
	double ca = t->ca, sa = t->sa, cs, ss;
	warp_circle(u1 * t->s * (0.5 / RT_PI), &cs, &ss);
	double s = ss * ca - cs * sa, c = cs * ca + ss * sa;
	double uu = c - ca, vv = s + sa * v3_dot(t->a, t->b); /* cos of the edge a b */
	double q = ((vv * c - uu * s) * ca - vv) / ((vv * s + uu * c) * sa);
	q = q < -1.0 ? -1.0 : q > 1.0 ? 1.0 : q;
	vec3 perp = v3_sub(t->c, v3_scale(t->a, v3_dot(t->c, t->a)));
	double lp = v3_len(perp);
	vec3 ch = lp > 0.0 ? v3_add(v3_scale(t->a, q), v3_scale(perp, sqrt(pos(1.0 - q * q)) / lp)) : t->a;
	double z = 1.0 - u2 * (1.0 - v3_dot(ch, t->b));
	vec3 perp2 = v3_sub(ch, v3_scale(t->b, v3_dot(ch, t->b)));
	double lp2 = v3_len(perp2);
	return lp2 > 0.0 ? v3_add(v3_scale(t->b, z), v3_scale(perp2, sqrt(pos(1.0 - z * z)) / lp2)) : t->b;
}

bool light_tri_solid_pdf(const shape_light *l, vec3 p, double *pdf)
{
	sph_tri st;
	if (!sph_tri_make(&st, l, p))
		return false;
	*pdf = 1.0 / st.s;
	return true;
}

bool light_tri_solid_sample(const shape_light *l, vec3 p, double u1, double u2, vec3 *wi, double *pdf, double *t)
{
	sph_tri st;
	if (!sph_tri_make(&st, l, p))
		return false;
	*wi = sph_tri_dir(&st, u1, u2);
	/* the distance to the triangle's plane along wi */
	double dn = v3_dot(*wi, l->n);
	*t = dn != 0.0 ? v3_dot(v3_sub(l->c, p), l->n) / dn : 0.0;
	*pdf = *t > 0.0 ? 1.0 / st.s : 0.0;
	return true;
}
