/* rtsh — preparing a scene for tracing, and the ray queries (world.h). */
#include "rtsh/world.h"

#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "integrators.h"
#include "rtsh/shape.h"

vec3 srgb255_to_linear(vec3 c)
{
	double v[3] = {c.x / 255.0, c.y / 255.0, c.z / 255.0};
	for (int i = 0; i < 3; i++) /* IEC 61966-2-1 */
		v[i] = v[i] <= 0.04045 ? v[i] / 12.92 : pow((v[i] + 0.055) / 1.055, 2.4);
	return v3(v[0], v[1], v[2]);
}

cam_view cam_view_make(const camera *c)
{
	cam_view v;
	v.pos = c->pos;
	v.fwd = v3_norm(c->dir);
	vec3 up_ref = fabs(v.fwd.y) > 0.999999 ? v3(0, 0, 1) : v3(0, 1, 0);
	v.right = v3_norm(v3_cross(up_ref, v.fwd));
	v.up = v3_cross(v.fwd, v.right);
	double fov = clampd(c->fov, 0.01, 179.99);
	v.tan_half = tan(deg_to_rad(fov) * 0.5);
	return v;
}

ray cam_ray(const cam_view *c, double fx, double fy, int w, int h)
{
	double u = (2.0 * fx / w - 1.0) * c->tan_half;
	double v = (1.0 - 2.0 * fy / h) * c->tan_half * ((double)h / w);
	vec3 d = v3_add(c->fwd, v3_add(v3_scale(c->right, u), v3_scale(c->up, v)));
	return (ray){c->pos, v3_norm(d)};
}

static mat_lin material_linear(const material *m)
{
	mat_lin l;
	l.albedo = srgb255_to_linear(m->color);
	l.diffuse = m->diffuse;
	l.specular = m->specular;
	l.shininess = m->shininess;
	l.reflective = m->reflective;
	l.fuzz = m->fuzz;
	l.metal = m->metal;
	l.ior = m->ior;
	l.emission = v3_scale(l.albedo, m->emission);
	l.checker = m->checker;
	l.light = -1; /* set by emitters_build */
	return l;
}

/* A sphere with a uniform scale, no shear and no texture that its rotation
 * could turn is traced directly in world space. */
static bool is_fast_sphere(const object *o)
{
	if (o->kind != OBJ_SPHERE || o->scale.x != o->scale.y || o->scale.y != o->scale.z)
		return false;
	for (int i = 0; i < 6; i++)
		if (o->shear[i] != 0.0)
			return false;
	return o->mat.checker == 0;
}

static bool make_prim(const object *o, uint32_t index, prim *p, box *b, rt_error *err)
{
	memset(p, 0, sizeof *p);
	p->kind = o->kind;
	p->object = index;
	if (o->kind == OBJ_TRIANGLE) {
		p->u.tri.v0 = o->tri[0];
		p->u.tri.e1 = v3_sub(o->tri[1], o->tri[0]);
		p->u.tri.e2 = v3_sub(o->tri[2], o->tri[0]);
		*b = object_bounds(o);
		return true;
	}
	if (is_fast_sphere(o)) {
		double r = o->scale.x * 0.5;
		p->fast_sphere = 1;
		p->u.sph.c = o->pos;
		p->u.sph.r2 = r * r;
		p->u.sph.inv_r = 1.0 / r;
		*b = (box){v3_sub(o->pos, v3_splat(r)), v3_add(o->pos, v3_splat(r))};
		return true;
	}
	xform x;
	if (!object_xform(o, &x))
		return rt_error_set(err, "object %u (%s) cannot be placed: its transform is not invertible",
		                    index + 1, obj_kind_name(o->kind));
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 4; j++)
			p->u.inv[i][j] = x.inv.m[i][j];
	*b = xf_box(&x, shape_local_bounds(o->kind));
	return true;
}

