/* rtsh — the emissive surfaces the path tracer samples directly (path.c
 * weighs them against its own paths). */
#include "emitters.h"

#include <stdlib.h>

#include "warp.h"

/* --- emissive surfaces: sampled directly and found by the paths, the two
 * combined by multiple importance sampling with the power heuristic (Veach
 * & Guibas, "Optimally combining sampling techniques for Monte Carlo
 * rendering", SIGGRAPH 1995). */

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
			emitter e = {.object = (uint32_t)i};
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

double emitter_pdf(const emitter *e, vec3 p, vec3 d, double t)
{
	if (e->shape == EMITTER_SPHERE) {
		double d2 = v3_len2(v3_sub(e->c, p)), r2 = e->r * e->r;
		return d2 > r2 ? 1.0 / (2.0 * RT_PI * cone_gap(r2, d2)) : 0.0;
	}
	double cos_l = fabs(v3_dot(e->n, d));
	return cos_l > 0.0 ? t * t / (cos_l * e->area) : 0.0;
}

bool emitter_sample(const emitter *e, vec3 p, rng *g, vec3 *wi, double *pdf, double *t)
{
	if (e->shape == EMITTER_SPHERE) {
		vec3 pc = v3_sub(e->c, p);
		double d2 = v3_len2(pc), r2 = e->r * e->r;
		if (!(d2 > r2))
			return false; /* inside: left to the paths */
		double gap = cone_gap(r2, d2), cos_a = 1.0 - rng_next(g) * gap;
		double x, y, rr;
		disc_point(g, &x, &y, &rr);
		double k2 = sqrt(pos(1.0 - cos_a * cos_a) / rr);
		vec3 ax = v3_scale(pc, 1.0 / sqrt(d2)), tu, tv;
		basis(ax, &tu, &tv);
		*wi = v3_add(v3_add(v3_scale(tu, x * k2), v3_scale(tv, y * k2)), v3_scale(ax, cos_a));
		*pdf = 1.0 / (2.0 * RT_PI * gap);
		/* the near side of the sphere along wi: |p + t wi - c| = r */
		double along = v3_dot(pc, *wi);
		*t = along - sqrt(pos(along * along - (d2 - r2)));
	} else {
		double a, c;
		if (e->shape == EMITTER_RECT) {
			a = 2.0 * rng_next(g) - 1.0;
			c = 2.0 * rng_next(g) - 1.0;
		} else if (e->shape == EMITTER_DISC) {
			double rr;
			disc_point(g, &a, &c, &rr);
		} else { /* uniform on the triangle (Turk, Graphics Gems 1990) */
			double su = sqrt(rng_next(g));
			a = 1.0 - su;
			c = rng_next(g) * su;
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
