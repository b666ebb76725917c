/* rtsh — preparing a scene for tracing, and the ray queries (world.h). */
#include "rtsh/world.h"

#include <float.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/bvh/bvh.h"
#include "core/prim_hit.h"
#include "emitters.h"
#include "envmap.h"
#include "surface.h"
#include "ggx.h"
#include "rtsh/memory.h"
#include "rtsh/shape.h"

/* mat_lin_make into *l, whose bytes are zero on entry: world_build fills
 * its calloc'ed array in place rather than copying a zeroed value in and out
 * (a million objects). */
/* srgb255_to_linear(c), with tab its table (srgb8_table): whole codes
 * from the table in line, the same bits; others through the call. */
static inline vec3 srgb255_lin(const double *tab, vec3 c)
{
	if (c.x >= 0.0 && c.x <= 255.0 && c.x == (double)(int)c.x && c.y >= 0.0 && c.y <= 255.0 &&
	    c.y == (double)(int)c.y && c.z >= 0.0 && c.z <= 255.0 && c.z == (double)(int)c.z)
		return v3(tab[(int)c.x], tab[(int)c.y], tab[(int)c.z]);
	return srgb255_to_linear(c);
}

static inline void mat_lin_fill(mat_lin *restrict l, const material *m, const double *tab)
{
	l->albedo = srgb255_lin(tab, m->color);
	l->diffuse = m->diffuse;
	l->specular = m->specular;
	l->shininess = m->shininess;
	l->reflective = m->reflective;
	l->fuzz = m->fuzz;
	l->metal = m->metal;
	l->ior = m->ior;
	const material_pbr *p = m->pbr;
	bool own_emit = p && p->emit_color.x >= 0.0 && p->emit_color.y >= 0.0 && p->emit_color.z >= 0.0;
	l->emission = v3_scale(own_emit ? srgb255_to_linear(p->emit_color) : l->albedo, m->emission);
	l->checker = m->checker;
	l->light = -1; /* set by emitters_build */
	l->tx = NULL;  /* set by surf_material */
	if (!p)
		return;
	l->family = MAT_PBR;
	l->ior = m->ior >= 1.0 ? m->ior : 1.5;
	l->pbr.roughness = (float)(p->roughness >= 0.0 ? p->roughness : 1.0);
	l->pbr.metallic = (float)p->metallic;
	l->pbr.transmission = (float)p->transmission;
	l->thin = p->thin != 0;
	l->pbr.clearcoat = (float)p->clearcoat;
	l->pbr.clearcoat_roughness = (float)p->clearcoat_roughness;
	l->pbr.specular_factor = (float)p->specular_factor;
	l->pbr.single = p->multiscatter == 0;
	vec3 sc = srgb255_to_linear(p->specular_color);
	l->pbr.specular_color[0] = (float)sc.x;
	l->pbr.specular_color[1] = (float)sc.y;
	l->pbr.specular_color[2] = (float)sc.z;
	if (p->att_dist > 0.0) {
		vec3 a = srgb255_to_linear(p->att_color);
		/* Beer-Lambert: white light keeps a of itself after att_dist */
		double c[3] = {a.x, a.y, a.z};
		for (int i = 0; i < 3; i++)
			l->pbr.sigma_a[i] = (float)(c[i] > 0 ? -log(c[i]) / p->att_dist : 1e30);
	}
	pbr_lin_finish(l);
}

mat_lin mat_lin_make(const material *m)
{
	mat_lin l = {0};
	mat_lin_fill(&l, m, srgb8_table());
	return l;
}

/* world_build's byte of an object: its kind flags (scene.h, below 16) and
 * this bit when is_fast_sphere */
enum { OBJ_FAST_SPHERE = 0x80 };
_Static_assert((KIND_UNBOUNDED | KIND_VERTICES | KIND_TUBE | KIND_MODEL) < OBJ_FAST_SPHERE,
               "the kind flags fit below OBJ_FAST_SPHERE");

/* A sphere with a uniform scale, no shear and no texture that its rotation
 * could turn is traced directly in world space. */
static inline bool is_fast_sphere(const object *o)
{
	if (o->kind >= OBJ_KIND_COUNT || !shape_kinds[o->kind]->world_sphere || o->scale.x != o->scale.y || o->scale.y != o->scale.z)
		return false;
	/* every shear 0 or -0 (a NaN is not 0): the bits less the sign all 0 */
	uint64_t bits = 0;
	for (int i = 0; i < 6; i++) {
		uint64_t u;
		memcpy(&u, &o->shear[i], sizeof u);
		bits |= u << 1;
	}
	return bits == 0 && o->mat.checker == 0 && !o->mat.texture && !o->mat.normalmap && !o->mat.bump;
}

/* The primitive of object `index`, o, a fast sphere (is_fast_sphere), and
 * its world bounds. world_build makes these twice, the box in its object
 * loop and the primitive in tree order (reorder), so that a million spheres
 * are written once, where they end. */
static inline void fast_sphere_prim(const object *o, uint32_t index, prim *p)
{
	memset(p, 0, sizeof *p);
	p->object = index;
	p->tag = PRIM_SPHERE;
	p->u.sph.c = o->pos;
	p->u.sph.r = o->scale.x * 0.5;
}