world *world_build(const scene *s, rt_error *err)
{
	world *w = calloc(1, sizeof *w);
	if (!w) {
		rt_error_set(err, "out of memory preparing the scene");
		return NULL;
	}
	camera c = scene_camera(s);
	w->cam = cam_view_make(&c);
	if (s->has_ambient)
		w->ambient = v3_scale(srgb255_to_linear(s->amb.color), s->amb.ratio);
	w->has_sky = s->has_sky;
	if (s->has_sky) {
		w->sky_zenith = v3_scale(srgb255_to_linear(s->sky.zenith), s->sky.strength);
		w->sky_horizon = v3_scale(srgb255_to_linear(s->sky.horizon), s->sky.strength);
	}
	size_t nplanes = 0;
	for (size_t i = 0; i < s->nobjs; i++)
		nplanes += s->objs[i].kind == OBJ_PLANE;
	size_t nbounded = s->nobjs - nplanes;
	w->lights = calloc(s->nlights ? s->nlights : 1, sizeof *w->lights);
	w->mats = calloc(s->nobjs ? s->nobjs : 1, sizeof *w->mats);
	w->prims = calloc(nbounded ? nbounded : 1, sizeof *w->prims);
	w->planes = calloc(nplanes ? nplanes : 1, sizeof *w->planes);
	box *bounds = calloc(nbounded ? nbounded : 1, sizeof *bounds);
	if (!w->lights || !w->mats || !w->prims || !w->planes || !bounds) {
		free(bounds);
		world_free(w);
		rt_error_set(err, "out of memory preparing the scene");
		return NULL;
	}
	w->nlights = s->nlights;
	for (size_t i = 0; i < s->nlights; i++) {
		w->lights[i].pos = s->lights[i].pos;
		w->lights[i].radiance = v3_scale(srgb255_to_linear(s->lights[i].color), s->lights[i].ratio);
	}
	w->nmats = s->nobjs;
	w->bounds = box_empty();
	double extent = v3_max_abs(c.pos);
	for (size_t i = 0; i < s->nobjs; i++) {
		const object *o = &s->objs[i];
		w->mats[i] = material_linear(&o->mat);
		prim *p = o->kind == OBJ_PLANE ? &w->planes[w->nplanes++] : &w->prims[w->nprims];
		box b;
		if (!make_prim(o, (uint32_t)i, p, o->kind == OBJ_PLANE ? &b : &bounds[w->nprims], err)) {
			free(bounds);
			world_free(w);
			return NULL;
		}
		if (o->kind == OBJ_PLANE) {
			extent = fmax(extent, v3_max_abs(o->pos));
		} else {
			w->bounds = box_union(w->bounds, bounds[w->nprims]);
			w->nprims++;
		}
	}
	if (!box_is_empty(w->bounds))
		extent = fmax(extent, fmax(v3_max_abs(w->bounds.lo), v3_max_abs(w->bounds.hi)));
	for (size_t i = 0; i < s->nlights; i++)
		extent = fmax(extent, v3_max_abs(s->lights[i].pos));
	w->eps = 1e-9 * fmax(1.0, extent);
	w->tree = bvh_build(w->prims, bounds, w->nprims, err);
	free(bounds);
	if (!w->tree || !emitters_build(w, s, err)) {
		world_free(w);
		return NULL;
	}
	return w;
}

void world_free(world *w)
{
	if (!w)
		return;
	free(w->lights);
	free(w->mats);
	free(w->prims);
	free(w->planes);
	free(w->emitters);
	bvh_free(w->tree);
	free(w);
}

/* --- primitive tests --- */

/* The nearest hit of one primitive in (tmin, tmax): *t and the unnormalised
 * normal in the primitive's own space (*nl). */
