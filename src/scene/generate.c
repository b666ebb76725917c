/* rtsh — the random scene generator (generate.h).
 *
 * Determinism across machines: every number in a generated scene is an
 * integer drawn from our own splitmix64 stream (Steele, Lea & Flood, "Fast
 * splittable pseudorandom number generators", 2014) and divided by a power of
 * ten (positions in thousandths, sizes in ten-thousandths of a unit). No libm
 * function and no floating-point expression with more than one rounding is
 * involved, so the scene is bit-identical on every IEEE 754 machine and
 * whatever the compiler contracts into FMAs. The decimal quantisation also
 * keeps the .rt files short: the writer prints these values with at most
 * four decimals.
 *
 * Layout: the objects fill the region |x| <= 5, 0 <= y <= 6, |z| <= 5 above
 * a ground plane y = 0, seen by a fixed camera. The typical object size
 * shrinks as n^(-1/3), so the volume fraction taken by the objects, and so
 * the look of the image, stays about the same from 10 to 10 million objects.
 * The lights and the camera depend on the seed only, not on n.
 */
#include "rtsh/generate.h"
#include "rtsh/shape.h"

#include "rtsh/memory.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The region, in thousandths of a unit. */
#define REGION_XZ 5000
#define REGION_Y 6000

/* Sizes in ten-thousandths: d^3 = K / n (d the typical diameter), clamped.
 * Mixed shapes: a volume fraction of about 5% of the region. Spheres only:
 * n (4/3) pi (d/2)^3 = 0.05 x 600, i.e. d^3 = 57.3 / n. */
#define MIXED_K 60000000000000ULL   /* 60 x 10^12 */
#define SPHERES_K 57300000000000ULL /* 57.3 x 10^12 */
#define MIXED_MAX_D 12000           /* 1.2 */
#define SPHERES_MAX_D 20000         /* 2.0 */

typedef struct gen_rng {
	uint64_t s;
} gen_rng;

