/* rtsh — the emissive surfaces the path tracer samples directly (path.c
 * weighs them against its own paths). */
#include "emitters.h"

#include <stdlib.h>

#include "rtsh/mesh.h"
#include "warp.h"

/* --- emissive surfaces: sampled directly and found by the paths, the two
 * combined by multiple importance sampling with the power heuristic (Veach
 * & Guibas, "Optimally combining sampling techniques for Monte Carlo
 * rendering", SIGGRAPH 1995). */

/* Flat emitters are sampled by the solid angle they subtend from points
 * within SOLID_ANGLE_REACH of their size, where the density of area
 * sampling (t^2 / (cos area)) varies most across them; farther, area
 * sampling is nearly as good and cheaper. */
#define SOLID_ANGLE_REACH 2.0

static double solid_angle_reach2(const emitter *e)
{
	double uu = v3_len2(e->u), vv = v3_len2(e->v), uv = v3_dot(e->u, e->v);
	if (e->shape == EMITTER_TRIANGLE) {
		double w2 = v3_len2(v3_sub(e->u, e->v));
		double big = uu > vv ? uu : vv;
		big = big > w2 ? big : w2;
		return SOLID_ANGLE_REACH * SOLID_ANGLE_REACH * big;
	}
	/* rectangles (and the square around a disc) need square corners: a
	 * sheared one stays with area sampling */
	if (fabs(uv) > 1e-9 * sqrt(uu * vv))
		return 0.0;
	return SOLID_ANGLE_REACH * SOLID_ANGLE_REACH * (uu + vv);
}

/* The world material of triangle t of instance in (object i). */
static uint32_t tri_mat(const prim_inst *in, size_t i, uint32_t t)
{
	if (in->mat_base == UINT32_MAX)
		return (uint32_t)i;
	return in->mat_base + (in->mesh->tmat ? in->mesh->tmat[t] : 0);
}

/* Walks the emissive triangles of the models: counts them, or (put) adds
 * them to w->emitters material by material, each material's in one run. */
static size_t mesh_walk(world *w, const scene *s, bool put)
{
	size_t total = 0, k = 0;
	/* the model objects in order are the instances (surface.c) */
	for (size_t i = 0; i < s->nobjs && k < w->ninsts; i++) {
		if (!(obj_kind_flags(s->objs[i].kind) & KIND_MODEL))
			continue;
		const prim_inst *in = &w->insts[k++];
		const mesh *m = in->mesh;
		if (!m || !m->blk)
			continue;
		uint32_t nm = in->mat_base == UINT32_MAX ? 1 : (m->nmats ? m->nmats : 1);
		for (uint32_t mi = 0; mi < nm; mi++) {
			uint32_t wm = in->mat_base == UINT32_MAX ? (uint32_t)i : in->mat_base + mi;
			if (wm >= w->nmats || !(max3(w->mats[wm].emission) > 0.0))
				continue;
			size_t first = w->nemitters, run = 0;
			uint32_t last = UINT32_MAX;
			/* each triangle once: a leaf's last block repeats its last */
			for (uint32_t slot = 0; slot < 4 * m->nblk; slot++) {
				uint32_t t = mesh_slot_tri(m, slot);
				if (t == last || tri_mat(in, i, t) != wm)
					continue;
				last = t;
				vec3 c[3];
				mesh_corners(m, slot, c);
				const double(*f)[4] = in->fwd;
				for (int j = 0; j < 3; j++) {
					vec3 q = c[j];
					c[j] = v3(f[0][0] * q.x + f[0][1] * q.y + f[0][2] * q.z + f[0][3],
					          f[1][0] * q.x + f[1][1] * q.y + f[1][2] * q.z + f[1][3],
					          f[2][0] * q.x + f[2][1] * q.y + f[2][2] * q.z + f[2][3]);
				}
				emitter e = {.object = UINT32_MAX, .mat = wm, .run = 1, .shape = EMITTER_TRIANGLE, .c = c[0]};
				e.u = v3_sub(c[1], c[0]);
				e.v = v3_sub(c[2], c[0]);
				vec3 nn = v3_cross(e.u, e.v);
				e.area = 0.5 * v3_len(nn);
				if (!(e.area > 0.0) || !v3_finite(nn))
					continue;
				e.n = v3_norm(nn);
				e.reach2 = solid_angle_reach2(&e);
				if (put)
					w->emitters[w->nemitters++] = e;
				run++;
			}
			if (put && run > 0) {
				w->emitters[first].run = (uint32_t)run;
				w->mats[wm].light = (int32_t)first;
			}
			total += run;
		}
	}
	return total;
}

/* A model's emissive triangles are sampled too, MESH_EMITTERS of them in
 * all at most (a lamp made of a few triangles; a model whose every
 * triangle glows is left to the paths, as before). The count, and (put)
 * the emitters added. */
#define MESH_EMITTERS 1024