static inline box fast_sphere_box(const object *o)
{
	double r = o->scale.x * 0.5;
	return (box){v3_sub(o->pos, v3_splat(r)), v3_add(o->pos, v3_splat(r))};
}

/* Fills p (and the side record it needs) for object o and its world bounds
 * *b (planes: see make_plane). flags is obj_kind_flags(o->kind) and fast
 * is_fast_sphere(o): world_build works them out once an object. */
static bool make_prim(world *w, const object *o, unsigned flags, bool fast, uint32_t index, prim *p, box *b,
                      rt_error *err)
{
	if (flags & KIND_MODEL)
		return surf_make_inst(w, o, index, p, b, err);
	memset(p, 0, sizeof *p);
	p->object = index;
	if (flags & KIND_VERTICES) {
		p->tag = PRIM_TRIANGLE;
		p->u.index = (uint32_t)w->ntris;
		prim_tri *t = &w->tris[w->ntris++];
		t->v0 = o->tri[0];
		t->e1 = v3_sub(o->tri[1], o->tri[0]);
		t->e2 = v3_sub(o->tri[2], o->tri[0]);
		*b = object_bounds(o);
		return true;
	}
	if (fast) {
		fast_sphere_prim(o, index, p);
		*b = fast_sphere_box(o);
		return true;
	}
	xform x;
	if (!object_xform(o, &x))
		return rt_error_set(err, "object %u (%s) cannot be placed: its transform is not invertible",
		                    index + 1, obj_kind_name(o->kind));
	p->tag = PRIM_SHAPE;
	p->u.index = (uint32_t)w->nshapes;
	prim_shape *sh = &w->shapes[w->nshapes++];
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 4; j++)
			sh->inv[i][j] = x.inv.m[i][j];
	sh->kind = o->kind;
	sh->tube = o->tube;
	*b = xf_box(&x, shape_local_bounds(o->kind, o->tube));
	return true;
}

static bool make_plane(world *w, const object *o, uint32_t index, prim_plane *pl, rt_error *err)
{
	prim p;
	box b;
	if (!make_prim(w, o, obj_kind_flags(o->kind), is_fast_sphere(o), index, &p, &b, err))
		return false;
	const prim_shape *sh = &w->shapes[p.u.index];
	for (int j = 0; j < 4; j++)
		pl->h[j] = sh->inv[1][j];
	pl->n = v3_norm(v3(pl->h[0], pl->h[1], pl->h[2]));
	pl->object = index;
	pl->shape = p.u.index;
	return true;
}

/* Puts the primitives in tree order, and the side records in the order of
 * the primitives that use them (planes first), so that a leaf's data is
 * contiguous in memory. A fast sphere (OBJ_FAST_SPHERE in kf, by object)
 * is made here from its object, once: w->prims holds only the others (a
 * scene of spheres leaves that array's pages untouched). Bounded primitive
 * j is object pobj[j], or object j when pobj is NULL (no planes). */
/* The primitives of tree places [begin, end) made or copied into prims
 * (reorder's first loop; halves of it run in two threads). */
typedef struct reorder_job {
	const world *w;
	const scene *s;
	const uint8_t *kf;
	const uint32_t *pobj, *order;
	prim *prims;
	size_t begin, end;
} reorder_job;

static void *reorder_run(void *arg)
{
	const reorder_job *j = arg;
	const object *objs = j->s->objs;
	const uint32_t *order = j->order, *pobj = j->pobj;
	enum { AHEAD = 16 }; /* the objects are read at random: fetched ahead */
	for (size_t i = j->begin; i < j->end; i++) {
		if (i + AHEAD < j->end) {
			uint32_t ja = order[i + AHEAD];
			const object *oa = &objs[pobj ? pobj[ja] : ja];
			__builtin_prefetch(&oa->pos);
			__builtin_prefetch(&oa->scale);
		}
		uint32_t k = order[i], ob = pobj ? pobj[k] : k;
		if (j->kf[ob] & OBJ_FAST_SPHERE)
			fast_sphere_prim(&objs[ob], ob, &j->prims[i]);
		else
			j->prims[i] = j->w->prims[k];
	}
	return NULL;
}

/* Below this many primitives reorder's first loop stays in one thread. */
#define REORDER_APART_MIN 65536