static inline bool prim_hit(const prim *p, const ray *r, double tmin, double tmax, double *t, vec3 *nl)
{
	if (p->fast_sphere) {
		vec3 oc = v3_sub(r->o, p->u.sph.c);
		double b = v3_dot(oc, r->d), a = v3_dot(r->d, r->d);
		double c = v3_dot(oc, oc) - p->u.sph.r2;
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
	if (p->kind == OBJ_TRIANGLE)
		return tri_intersect(p->u.tri.v0, p->u.tri.e1, p->u.tri.e2, r->o, r->d, tmin, tmax, t);
	const double(*m)[4] = p->u.inv;
	vec3 o = {m[0][0] * r->o.x + m[0][1] * r->o.y + m[0][2] * r->o.z + m[0][3],
	          m[1][0] * r->o.x + m[1][1] * r->o.y + m[1][2] * r->o.z + m[1][3],
	          m[2][0] * r->o.x + m[2][1] * r->o.y + m[2][2] * r->o.z + m[2][3]};
	vec3 d = {m[0][0] * r->d.x + m[0][1] * r->d.y + m[0][2] * r->d.z,
	          m[1][0] * r->d.x + m[1][1] * r->d.y + m[1][2] * r->d.z,
	          m[2][0] * r->d.x + m[2][1] * r->d.y + m[2][2] * r->d.z};
	return shape_table[p->kind].intersect(o, d, tmin, tmax, t, nl);
}

static inline bool prim_occluded(const prim *p, const ray *r, double tmin, double tmax)
{
	if (p->fast_sphere || p->kind == OBJ_TRIANGLE) {
		double t;
		vec3 n;
		return prim_hit(p, r, tmin, tmax, &t, &n);
	}
	const double(*m)[4] = p->u.inv;
	vec3 o = {m[0][0] * r->o.x + m[0][1] * r->o.y + m[0][2] * r->o.z + m[0][3],
	          m[1][0] * r->o.x + m[1][1] * r->o.y + m[1][2] * r->o.z + m[1][3],
	          m[2][0] * r->o.x + m[2][1] * r->o.y + m[2][2] * r->o.z + m[2][3]};
	vec3 d = {m[0][0] * r->d.x + m[0][1] * r->d.y + m[0][2] * r->d.z,
	          m[1][0] * r->d.x + m[1][1] * r->d.y + m[1][2] * r->d.z,
	          m[2][0] * r->d.x + m[2][1] * r->d.y + m[2][2] * r->d.z};
	return shape_table[p->kind].occluded(o, d, tmin, tmax);
}

/* Fills the hit record for the primitive found nearest. */
static void finish_hit(const prim *p, const ray *r, double t, vec3 nl, hit *h)
{
	h->t = t;
	h->p = ray_at(*r, t);
	h->object = p->object;
	vec3 n;
	if (p->fast_sphere) {
		n = v3_scale(v3_sub(h->p, p->u.sph.c), p->u.sph.inv_r);
		h->local = n;
	} else if (p->kind == OBJ_TRIANGLE) {
		n = v3_cross(p->u.tri.e1, p->u.tri.e2);
		h->local = h->p;
	} else {
		const double(*m)[4] = p->u.inv;
		n = (vec3){m[0][0] * nl.x + m[1][0] * nl.y + m[2][0] * nl.z,
		           m[0][1] * nl.x + m[1][1] * nl.y + m[2][1] * nl.z,
		           m[0][2] * nl.x + m[1][2] * nl.y + m[2][2] * nl.z};
		vec3 q = h->p;
		h->local = (vec3){m[0][0] * q.x + m[0][1] * q.y + m[0][2] * q.z + m[0][3],
		                  m[1][0] * q.x + m[1][1] * q.y + m[1][2] * q.z + m[1][3],
		                  m[2][0] * q.x + m[2][1] * q.y + m[2][2] * q.z + m[2][3]};
	}
	n = v3_norm(n);
	h->front = v3_dot(n, r->d) < 0.0;
	h->n = n;
}

/* --- the tree walk --- */

static inline double mn(double a, double b) { return a < b ? a : b; }
static inline double mx(double a, double b) { return a > b ? a : b; }

static inline bool slab(const box *b, vec3 o, vec3 inv, double tmin, double tmax)
{
	double tx0 = (b->lo.x - o.x) * inv.x, tx1 = (b->hi.x - o.x) * inv.x;
	double ty0 = (b->lo.y - o.y) * inv.y, ty1 = (b->hi.y - o.y) * inv.y;
	double tz0 = (b->lo.z - o.z) * inv.z, tz1 = (b->hi.z - o.z) * inv.z;
	/* Plain comparisons, not fmin/fmax: those are library calls on x86-64. */
	double lo = mx(mx(mn(tx0, tx1), mn(ty0, ty1)), mx(mn(tz0, tz1), tmin));
	double hi = mn(mn(mx(tx0, tx1), mx(ty0, ty1)), mn(mx(tz0, tz1), tmax));
	return lo <= hi;
}

static vec3 inverse_dir(vec3 d)
{
	return v3(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
}

bool world_intersect(const world *w, const ray *r, double tmin, double tmax, hit *h)
{
	const prim *best = NULL;
	vec3 best_n = {0, 0, 0};
	double t;
	vec3 nl;
	for (size_t i = 0; i < w->nplanes; i++)
		if (prim_hit(&w->planes[i], r, tmin, tmax, &t, &nl)) {
			tmax = t;
			best = &w->planes[i];
			best_n = nl;
		}
	if (w->nprims) {
		const bvh_node *nodes = w->tree->nodes;
		vec3 inv = inverse_dir(r->d);
		int neg[3] = {r->d.x < 0, r->d.y < 0, r->d.z < 0};
		uint32_t stack[BVH_MAX_DEPTH + 2];
		int sp = 0;
		uint32_t ni = 0;
		for (;;) {
			const bvh_node *n = &nodes[ni];
			if (slab(&n->b, r->o, inv, tmin, tmax)) {
				if (n->count) {
					const prim *p = &w->prims[n->first_or_right];
					for (unsigned k = 0; k < n->count; k++)
						if (prim_hit(&p[k], r, tmin, tmax, &t, &nl)) {
							tmax = t;
							best = &p[k];
							best_n = nl;
						}
				} else {
					/* Visit the child on the ray's near side first. */
					if (neg[n->axis]) {
						stack[sp++] = ni + 1;
						ni = n->first_or_right;
					} else {
						stack[sp++] = n->first_or_right;
						ni = ni + 1;
					}
					continue;
				}
			}
			if (sp == 0)
				break;
			ni = stack[--sp];
		}
	}
	if (!best)
		return false;
	finish_hit(best, r, tmax, best_n, h);
	return true;
}

bool world_occluded(const world *w, const ray *r, double tmin, double tmax)
{
	for (size_t i = 0; i < w->nplanes; i++)
		if (prim_occluded(&w->planes[i], r, tmin, tmax))
			return true;
	if (!w->nprims)
		return false;
	const bvh_node *nodes = w->tree->nodes;
	vec3 inv = inverse_dir(r->d);
	uint32_t stack[BVH_MAX_DEPTH + 2];
	int sp = 0;
	uint32_t ni = 0;
	for (;;) {
		const bvh_node *n = &nodes[ni];
		if (slab(&n->b, r->o, inv, tmin, tmax)) {
			if (n->count) {
				const prim *p = &w->prims[n->first_or_right];
				for (unsigned k = 0; k < n->count; k++)
					if (prim_occluded(&p[k], r, tmin, tmax))
						return true;
			} else {
				stack[sp++] = n->first_or_right;
				ni = ni + 1;
				continue;
			}
		}
		if (sp == 0)
			return false;
		ni = stack[--sp];
	}
}

bool world_intersect_brute(const world *w, const ray *r, double tmin, double tmax, hit *h)
{
	const prim *best = NULL;
	vec3 best_n = {0, 0, 0};
	double t;
	vec3 nl;
	for (size_t i = 0; i < w->nplanes; i++)
		if (prim_hit(&w->planes[i], r, tmin, tmax, &t, &nl)) {
			tmax = t;
			best = &w->planes[i];
			best_n = nl;
		}
	for (size_t i = 0; i < w->nprims; i++)
		if (prim_hit(&w->prims[i], r, tmin, tmax, &t, &nl)) {
			tmax = t;
			best = &w->prims[i];
			best_n = nl;
		}
	if (!best)
		return false;
	finish_hit(best, r, tmax, best_n, h);
	return true;
}

bool world_occluded_brute(const world *w, const ray *r, double tmin, double tmax)
{
	for (size_t i = 0; i < w->nplanes; i++)
		if (prim_occluded(&w->planes[i], r, tmin, tmax))
			return true;
	for (size_t i = 0; i < w->nprims; i++)
		if (prim_occluded(&w->prims[i], r, tmin, tmax))
			return true;
	return false;
}