static size_t mesh_emitters(world *w, const scene *s, bool put)
{
	size_t n = mesh_walk(w, s, false);
	if (n == 0 || n > MESH_EMITTERS)
		return 0;
	if (put)
		mesh_walk(w, s, true);
	return n;
}

const emitter *emitter_at(const world *w, int32_t first, vec3 p)
{
	const emitter *e = &w->emitters[first], *best = e;
	if (e->run <= 1)
		return e;
	double bd = INFINITY;
	for (uint32_t j = 0; j < e->run; j++) {
		const emitter *x = &w->emitters[(uint32_t)first + j];
		/* p's barycentrics in the triangle c + a u + b v; how far outside */
		vec3 d = v3_sub(p, x->c);
		double uu = v3_dot(x->u, x->u), uv = v3_dot(x->u, x->v), vv = v3_dot(x->v, x->v);
		double du = v3_dot(d, x->u), dv = v3_dot(d, x->v), det = uu * vv - uv * uv;
		if (!(det > 0.0))
			continue;
		double a = (vv * du - uv * dv) / det, b = (uu * dv - uv * du) / det;
		double out = fmax(fmax(-a, -b), a + b - 1.0);
		out = fmax(out, 0.0) + fabs(v3_dot(d, x->n)) / sqrt(fmax(uu, vv));
		if (out < bd) {
			bd = out;
			best = x;
		}
	}
	return best;
}

bool emitters_build(world *w, const scene *s, rt_error *err)
{
	w->emitters = NULL;
	w->nemitters = 0;
	size_t n = 0;
	for (size_t pass = 0; pass < 2; pass++) {
		for (size_t i = 0; i < s->nobjs; i++) {
			const object *o = &s->objs[i];
			const mat_lin *m = &w->mats[i];
			if (!(max3(m->emission) > 0.0))
				continue;
			emitter e = {.object = (uint32_t)i, .mat = (uint32_t)i, .run = 1};
			bool plain = true; /* uniform scale, no shear */
			for (int k = 0; k < 6; k++)
				plain = plain && o->shear[k] == 0.0;
			xform x;
			if (o->kind == OBJ_SPHERE && plain && o->scale.x == o->scale.y &&
			    o->scale.y == o->scale.z) {
				e.shape = EMITTER_SPHERE;
				e.c = o->pos;
				e.r = 0.5 * o->scale.x;
			} else if (o->kind == OBJ_TRIANGLE) {
				e.shape = EMITTER_TRIANGLE;
				e.c = o->tri[0];
				e.u = v3_sub(o->tri[1], o->tri[0]);
				e.v = v3_sub(o->tri[2], o->tri[0]);
				e.area = 0.5 * v3_len(v3_cross(e.u, e.v));
			} else if ((o->kind == OBJ_RECT || o->kind == OBJ_DISC) && object_xform(o, &x)) {
				/* the unit shape's axes X and Z, carried into the world */
				e.shape = o->kind == OBJ_RECT ? EMITTER_RECT : EMITTER_DISC;
				e.c = m4_point(&x.m, v3(0, 0, 0));
				e.u = m4_vector(&x.m, v3(1, 0, 0));
				e.v = m4_vector(&x.m, v3(0, 0, 1));
				double a = v3_len(v3_cross(e.u, e.v));
				e.area = o->kind == OBJ_RECT ? 4.0 * a : RT_PI * a;
			} else {
				continue; /* found by the paths only */
			}
			if (e.shape != EMITTER_SPHERE) {
				vec3 nn = v3_cross(e.u, e.v);
				if (!(e.area > 0.0) || !v3_finite(nn))
					continue;
				e.n = v3_norm(nn);
				e.reach2 = solid_angle_reach2(&e);
			} else if (!(e.r > 0.0)) {
				continue;
			}
			if (pass == 1) {
				w->mats[i].light = (int32_t)w->nemitters;
				w->emitters[w->nemitters++] = e;
			} else {
				n++;
			}
		}
		n += mesh_emitters(w, s, pass == 1);
		if (pass == 0) {
			if (n == 0)
				return true;
			w->emitters = calloc(n, sizeof *w->emitters);
			if (!w->emitters)
				return rt_error_set(err, "out of memory preparing the scene");
		}
	}
	return true;
}

/* 1 - cos(theta_max) of the cone that the sphere subtends from a point at
 * squared distance d2 > r^2, without cancellation for small spheres. */