static bool reorder(world *w, const scene *s, const uint8_t *kf, const uint32_t *pobj, const uint32_t *order,
                    int threads)
{
	/* walked in tree order by every ray: huge pages spare the TLB */
	prim *prims = mem_alloc_huge(w->nprims * sizeof *prims);
	prim_shape *shapes = mem_alloc_huge(w->nshapes * sizeof *shapes);
	prim_tri *tris = mem_alloc_huge(w->ntris * sizeof *tris);
	if (!prims || !shapes || !tris) {
		free(prims);
		free(shapes);
		free(tris);
		return false;
	}
	/* with 2 threads the first half by another one: each place is
	 * written from its own object, the same bytes either way */
	reorder_job all = {w, s, kf, pobj, order, prims, 0, w->nprims}, first = all;
	pthread_t th;
	bool apart = threads > 1 && w->nprims >= REORDER_APART_MIN;
	if (apart) {
		first.end = all.begin = w->nprims / 2;
		apart = pthread_create(&th, NULL, reorder_run, &first) == 0;
		if (!apart)
			all.begin = 0;
	}
	reorder_run(&all);
	if (apart)
		pthread_join(th, NULL);
	size_t ns = 0, nt = 0;
	for (size_t i = 0; i < w->nplanes; i++) {
		shapes[ns] = w->shapes[w->planes[i].shape];
		w->planes[i].shape = (uint32_t)ns++;
	}
	/* (each plane has one shape: without bounded shapes or triangles
	 * there is nothing to renumber) */
	for (size_t i = 0; (w->nshapes > w->nplanes || w->ntris) && i < w->nprims; i++) {
		prim *p = &prims[i];
		if (p->tag == PRIM_SHAPE) {
			shapes[ns] = w->shapes[p->u.index];
			p->u.index = (uint32_t)ns++;
		} else if (p->tag == PRIM_TRIANGLE) {
			tris[nt] = w->tris[p->u.index];
			p->u.index = (uint32_t)nt++;
		}
	}
	free(w->prims);
	free(w->shapes);
	free(w->tris);
	w->prims = prims;
	w->shapes = shapes;
	w->tris = tris;
	return true;
}

/* A world's materials made by a second thread (world_build_threads, a
 * scene without models, whose instances read their object's material):
 * prefaulted and filled while the calling thread makes the primitives and
 * references; the textures (surf_material) follow in object order once it
 * is done, so that the world and any error are the one thread's. */
typedef struct mats_job {
	mat_lin *mats;
	const object *objs;
	size_t n;
} mats_job;

static void *mats_fill_run(void *arg)
{
	mats_job *j = arg;
	mem_prefault(j->mats, j->n * sizeof *j->mats);
	const double *tab = srgb8_table();
	for (size_t i = 0; i < j->n; i++)
		mat_lin_fill(&j->mats[i], &j->objs[i].mat, tab); /* calloc'ed: zero */
	return NULL;
}

/* The counts of world_build_threads's first loop over objects [begin,
 * end), and each one's kind flags in kf (halves of it run in two threads). */
typedef struct counts_job {
	const object *objs;
	uint8_t *kf;
	size_t begin, end;
	size_t nplanes, ntris, nshapes, nmodels;
} counts_job;

static void *counts_run(void *arg)
{
	counts_job *j = arg;
	size_t nplanes = 0, ntris = 0, nshapes = 0, nmodels = 0;
	/* obj_kind_flags of each kind, looked up here rather than called an
	 * object (the same flags; 0 for a kind out of range, as it gives) */
	unsigned kflags[OBJ_KIND_COUNT];
	for (int k = 0; k < OBJ_KIND_COUNT; k++)
		kflags[k] = obj_kind_flags((obj_kind)k);
	for (size_t i = j->begin; i < j->end; i++) {
		const object *o = &j->objs[i];
		unsigned f = (unsigned)o->kind < OBJ_KIND_COUNT ? kflags[o->kind] : 0;
		bool fast = !(f & (KIND_VERTICES | KIND_MODEL)) && is_fast_sphere(o);
		j->kf[i] = (uint8_t)(f | (fast ? OBJ_FAST_SPHERE : 0));
		nplanes += (f & KIND_UNBOUNDED) != 0;
		ntris += (f & KIND_VERTICES) != 0;
		nshapes += !(f & (KIND_VERTICES | KIND_MODEL)) && !fast;
		nmodels += (f & KIND_MODEL) != 0;
	}
	j->nplanes = nplanes;
	j->ntris = ntris;
	j->nshapes = nshapes;
	j->nmodels = nmodels;
	return NULL;
}

/* a = a u b for the world's bounds, in line rather than box_union's six
 * calls of fmin and fmax: the same coordinates for these (a NaN in b is
 * passed over, as they pass it; of -0 and +0 either may stay, which the
 * extent made from the bounds, of absolute values, does not see). */
static inline void bounds_add(box *a, const box *b)
{
	a->lo.x = b->lo.x < a->lo.x ? b->lo.x : a->lo.x;
	a->lo.y = b->lo.y < a->lo.y ? b->lo.y : a->lo.y;
	a->lo.z = b->lo.z < a->lo.z ? b->lo.z : a->lo.z;
	a->hi.x = b->hi.x > a->hi.x ? b->hi.x : a->hi.x;
	a->hi.y = b->hi.y > a->hi.y ? b->hi.y : a->hi.y;
	a->hi.z = b->hi.z > a->hi.z ? b->hi.z : a->hi.z;
}

/* Below this many objects the counts stay in one thread. */
#define COUNTS_APART_MIN 65536

/* surf_material for the objects [0, n) that need it, in order. */
static bool mats_textures(world *w, const scene *s, size_t n, rt_error *err)
{
	for (size_t i = 0; i < n; i++)
		if (surf_material_needed(&s->objs[i]) && !surf_material(w, &s->objs[i], (uint32_t)i, err))
			return false;
	return true;
}