static uint64_t gen_u64(gen_rng *r)
{
	uint64_t z = (r->s += 0x9e3779b97f4a7c15ULL);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

/* A stream for one purpose of one seed. */
static gen_rng gen_stream(uint64_t seed, uint64_t purpose)
{
	gen_rng r = {seed ^ (purpose * 0xd1b54a32d192ed03ULL)};
	r.s = gen_u64(&r);
	return r;
}

/* Uniform integer in [lo, hi] (the modulo bias, below 2^-40, is irrelevant). */
static int64_t gen_int(gen_rng *r, int64_t lo, int64_t hi)
{
	uint64_t span = (uint64_t)(hi - lo) + 1;
	return lo + (int64_t)((gen_u64(r) >> 11) % span);
}

/* True with probability pct / 100. */
static bool gen_chance(gen_rng *r, int pct)
{
	return gen_int(r, 0, 99) < pct;
}

static double milli(int64_t k)
{
	return (double)k / 1000.0;
}

static double tenth_milli(int64_t k)
{
	return (double)k / 10000.0;
}

/* The largest m with m^3 <= x (integer cube root by bisection). */
static uint64_t icbrt(uint64_t x)
{
	uint64_t lo = 0, hi = 2097152; /* 2^21: hi^3 = 2^63 > any x used here */
	while (lo < hi) {
		uint64_t mid = (lo + hi + 1) / 2;
		if (mid * mid * mid <= x)
			lo = mid;
		else
			hi = mid - 1;
	}
	return lo;
}

/* The typical diameter in ten-thousandths for n objects. */
static int64_t typical_size(size_t n, bool spheres)
{
	uint64_t k = spheres ? SPHERES_K : MIXED_K;
	uint64_t d = icbrt(k / (uint64_t)n);
	uint64_t dmax = spheres ? SPHERES_MAX_D : MIXED_MAX_D;
	return (int64_t)(d > dmax ? dmax : d < 1 ? 1 : d);
}

/* A vivid colour: one channel high, the others anywhere. */
static vec3 gen_color(gen_rng *r)
{
	double c[3];
	for (int i = 0; i < 3; i++)
		c[i] = (double)gen_int(r, 15, 235);
	c[gen_int(r, 0, 2)] = (double)gen_int(r, 200, 255);
	return v3(c[0], c[1], c[2]);
}

static material gen_material(gen_rng *r)
{
	material m = material_default(gen_color(r));
	if (gen_chance(r, 25))
		return m; /* the 42 default, written in the short form */
	m.diffuse = (double)gen_int(r, 60, 100) / 100.0;
	m.specular = (double)gen_int(r, 0, 9) / 10.0;
	m.shininess = (double)gen_int(r, 10, 400);
	m.reflective = gen_chance(r, 30) ? (double)gen_int(r, 1, 7) / 10.0 : 0.0;
	return m;
}

/* A direction with components in thousandths, not too short. */
static vec3 gen_dir(gen_rng *r)
{
	for (;;) {
		int64_t x = gen_int(r, -1000, 1000), y = gen_int(r, -1000, 1000), z = gen_int(r, -1000, 1000);
		if (x * x + y * y + z * z >= 250000)
			return v3(milli(x), milli(y), milli(z));
	}
}

/* A centre in thousandths, keeping a margin of `half` thousandths inside the
 * region. */
static void gen_center(gen_rng *r, int64_t half, int64_t c[3])
{
	if (half > 2900)
		half = 2900;
	c[0] = gen_int(r, -REGION_XZ + half, REGION_XZ - half);
	c[1] = gen_int(r, half, REGION_Y - half);
	c[2] = gen_int(r, -REGION_XZ + half, REGION_XZ - half);
}

/* size x pct / 100, in ten-thousandths, at least 1. */
static double part(int64_t size, int64_t pct)
{
	int64_t v = size * pct / 100;
	return tenth_milli(v < 1 ? 1 : v);
}

static object gen_sphere(gen_rng *r, int64_t d, bool plain)
{
	object o = object_make(OBJ_SPHERE, v3(0, 0, 0));
	int64_t c[3];
	gen_center(r, d / 20 + 1, c);
	o.pos = v3(milli(c[0]), milli(c[1]), milli(c[2]));
	o.mat = gen_material(r);
	if (plain || gen_chance(r, 80)) {
		double s = part(d, plain ? 100 : gen_int(r, 60, 100));
		o.scale = v3(s, s, s);
	} else {
		/* an ellipsoid, turned */
		o.dir = gen_dir(r);
		o.scale = v3(part(d, gen_int(r, 40, 100)), part(d, gen_int(r, 40, 100)), part(d, gen_int(r, 40, 100)));
	}
	return o;
}

static object gen_shape(gen_rng *r, int64_t d)
{
	/* the kinds with a recipe (shape.h), in the order of the kinds */
	obj_kind kinds[OBJ_KIND_COUNT];
	int64_t nk = 0;
	for (int k = 0; k < OBJ_KIND_COUNT; k++)
		if (shape_kinds[k]->recipe.use)
			kinds[nk++] = (obj_kind)k;
	obj_kind k = kinds[gen_int(r, 0, nk - 1)];
	const shape_kind *desc = shape_kinds[k];
	if (desc->world_sphere)
		return gen_sphere(r, d, false);
	object o = object_make(k, v3(0, 0, 0));
	int64_t c[3];
	gen_center(r, d / 20 + 1, c);
	o.mat = gen_material(r);
	if (obj_kind_flags(k) & KIND_VERTICES) {
		/* vertices within d/2 of the centre, in ten-thousandths */
		for (;;) {
			for (int i = 0; i < 3; i++) {
				int64_t v[3];
				for (int a = 0; a < 3; a++)
					v[a] = c[a] * 10 + gen_int(r, -d / 2, d / 2);
				o.tri[i] = v3(tenth_milli(v[0]), tenth_milli(v[1]), tenth_milli(v[2]));
			}
			if (object_validate(&o, NULL))
				return o;
		}
	}
	o.pos = v3(milli(c[0]), milli(c[1]), milli(c[2]));
	o.dir = gen_chance(r, 30) ? v3(0, 1, 0) : gen_dir(r);
	if (gen_chance(r, 25))
		o.twist = (double)gen_int(r, 1, 359);
	const shape_recipe *rc = &desc->recipe;
	double s[3];
	for (int a = 0; a < 3; a++)
		s[a] = rc->lo[a] > 0 ? part(d, gen_int(r, rc->lo[a], rc->hi[a])) : rc->lo[a] < 0 ? 1.0 : s[rc->hi[a]];
	o.scale = v3(s[0], s[1], s[2]);
	if (rc->tube_hi > 0)
		o.tube = (double)gen_int(r, rc->tube_lo, rc->tube_hi) / 100.0;
	if (gen_chance(r, 10)) {
		/* |entries| <= 0.3 keeps every row diagonally dominant: invertible */
		for (int i = 0; i < 6; i++)
			o.shear[i] = (double)gen_int(r, -30, 30) / 100.0;
		if (!object_validate(&o, NULL))
			memset(o.shear, 0, sizeof o.shear);
	}
	return o;
}

/* The seed's lights (2-4, coloured), ambient, camera and ground plane. */
static bool gen_setting(scene *s, uint64_t seed, rt_error *err)
{
	gen_rng r = gen_stream(seed, 1);
	s->has_ambient = true;
	s->amb = (ambient){0.15, v3(180, 200, 255)};
	camera cam = {v3(0, 7, -17), v3(0, -4, 17), 60, false, 0, 0};
	if (!scene_add_camera(s, &cam, err))
		return false;
	int64_t nl = gen_int(&r, 2, 4);
	for (int64_t i = 0; i < nl; i++) {
		light l = {0};
		l.pos = v3((double)gen_int(&r, -90, 90) / 10.0, (double)gen_int(&r, 70, 130) / 10.0,
		           (double)gen_int(&r, -120, 60) / 10.0);
		l.ratio = (double)(gen_int(&r, 50, 90) * 2 / nl) / 100.0;
		double c[3];
		for (int k = 0; k < 3; k++)
			c[k] = (double)gen_int(&r, 110, 255);
		c[gen_int(&r, 0, 2)] = 255;
		l.color = v3(c[0], c[1], c[2]);
		if (!scene_add_light(s, &l, err))
			return false;
	}
	object ground = object_make(OBJ_PLANE, v3(190, 190, 190));
	return scene_add_object(s, &ground, err);
}

scene *scene_generate(size_t n, uint64_t seed, const gen_opts *opts, rt_error *err)
{
	if (n < 1 || n > GENERATE_MAX) {
		rt_error_set(err, "cannot generate %zu objects; expected 1..%d", n, GENERATE_MAX);
		return NULL;
	}
	char what[64];
	snprintf(what, sizeof what, "generating %zu objects", n);
	if (!mem_check((double)(n + 1) * MEM_PER_OBJECT, what, err))
		return NULL;
	bool spheres = opts && opts->spheres_only;
	scene *s = scene_new();
	if (!s) {
		rt_error_set(err, "out of memory generating the scene");
		return NULL;
	}
	/* Every object at once: no doubling copies of a 300 MB array. */
	s->objs = malloc((n + 1) * sizeof *s->objs);
	if (!s->objs) {
		scene_free(s);
		rt_error_set(err, "out of memory generating %zu objects", n);
		return NULL;
	}
	s->cap_objs = n + 1;
	if (!gen_setting(s, seed, err)) {
		scene_free(s);
		return NULL;
	}
	gen_rng r = gen_stream(seed, spheres ? 3 : 2);
	int64_t d = typical_size(n, spheres);
	const atomic_bool *cancel = opts ? opts->cancel : NULL;
	for (size_t i = 0; i < n; i++) {
		if ((i & 0xffff) == 0 && cancel && atomic_load(cancel)) {
			scene_free(s);
			rt_error_set(err, "stopped");
			return NULL;
		}
		s->objs[s->nobjs++] = spheres ? gen_sphere(&r, d, true) : gen_shape(&r, d);
	}
	return s;
}