static double cone_gap(double r2, double d2)
{
	double s2 = r2 / d2;
	return s2 / (1.0 + sqrt(1.0 - s2));
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

static bool sph_rect_make(sph_rect *r, const emitter *e, vec3 o)
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

/* --- spherical triangles (Arvo, "Stratified sampling of spherical
 * triangles", SIGGRAPH 1995) --- the triangle's vertices seen from o as
 * unit vectors a, b, c. */
typedef struct sph_tri {
	vec3 a, b, c;
	double ca, sa, s; /* cos and sin of the angle at a; s: the solid angle */
} sph_tri;

static bool sph_tri_make(sph_tri *t, const emitter *e, vec3 o)
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

static bool near_enough(const emitter *e, vec3 p)
{
	return v3_len2(v3_sub(e->c, p)) < e->reach2;
}

double emitter_pdf(const emitter *e, vec3 p, vec3 d, double t)
{
	if (e->shape == EMITTER_SPHERE) {
		double d2 = v3_len2(v3_sub(e->c, p)), r2 = e->r * e->r;
		return d2 > r2 ? 1.0 / (2.0 * RT_PI * cone_gap(r2, d2)) : 0.0;
	}
	if (near_enough(e, p)) {
		if (e->shape == EMITTER_TRIANGLE) {
			sph_tri st;
			if (sph_tri_make(&st, e, p))
				return 1.0 / st.s;
		} else {
			sph_rect sr;
			if (sph_rect_make(&sr, e, p))
				return 1.0 / sr.s; /* a disc: its square's, inside the disc */
		}
		/* degenerate seen from p (in the plane): by area */
	}
	double cos_l = fabs(v3_dot(e->n, d));
	return cos_l > 0.0 ? t * t / (cos_l * e->area) : 0.0;
}

/* By solid angle: rectangles directly, discs by the square around them
 * (a point outside the disc is no sample: *pdf = 0), triangles directly.
 * False when the shape is degenerate seen from p (then by area, as
 * emitter_pdf does). */
static bool solid_angle_sample(const emitter *e, vec3 p, double u1, double u2, vec3 *wi, double *pdf,
                               double *t)
{
	vec3 d;
	if (e->shape == EMITTER_TRIANGLE) {
		sph_tri st;
		if (!sph_tri_make(&st, e, p))
			return false;
		*wi = sph_tri_dir(&st, u1, u2);
		/* the distance to the triangle's plane along wi */
		double dn = v3_dot(*wi, e->n);
		*t = dn != 0.0 ? v3_dot(v3_sub(e->c, p), e->n) / dn : 0.0;
		*pdf = *t > 0.0 ? 1.0 / st.s : 0.0;
		return true;
	}
	sph_rect sr;
	if (!sph_rect_make(&sr, e, p))
		return false;
	vec3 q = sph_rect_point(&sr, u1, u2);
	d = v3_sub(q, p);
	*t = v3_len(d);
	*pdf = 0.0;
	if (!(*t > 0.0))
		return true;
	*wi = v3_scale(d, 1.0 / *t);
	if (e->shape == EMITTER_DISC) {
		/* inside the disc: |a| and |b| of q - c on u, v as a^2 + b^2 <= 1 */
		vec3 qc = v3_sub(q, e->c);
		double a = v3_dot(qc, e->u) / v3_len2(e->u), b = v3_dot(qc, e->v) / v3_len2(e->v);
		if (a * a + b * b > 1.0)
			return true;
	}
	*pdf = 1.0 / sr.s;
	return true;
}

bool emitter_sample(const emitter *e, vec3 p, double u1, double u2, vec3 *wi, double *pdf, double *t)
{
	if (e->shape == EMITTER_SPHERE) {
		vec3 pc = v3_sub(e->c, p);
		double d2 = v3_len2(pc), r2 = e->r * e->r;
		if (!(d2 > r2))
			return false; /* inside: left to the paths */
		double gap = cone_gap(r2, d2), cos_a = 1.0 - u1 * gap;
		double x, y;
		warp_circle(u2, &x, &y);
		double k2 = sqrt(pos(1.0 - cos_a * cos_a));
		vec3 ax = v3_scale(pc, 1.0 / sqrt(d2)), tu, tv;
		basis(ax, &tu, &tv);
		*wi = v3_add(v3_add(v3_scale(tu, x * k2), v3_scale(tv, y * k2)), v3_scale(ax, cos_a));
		*pdf = 1.0 / (2.0 * RT_PI * gap);
		/* the near side of the sphere along wi: |p + t wi - c| = r */
		double along = v3_dot(pc, *wi);
		*t = along - sqrt(pos(along * along - (d2 - r2)));
	} else if (near_enough(e, p) && solid_angle_sample(e, p, u1, u2, wi, pdf, t)) {
		return *pdf > 0.0;
	} else {
		double a, c;
		if (e->shape == EMITTER_RECT) {
			a = 2.0 * u1 - 1.0;
			c = 2.0 * u2 - 1.0;
		} else if (e->shape == EMITTER_DISC) {
			warp_disc(u1, u2, &a, &c);
		} else { /* uniform on the triangle (Turk, Graphics Gems 1990) */
			double su = sqrt(u1);
			a = 1.0 - su;
			c = u2 * su;
		}
		vec3 q = v3_add(e->c, v3_add(v3_scale(e->u, a), v3_scale(e->v, c)));
		vec3 d = v3_sub(q, p);
		*t = v3_len(d);
		if (!(*t > 0.0))
			return false;
		*wi = v3_scale(d, 1.0 / *t);
		*pdf = emitter_pdf(e, p, *wi, *t);
		if (!(*pdf > 0.0))
			return false;
	}
	return true;
}