/* Fewer objects than this fill their materials in the calling thread. */
#define MATS_APART_MIN 4096

world *world_build(const scene *s, rt_error *err)
{
	return world_build_threads(s, 1, NULL, err);
}

world *world_build_cancel(const scene *s, const atomic_bool *cancel, rt_error *err)
{
	return world_build_threads(s, 1, cancel, err);
}

world *world_build_threads(const scene *s, int threads, const atomic_bool *cancel, rt_error *err)
{
	world *w = calloc(1, sizeof *w);
	if (!w) {
		rt_error_set(err, "out of memory preparing the scene");
		return NULL;
	}
	w->cancel = cancel;
	atomic_init(&w->refs, 1);
	camera c = scene_camera(s);
	w->cam = cam_view_make(&c);
	if (s->has_ambient)
		w->ambient = v3_scale(srgb255_to_linear(s->amb.color), s->amb.ratio);
	w->has_sky = s->has_sky;
	if (s->has_sky && s->sky.file) {
		envmap *env = envmap_new(s->sky.file, s->sky.strength, s->sky.rotation, cancel, err);
		if (!env) {
			world_free(w);
			return NULL;
		}
		w->env = env;
	} else if (s->has_sky) {
		w->sky_zenith = v3_scale(srgb255_to_linear(s->sky.zenith), s->sky.strength);
		w->sky_horizon = v3_scale(srgb255_to_linear(s->sky.horizon), s->sky.strength);
	}
	/* Each object's kind flags, with OBJ_FAST_SPHERE for is_fast_sphere: the
	 * counts here and make_prim below read them (one test an object) */
	uint8_t *kf = malloc(s->nobjs ? s->nobjs : 1);
	if (!kf) {
		world_free(w);
		rt_error_set(err, "out of memory preparing the scene (%zu objects)", s->nobjs);
		return NULL;
	}
	/* with 2 threads the first half by another one (sums and bytes by
	 * object: the same either way) */
	counts_job cj[2] = {{s->objs, kf, 0, s->nobjs, 0, 0, 0, 0}, {s->objs, kf, 0, 0, 0, 0, 0, 0}};
	pthread_t ct;
	bool counts_apart = threads > 1 && s->nobjs >= COUNTS_APART_MIN;
	if (counts_apart) {
		cj[1].end = cj[0].begin = s->nobjs / 2;
		counts_apart = pthread_create(&ct, NULL, counts_run, &cj[1]) == 0;
		if (!counts_apart)
			cj[0].begin = 0;
	}
	counts_run(&cj[0]);
	if (counts_apart)
		pthread_join(ct, NULL);
	size_t nplanes = cj[0].nplanes + cj[1].nplanes, ntris = cj[0].ntris + cj[1].ntris,
	       nshapes = cj[0].nshapes + cj[1].nshapes, nmodels = cj[0].nmodels + cj[1].nmodels;
	bool mats_apart = threads > 1 && nmodels == 0 && s->nobjs >= MATS_APART_MIN;
	size_t nbounded = s->nobjs - nplanes;
	w->lights = calloc(s->nlights ? s->nlights : 1, sizeof *w->lights);
	w->mats = calloc(s->nobjs ? s->nobjs : 1, sizeof *w->mats);
	w->prims = malloc((nbounded ? nbounded : 1) * sizeof *w->prims);
	w->planes = malloc((nplanes ? nplanes : 1) * sizeof *w->planes);
	w->shapes = malloc((nshapes ? nshapes : 1) * sizeof *w->shapes);
	w->tris = malloc((ntris ? ntris : 1) * sizeof *w->tris);
	/* each primitive's box as the tree builder takes it (floats, 32 bytes) */
	bvh_fbox *refs = malloc((nbounded ? nbounded : 1) * sizeof *refs);
	uint32_t *order = malloc((nbounded ? nbounded : 1) * sizeof *order);
	/* the object of each bounded primitive, when planes make them differ */
	uint32_t *pobj = nplanes ? malloc((nbounded ? nbounded : 1) * sizeof *pobj) : NULL;
	if (!w->lights || !w->mats || !w->prims || !w->planes || !w->shapes || !w->tris || !refs || !order ||
	    (nplanes && !pobj)) {
		mem_free_all(refs, order, pobj, kf);
		world_free(w);
		rt_error_set(err, "out of memory preparing the scene (%zu objects)", s->nobjs);
		return NULL;
	}
	/* written whole below: their pages made at once, not a fault each */
	if (!mats_apart)
		mem_prefault(w->mats, s->nobjs * sizeof *w->mats);
	mem_prefault(refs, nbounded * sizeof *refs);
	mem_prefault(order, nbounded * sizeof *order);
	w->nlights = s->nlights;
	for (size_t i = 0; i < s->nlights; i++) {
		const light *sl = &s->lights[i];
		light_lin *l = &w->lights[i];
		l->pos = sl->pos;
		l->radiance = v3_scale(srgb255_to_linear(sl->color), sl->ratio);
		l->kind = sl->kind;
		if (sl->kind != LIGHT_MINIRT) {
			/* I candela at d give I / d^2 lux: pi L = I (see light_at) */
			l->radiance = v3_scale(l->radiance, sl->intensity / RT_PI);
			l->dir = v3_len(sl->dir) > 0 ? v3_norm(sl->dir) : v3(0, -1, 0);
			l->range = sl->range;
			double ci = cos(deg_to_rad(sl->inner)), co = cos(deg_to_rad(sl->outer));
			l->cos_outer = co;
			l->cone_scale = 1.0 / fmax(1e-3, ci - co);
		}
	}
	w->nmats = s->nobjs;
	if (!surf_begin(w, s, err)) {
		mem_free_all(refs, order, pobj, kf);
		world_free(w);
		return NULL;
	}
	mats_job mj = {w->mats, s->objs, s->nobjs};
	pthread_t mt;
	if (mats_apart && pthread_create(&mt, NULL, mats_fill_run, &mj) != 0) {
		mats_apart = false; /* filled below, unprefaulted */
	}
	w->bounds = box_empty();
	double extent = v3_max_abs(c.pos);
	const double *tab = srgb8_table();
	for (size_t i = 0; i < s->nobjs; i++) {
		const object *o = &s->objs[i];
		if ((i & 0xffff) == 0 && cancel && atomic_load(cancel)) {
			if (mats_apart)
				pthread_join(mt, NULL);
			mem_free_all(refs, order, pobj, kf);
			world_free(w);
			rt_error_set(err, "stopped");
			return NULL;
		}
		if (!mats_apart)
			mat_lin_fill(&w->mats[i], &o->mat, tab); /* calloc'ed: zero */
		box bx;
		unsigned f = kf[i] & ~(unsigned)OBJ_FAST_SPHERE;
		bool plane = (f & KIND_UNBOUNDED) != 0, fast = (kf[i] & OBJ_FAST_SPHERE) != 0;
		/* (tx is NULL already when surf_material has nothing to do; a
		 * fast sphere's primitive is made by reorder) */
		if ((!mats_apart && surf_material_needed(o) && !surf_material(w, o, (uint32_t)i, err)) ||
		    (plane  ? !make_plane(w, o, (uint32_t)i, &w->planes[w->nplanes], err)
		     : fast ? (bx = fast_sphere_box(o), false)
		            : !make_prim(w, o, f, false, (uint32_t)i, &w->prims[w->nprims], &bx, err))) {
			if (mats_apart) {
				/* one thread would have met a texture's error first */
				pthread_join(mt, NULL);
				rt_error first;
				if (!mats_textures(w, s, i + 1, &first) && err)
					*err = first;
			}
			mem_free_all(refs, order, pobj, kf);
			world_free(w);
			return NULL;
		}
		if (plane) {
			w->nplanes++;
			extent = fmax(extent, v3_max_abs(o->pos));
		} else {
			bounds_add(&w->bounds, &bx);
			/* what a test costs, relative to a world-space sphere, for the
			 * SAH: a transformed shape is a matrix, a call and a quadric or
			 * slabs (8 gave the fastest mixed scenes: 3000 generated shapes
			 * render 15% faster than with 4, and 40% faster than with every
			 * cost 1) */
			bool tri = (f & (KIND_VERTICES | KIND_MODEL)) == KIND_VERTICES;
			float cost = fast ? 1.0f : tri ? 2.0f : shape_kinds[o->kind]->cost;
			bvh_ref_set(&refs[w->nprims], &bx, cost);
			if (pobj)
				pobj[w->nprims] = (uint32_t)i;
			w->nprims++;
		}
	}
	if (mats_apart) {
		pthread_join(mt, NULL);
		if (!mats_textures(w, s, s->nobjs, err)) {
			mem_free_all(refs, order, pobj, kf);
			world_free(w);
			return NULL;
		}
	}
	if (!box_is_empty(w->bounds))
		extent = fmax(extent, fmax(v3_max_abs(w->bounds.lo), v3_max_abs(w->bounds.hi)));
	for (size_t i = 0; i < s->nlights; i++)
		extent = fmax(extent, v3_max_abs(s->lights[i].pos));
	w->eps = 1e-9 * fmax(1.0, extent);
	w->tree = bvh_build(refs, w->nprims, order, threads, cancel, err);
	free(refs);
	bool ok = w->tree && reorder(w, s, kf, pobj, order, threads);
	mem_free_all(order, pobj, kf);
	if (w->tree && !ok)
		rt_error_set(err, "out of memory preparing the scene (%zu objects)", s->nobjs);
	if (!ok || !emitters_build(w, s, err)) {
		world_free(w);
		return NULL;
	}
	w->cancel = NULL;
	return w;
}

const world *world_retain(const world *w)
{
	if (w)
		atomic_fetch_add_explicit(&((world *)w)->refs, 1, memory_order_relaxed);
	return w;
}

/* The last reference frees: the release orders every use of the world by
 * any thread before the free (acquire on the last). */
void world_release(const world *cw)
{
	world *w = (world *)cw;
	if (!w || atomic_fetch_sub_explicit(&w->refs, 1, memory_order_acq_rel) != 1)
		return;
	surf_free(w);
	envmap_free((envmap *)w->env);
	bvh_free(w->tree);
	mem_free_all(w->lights, w->mats, w->prims, w->planes, w->shapes, w->tris, w->emitters, w);
}

void world_free(world *w)
{
	world_release(w);
}

/* --- primitive tests --- */

/* The ray in the object space of a shape (its direction not renormalised,
 * so t is the same in both spaces). */
static inline void to_object(const prim_shape *sh, const ray *r, vec3 *o, vec3 *d)
{
	const double(*m)[4] = sh->inv;
	*o = (vec3){m[0][0] * r->o.x + m[0][1] * r->o.y + m[0][2] * r->o.z + m[0][3],
	            m[1][0] * r->o.x + m[1][1] * r->o.y + m[1][2] * r->o.z + m[1][3],
	            m[2][0] * r->o.x + m[2][1] * r->o.y + m[2][2] * r->o.z + m[2][3]};
	*d = (vec3){m[0][0] * r->d.x + m[0][1] * r->d.y + m[0][2] * r->d.z,
	            m[1][0] * r->d.x + m[1][1] * r->d.y + m[1][2] * r->d.z,
	            m[2][0] * r->d.x + m[2][1] * r->d.y + m[2][2] * r->d.z};
}

/* A triangle or a transformed shape (spheres are tested inline): *t and,
 * for a shape, the unnormalised normal in its object space (*nl). */
static bool other_hit(const world *w, const prim *p, const ray *r, double tmin, double tmax, double *t,
                      vec3 *nl)
{
	if (p->tag == PRIM_TRIANGLE) {
		const prim_tri *tr = &w->tris[p->u.index];
		return tri_intersect(tr->v0, tr->e1, tr->e2, r->o, r->d, tmin, tmax, t);
	}
	if (p->tag == PRIM_MESH)
		return surf_inst_hit(w, p, r, tmin, tmax, t, nl, false);
	const prim_shape *sh = &w->shapes[p->u.index];
	vec3 o, d;
	to_object(sh, r, &o, &d);
	return shape_kinds[sh->kind]->intersect(o, d, sh->tube, tmin, tmax, t, nl);
}

static bool other_occluded(const world *w, const prim *p, const ray *r, double tmin, double tmax)
{
	if (p->tag == PRIM_TRIANGLE) {
		double t;
		const prim_tri *tr = &w->tris[p->u.index];
		return tri_intersect(tr->v0, tr->e1, tr->e2, r->o, r->d, tmin, tmax, &t);
	}
	if (p->tag == PRIM_MESH)
		return surf_inst_occluded(w, p, r, tmin, tmax);
	const prim_shape *sh = &w->shapes[p->u.index];
	vec3 o, d;
	to_object(sh, r, &o, &d);
	return shape_kinds[sh->kind]->occluded(o, d, sh->tube, tmin, tmax);
}

/* The nearest hit of one primitive in (tmin, tmax); coherent: r is a
 * camera ray (world_trace_coherent). */
static inline bool prim_hit(const world *w, const prim *p, const ray *r, double tmin, double tmax, double *t,
                            vec3 *nl, bool coherent)
{
	if (p->tag == PRIM_SPHERE)
		return sphere_hit(p, r, tmin, tmax, t);
	if (p->tag == PRIM_MESH)
		return surf_inst_hit(w, p, r, tmin, tmax, t, nl, coherent);
	return other_hit(w, p, r, tmin, tmax, t, nl);
}

static inline bool prim_occluded(const world *w, const prim *p, const ray *r, double tmin, double tmax)
{
	double t;
	if (p->tag == PRIM_SPHERE)
		return sphere_hit(p, r, tmin, tmax, &t);
	return other_occluded(w, p, r, tmin, tmax);
}

bool world_prim_hit(const world *w, const prim *p, const ray *r, double tmin, double tmax, double *t, vec3 *nl,
                    bool coherent)
{
	return prim_hit(w, p, r, tmin, tmax, t, nl, coherent);
}

bool world_prim_occluded(const world *w, const prim *p, const ray *r, double tmin, double tmax)
{
	return prim_occluded(w, p, r, tmin, tmax);
}

/* The hit record of a plane. */
static void finish_plane(const world *w, const prim_plane *pl, const ray *r, double t, hit *h)
{
	const prim_shape *sh = &w->shapes[pl->shape];
	const double(*m)[4] = sh->inv;
	h->t = t;
	h->p = ray_at(*r, t);
	h->object = pl->object;
	vec3 q = h->p;
	h->local = (vec3){m[0][0] * q.x + m[0][1] * q.y + m[0][2] * q.z + m[0][3],
	                  m[1][0] * q.x + m[1][1] * q.y + m[1][2] * q.z + m[1][3],
	                  m[2][0] * q.x + m[2][1] * q.y + m[2][2] * q.z + m[2][3]};
	h->front = v3_dot(pl->n, r->d) < 0.0;
	h->n = pl->n;
	surf_shape_uv(w, sh, pl->n, h);
}

/* Fills the hit record for the primitive found nearest. */
static void finish_hit(const world *w, const prim *p, const ray *r, double t, vec3 nl, hit *h)
{
	h->t = t;
	h->p = ray_at(*r, t);
	h->object = p->object;
	h->mat = p->object;
	h->has_uv = false;
	vec3 n;
	if (p->tag == PRIM_SPHERE) {
		n = v3_norm(v3_sub(h->p, p->u.sph.c));
		h->local = n;
		h->front = v3_dot(n, r->d) < 0.0;
		h->n = n;
		return;
	}
	if (p->tag == PRIM_MESH) {
		surf_inst_finish(w, p, r, nl, h);
		return;
	}
	const prim_shape *shp = NULL;
	if (p->tag == PRIM_TRIANGLE) {
		const prim_tri *tr = &w->tris[p->u.index];
		n = v3_cross(tr->e1, tr->e2);
		h->local = h->p;
	} else {
		shp = &w->shapes[p->u.index];
		const double(*m)[4] = shp->inv;
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
	if (shp) {
		surf_shape_uv(w, shp, nl, h);
	} else {
		const prim_tri *tr = &w->tris[p->u.index];
		surf_triangle_uv(w, tr->v0, tr->e1, tr->e2, h);
	}
}

/* --- the tree walk --- */

static _Thread_local uint64_t rays_traced;

void world_rays_reset(void)
{
	rays_traced = 0;
}

uint64_t world_rays_traced(void)
{
	return rays_traced;
}

void world_rays_count(int n)
{
	rays_traced += (uint64_t)(int64_t)n;
}

size_t world_memory(const world *w)
{
	size_t n = w->nlights * sizeof *w->lights + w->nprims * sizeof *w->prims +
	           w->nplanes * sizeof *w->planes + w->nshapes * sizeof *w->shapes +
	           w->ntris * sizeof *w->tris + w->nmats * sizeof *w->mats +
	           w->nemitters * sizeof *w->emitters;
	if (w->tree)
		n += sizeof *w->tree + w->tree->nnodes * sizeof *w->tree->nodes;
	return n + surf_memory(w) + (w->env ? envmap_memory(w->env) : 0);
}

/* The one walk of the scene's BVH, below the planes. any: an occlusion
 * test, true at the first primitive hit (children in mask order, nothing
 * pruned); otherwise the nearest hit: *tmax, *best and *best_n follow it,
 * children nearest first, and entries a nearer hit rules out are dropped.
 * Inlined with `any` constant, so each caller gets its own loop. */
static inline __attribute__((always_inline)) bool walk(const world *w, const ray *r, double tmin, double *tmax_io,
                                                       bool any, bool coherent, const prim **best, vec3 *best_n)
{
	const bvh *tree = w->tree;
	const bvh_node *nodes = tree->nodes;
	double tmax = *tmax_io, t;
	vec3 nl;
	bvh_ray q;
	bvh_ray_prepare(r, &q);
	float ftmin = to_float_down(tmin), ftmax = to_float_up(tmax);
	bvh_entry stack[BVH_STACK];
	int sp = 0;
	uint32_t child = tree->root, meta = tree->root_meta;
	for (;;) {
		if (meta) {
			const prim *p = &w->prims[child];
			uint32_t count = meta & ~BVH_LEAF;
			for (uint32_t k = 0; k < count; k++)
				if (any) {
					if (prim_occluded(w, &p[k], r, tmin, tmax))
						return true;
				} else if (prim_hit(w, &p[k], r, tmin, tmax, &t, &nl, coherent)) {
					tmax = t;
					ftmax = to_float_up(tmax);
					*best = &p[k];
					*best_n = nl;
				}
		} else {
			const bvh_node *n = &nodes[child];
			float tn[BVH_WIDTH];
			unsigned m = bvh_slab4(n, &q, ftmin, ftmax, tn);
			if (m) {
				if (any) {
					/* any hit will do: no sorting, the first child now */
					sp = bvh_enter_any(n, m, tn, stack, sp, &child, &meta);
					continue;
				}
				if (m & (m - 1)) {
					/* several: the nearest now, the others later */
					sp = bvh_enter_sorted(n, m, tn, stack, sp, &child, &meta);
				} else {
					int k = __builtin_ctz(m);
					child = n->child[k];
					meta = n->meta[k];
				}
				continue;
			}
		}
		/* the next entry that a nearer hit has not ruled out */
		if (!any)
			while (sp > 0 && stack[sp - 1].t > (double)BVH_SLAB_SLACK * tmax)
				sp--;
		if (sp == 0)
			break;
		sp--;
		child = stack[sp].child;
		meta = stack[sp].meta;
	}
	*tmax_io = tmax;
	return false;
}

/* The nearest hit's primitive, distance and local data (world.h). */
static inline __attribute__((always_inline)) bool trace(const world *w, const ray *r, double tmin, double tmax,
                                                        trace_hit *th, bool coherent)
{
	const prim *best = NULL;
	const prim_plane *best_plane = NULL;
	vec3 best_n = {0, 0, 0};
	double t;
	vec3 nl;
	rays_traced++;
	for (size_t i = 0; i < w->nplanes; i++)
		if (plane_hit(&w->planes[i], r, tmin, tmax, &t)) {
			tmax = t;
			best_plane = &w->planes[i];
		}
	if (w->nprims == 1 && w->prims[0].tag == PRIM_MESH) {
		/* a lone model (the model viewer's world): the root of its own
		 * tree is the box test the world's would make first */
		if (surf_inst_hit(w, &w->prims[0], r, tmin, tmax, &t, &nl, coherent)) {
			tmax = t;
			best = &w->prims[0];
			best_n = nl;
		}
	} else if (w->nprims) {
		walk(w, r, tmin, &tmax, false, coherent, &best, &best_n);
	}
	/* a primitive hit after the planes is nearer than all of them */
	th->t = tmax;
	th->prim = best;
	th->plane = best ? NULL : best_plane;
	th->nl = best_n;
	return best || best_plane;
}

static inline __attribute__((always_inline)) void finish(const world *w, const ray *r, const trace_hit *th, hit *h)
{
	if (th->prim)
		finish_hit(w, th->prim, r, th->t, th->nl, h);
	else
		finish_plane(w, th->plane, r, th->t, h);
}

bool world_trace(const world *w, const ray *r, double tmin, double tmax, trace_hit *th)
{
	return trace(w, r, tmin, tmax, th, false);
}

bool world_trace_coherent(const world *w, const ray *r, double tmin, double tmax, trace_hit *th)
{
	return trace(w, r, tmin, tmax, th, true);
}

void world_finish(const world *w, const ray *r, const trace_hit *th, hit *h)
{
	finish(w, r, th, h);
}

vec3 world_trace_ng(const world *w, const ray *r, const trace_hit *th)
{
	if (th->plane)
		return th->plane->n;
	const prim *p = th->prim;
	switch (p->tag) {
	case PRIM_SPHERE:
		return v3_sub(ray_at(*r, th->t), p->u.sph.c);
	case PRIM_TRIANGLE:
		return v3_cross(w->tris[p->u.index].e1, w->tris[p->u.index].e2);
	case PRIM_MESH:
		return surf_inst_ng(w, p, th->nl);
	default: {
		const prim_shape *sh = &w->shapes[p->u.index];
		const double(*m)[4] = (const double(*)[4])sh->inv;
		vec3 nl = th->nl;
		return (vec3){m[0][0] * nl.x + m[1][0] * nl.y + m[2][0] * nl.z, m[0][1] * nl.x + m[1][1] * nl.y + m[2][1] * nl.z,
		              m[0][2] * nl.x + m[1][2] * nl.y + m[2][2] * nl.z};
	}
	}
}

bool world_intersect(const world *w, const ray *r, double tmin, double tmax, hit *h)
{
	trace_hit th;
	if (!trace(w, r, tmin, tmax, &th, false))
		return false;
	finish(w, r, &th, h);
	return true;
}

bool world_intersect_coherent(const world *w, const ray *r, double tmin, double tmax, hit *h)
{
	trace_hit th;
	if (!trace(w, r, tmin, tmax, &th, true))
		return false;
	finish(w, r, &th, h);
	return true;
}

bool world_occluded(const world *w, const ray *r, double tmin, double tmax)
{
	rays_traced++;
	double t;
	for (size_t i = 0; i < w->nplanes; i++)
		if (plane_hit(&w->planes[i], r, tmin, tmax, &t))
			return true;
	if (!w->nprims)
		return false;
	if (w->nprims == 1 && w->prims[0].tag == PRIM_MESH)
		return surf_inst_occluded(w, &w->prims[0], r, tmin, tmax); /* as in world_intersect */
	return walk(w, r, tmin, &tmax, true, false, NULL, NULL);
}

bool world_intersect_brute(const world *w, const ray *r, double tmin, double tmax, hit *h)
{
	const prim *best = NULL;
	const prim_plane *best_plane = NULL;
	vec3 best_n = {0, 0, 0};
	double t;
	vec3 nl;
	for (size_t i = 0; i < w->nplanes; i++)
		if (plane_hit(&w->planes[i], r, tmin, tmax, &t)) {
			tmax = t;
			best_plane = &w->planes[i];
		}
	for (size_t i = 0; i < w->nprims; i++)
		if (prim_hit(w, &w->prims[i], r, tmin, tmax, &t, &nl, false)) {
			tmax = t;
			best = &w->prims[i];
			best_n = nl;
		}
	if (best)
		finish_hit(w, best, r, tmax, best_n, h);
	else if (best_plane)
		finish_plane(w, best_plane, r, tmax, h);
	return best || best_plane;
}

bool world_occluded_brute(const world *w, const ray *r, double tmin, double tmax)
{
	double t;
	for (size_t i = 0; i < w->nplanes; i++)
		if (plane_hit(&w->planes[i], r, tmin, tmax, &t))
			return true;
	for (size_t i = 0; i < w->nprims; i++)
		if (prim_occluded(w, &w->prims[i], r, tmin, tmax))
			return true;
	return false;
}
