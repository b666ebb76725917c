/* rtsh — the BVH against brute force: on random rays over random seeded
 * scenes of every shape kind (transformed, sheared, planes beside the tree),
 * world_intersect must find the same object at the same t as
 * world_intersect_brute, and world_occluded must agree with
 * world_occluded_brute. Also: an edit followed by world_build sees the new
 * geometry, and the degenerate trees (no object, one object, every centroid
 * in one point, huge coordinates, rays in the planes of the boxes). */
#include <float.h>
#include "testutil.h"

#include "core/bvh/bvh.h"
#include "rtsh/generate.h"
#include "rtsh/world.h"

static double urand(test_rng *g, double lo, double hi)
{
	return lo + (hi - lo) * trand(g);
}

static vec3 vrand(test_rng *g, double lo, double hi)
{
	return v3(urand(g, lo, hi), urand(g, lo, hi), urand(g, lo, hi));
}

/* A unit vector, uniform on the sphere; now and then along an axis, where
 * the inverse direction has infinities. */
static vec3 dir_rand(test_rng *g)
{
	if (trand(g) < 0.1) {
		vec3 d = v3(0, 0, 0);
		int a = (int)(trand(g) * 3) % 3;
		double s = trand(g) < 0.5 ? -1 : 1;
		return a == 0 ? v3(s, 0, 0) : a == 1 ? v3(0, s, 0) : (d.z = s, d);
	}
	for (;;) {
		vec3 d = vrand(g, -1, 1);
		double l = v3_len(d);
		if (l > 0.1 && l <= 1)
			return v3_scale(d, 1 / l);
	}
}

/* A random object of kind k near c, of about size s. */
static object random_object(test_rng *g, obj_kind k, vec3 c, double s)
{
	object o = object_make(k, v3(urand(g, 0, 255), urand(g, 0, 255), urand(g, 0, 255)));
	if (k == OBJ_TRIANGLE) {
		for (;;) {
			for (int i = 0; i < 3; i++)
				o.tri[i] = v3_add(c, vrand(g, -s, s));
			if (object_validate(&o, NULL))
				return o;
		}
	}
	o.pos = c;
	o.dir = dir_rand(g);
	o.twist = trand(g) < 0.5 ? urand(g, 0, 360) : 0;
	double u = urand(g, 0.2, 1) * s;
	o.scale = trand(g) < 0.5 ? v3(u, u, u) : v3_scale(vrand(g, 0.2, 1), s);
	if (k != OBJ_PLANE && trand(g) < 0.3) {
		for (int i = 0; i < 6; i++)
			o.shear[i] = urand(g, -0.3, 0.3);
		if (!object_validate(&o, NULL))
			memset(o.shear, 0, sizeof o.shear);
	}
	return o;
}

static scene *random_scene(uint64_t seed, size_t n, double region, double size, int planes)
{
	test_rng g = {seed};
	scene *s = scene_new();
	camera cam = {v3(0, 0, -3 * region), v3(0, 0, 1), 60, false, 0, 0};
	assert_true(scene_add_camera(s, &cam, NULL));
	for (size_t i = 0; i < n; i++) {
		obj_kind k = (obj_kind)(i % OBJ_KIND_COUNT);
		if (k == OBJ_PLANE)
			k = OBJ_SPHERE; /* half the spheres fast, half turned or sheared */
		if (obj_kind_flags(k) & KIND_MODEL)
			k = OBJ_CUBE; /* a model needs a file (test_mesh) */
		object o = random_object(&g, k, vrand(&g, -region, region), size);
		assert_true(object_validate(&o, NULL));
		assert_true(scene_add_object(s, &o, NULL));
	}
	for (int i = 0; i < planes; i++) {
		object p = random_object(&g, OBJ_PLANE, vrand(&g, -region * 1.5, region * 1.5), 1);
		assert_true(scene_add_object(s, &p, NULL));
	}
	return s;
}

static world *build(const scene *s)
{
	rt_error err;
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("world_build: %s", err.msg);
	return w;
}

/* A ray from somewhere in or around the region; half aimed at an object. */
static ray random_ray(test_rng *g, const scene *s, double region)
{
	ray r;
	r.o = vrand(g, -2 * region, 2 * region);
	if (s->nobjs && trand(g) < 0.5) {
		const object *o = &s->objs[(size_t)(trand(g) * (double)s->nobjs) % s->nobjs];
		vec3 to = v3_sub(v3_add(object_center(o), vrand(g, -0.3, 0.3)), r.o);
		r.d = v3_len(to) > 1e-9 ? v3_norm(to) : dir_rand(g);
	} else {
		r.d = dir_rand(g);
	}
	return r;
}

static int compared, hits;

/* One ray, both queries, tree against brute force. */
static void check_ray(const world *w, const ray *r, double tmin, double tmax)
{
	hit a, b;
	bool ha = world_intersect(w, r, tmin, tmax, &a);
	bool hb = world_intersect_brute(w, r, tmin, tmax, &b);
	compared++;
	if (ha != hb)
		fail_msg("ray o=(%.17g,%.17g,%.17g) d=(%.17g,%.17g,%.17g) [%g,%g]: tree %s, brute %s (object %u t=%.17g)",
		         r->o.x, r->o.y, r->o.z, r->d.x, r->d.y, r->d.z, tmin, tmax, ha ? "hit" : "missed",
		         hb ? "hit" : "missed", ha ? a.object + 1 : b.object + 1, ha ? a.t : b.t);
	if (ha) {
		hits++;
		if (a.object != b.object || !(fabs(a.t - b.t) <= 1e-9 * fabs(b.t)))
			fail_msg("ray o=(%.17g,%.17g,%.17g) d=(%.17g,%.17g,%.17g): tree object %u t=%.17g, brute object %u t=%.17g",
			         r->o.x, r->o.y, r->o.z, r->d.x, r->d.y, r->d.z, a.object + 1, a.t, b.object + 1, b.t);
		assert_true(v3_eq(a.n, b.n));
		/* the same hit in two stages, and its geometric normal along the
		 * hit's (these scenes have no smooth normals) */
		trace_hit th;
		assert_true(world_trace(w, r, tmin, tmax, &th));
		hit c;
		world_finish(w, r, &th, &c);
		assert_true(c.t == a.t && c.object == a.object && v3_eq(c.n, a.n) && v3_eq(c.p, a.p));
		vec3 ng = world_trace_ng(w, r, &th);
		assert_true(fabs(fabs(v3_dot(v3_norm(ng), a.n)) - 1) < 1e-9);
	} else {
		trace_hit th;
		assert_false(world_trace(w, r, tmin, tmax, &th));
	}
	bool oa = world_occluded(w, r, tmin, tmax), ob = world_occluded_brute(w, r, tmin, tmax);
	if (oa != ob)
		fail_msg("ray o=(%.17g,%.17g,%.17g) d=(%.17g,%.17g,%.17g) [%g,%g]: occluded tree %d, brute %d", r->o.x,
		         r->o.y, r->o.z, r->d.x, r->d.y, r->d.z, tmin, tmax, oa, ob);
	/* any-hit agrees with the nearest hit */
	assert_int_equal(oa, hb);
}

static void check_scene(const scene *s, double region, uint64_t seed, int nrays)
{
	world *w = build(s);
	test_rng g = {seed};
	for (int i = 0; i < nrays; i++) {
		ray r = random_ray(&g, s, region);
		double u = trand(&g);
		/* unbounded, a segment (shadow ray), and a ray starting inside */
		double tmax = u < 0.5 ? INFINITY : urand(&g, 0, 3 * region);
		double tmin = u > 0.9 ? urand(&g, 0, region) : 0;
		check_ray(w, &r, tmin, tmax);
	}
	world_free(w);
}

static void test_random_scenes(void **state)
{
	(void)state;
	compared = hits = 0;
	static const size_t sizes[] = {2, 7, 40, 300, 2000};
	for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++)
		for (uint64_t seed = 1; seed <= 4; seed++) {
			double region = 10;
			/* dense (overlapping) and sparse scenes, with and without planes */
			double size = seed % 2 ? 4.0 : 0.5;
			scene *s = random_scene(seed * 1000 + k, sizes[k], region, size, (int)(seed % 3));
			check_scene(s, region, seed, 2000);
			scene_free(s);
		}
	assert_true(hits > compared / 5);
}

static void test_generated_scenes(void **state)
{
	(void)state;
	for (int spheres = 0; spheres < 2; spheres++) {
		gen_opts o = {.spheres_only = spheres};
		scene *s = scene_generate(4000, 9, &o, NULL);
		assert_non_null(s);
		check_scene(s, 6, 77, 3000);
		scene_free(s);
	}
}

/* Rays along the axes through a grid of unit cubes, starting on the planes
 * of the boxes: (box - origin) x inf = 0 x inf = NaN in the slab tests. */
static void test_rays_in_box_planes(void **state)
{
	(void)state;
	scene *s = scene_new();
	camera cam = {v3(0, 0, -10), v3(0, 0, 1), 60, false, 0, 0};
	assert_true(scene_add_camera(s, &cam, NULL));
	for (int x = 0; x < 6; x++)
		for (int y = 0; y < 6; y++) {
			object o = object_make(x % 2 ? OBJ_CUBE : OBJ_SPHERE, v3(200, 200, 200));
			o.pos = v3(2 * x, 2 * y, 0);
			o.scale = v3(1, 1, 1);
			assert_true(scene_add_object(s, &o, NULL));
		}
	world *w = build(s);
	for (int i = -2; i <= 24; i++)
		for (int j = -2; j <= 24; j++) {
			double a = i * 0.5, b = j * 0.5;
			ray rays[] = {
				{v3(a, b, -5), v3(0, 0, 1)},  {v3(a, -5, b - 6), v3(0, 1, 0)},
				{v3(-5, a, b - 6), v3(1, 0, 0)}, {v3(a, b, 5), v3(0, 0, -1)},
				{v3(a, 20, b - 6), v3(0, -1, 0)}, {v3(20, a, b - 6), v3(-1, 0, 0)},
			};
			for (size_t k = 0; k < sizeof rays / sizeof rays[0]; k++)
				check_ray(w, &rays[k], 0, INFINITY);
		}
	world_free(w);
	scene_free(s);
}

/* An edit followed by world_build: the moved sphere is hit where it went and
 * no longer where it was. */
static void test_edit_then_build(void **state)
{
	(void)state;
	scene *s = random_scene(5, 500, 10, 0.5, 1);
	object probe = object_make(OBJ_SPHERE, v3(255, 0, 0));
	probe.pos = v3(100, 100, 100);
	assert_true(scene_add_object(s, &probe, NULL));
	size_t idx = s->nobjs - 1;
	ray r = {v3(100, 100, 90), v3(0, 0, 1)};
	world *w = build(s);
	hit h;
	assert_true(world_intersect(w, &r, 0, INFINITY, &h));
	assert_int_equal(h.object, idx);
	assert_near(h.t, 9.5, 1e-12);
	world_free(w);

	object_move(&s->objs[idx], v3(0, 50, 0));
	w = build(s);
	ray r2 = {v3(100, 150, 90), v3(0, 0, 1)};
	assert_true(world_intersect(w, &r2, 0, INFINITY, &h));
	assert_int_equal(h.object, idx);
	assert_false(world_intersect(w, &r, 0, INFINITY, &h) && h.object == idx);
	assert_true(world_occluded(w, &r2, 0, 20));
	world_free(w);

	/* a new object after the others is found too */
	object late = object_make(OBJ_CUBE, v3(0, 255, 0));
	late.pos = v3(-100, 0, 0);
	assert_true(scene_add_object(s, &late, NULL));
	w = build(s);
	ray r3 = {v3(-100, 0, -20), v3(0, 0, 1)};
	assert_true(world_intersect(w, &r3, 0, INFINITY, &h));
	assert_int_equal(h.object, s->nobjs - 1);
	assert_near(h.t, 19.5, 1e-12);
	world_free(w);
	scene_free(s);
}

static void test_no_objects(void **state)
{
	(void)state;
	scene *s = scene_new();
	world *w = build(s);
	ray r = {v3(0, 0, 0), v3(0, 0, 1)};
	hit h;
	assert_false(world_intersect(w, &r, 0, INFINITY, &h));
	assert_false(world_occluded(w, &r, 0, INFINITY));
	world_free(w);
	/* a plane alone: beside the tree, which is empty */
	object p = object_make(OBJ_PLANE, v3(1, 1, 1));
	p.pos = v3(0, -1, 0);
	assert_true(scene_add_object(s, &p, NULL));
	w = build(s);
	ray down = {v3(0, 0, 0), v3(0, -1, 0)};
	assert_true(world_intersect(w, &down, 0, INFINITY, &h));
	assert_near(h.t, 1, 1e-12);
	assert_vec_near(h.n, v3(0, 1, 0), 1e-12);
	assert_true(world_occluded(w, &down, 0, 2));
	assert_false(world_occluded(w, &down, 0, 0.5));
	world_free(w);
	scene_free(s);
}

static void test_one_object(void **state)
{
	(void)state;
	for (int k = 0; k < OBJ_KIND_COUNT; k++) {
		if (k == OBJ_PLANE || (obj_kind_flags((obj_kind)k) & KIND_MODEL))
			continue;
		scene *s = random_scene(42 + (uint64_t)k, 0, 1, 1, 0);
		test_rng g = {(uint64_t)k};
		object o = random_object(&g, (obj_kind)k, v3(0.1, -0.2, 0.3), 1);
		assert_true(scene_add_object(s, &o, NULL));
		check_scene(s, 2, (uint64_t)k, 3000);
		world *w = build(s);
		assert_int_equal(w->nprims, 1);
		world_free(w);
		scene_free(s);
	}
}

/* Every centroid in one point: concentric spheres and cubes; the builder
 * can only halve by count. */
static void test_same_centroid(void **state)
{
	(void)state;
	scene *s = random_scene(3, 0, 1, 1, 0);
	for (int i = 0; i < 200; i++) {
		object o = object_make(i % 3 ? OBJ_SPHERE : OBJ_CUBE, v3(9, 9, 9));
		o.pos = v3(1, 2, 3);
		double d = 0.05 * (i + 1);
		o.scale = v3(d, d, d);
		assert_true(scene_add_object(s, &o, NULL));
	}
	check_scene(s, 5, 11, 3000);
	world *w = build(s);
	/* a ray from outside meets the largest shape first */
	ray r = {v3(1, 2, -100), v3(0, 0, 1)};
	hit h;
	assert_true(world_intersect(w, &r, 0, INFINITY, &h));
	assert_true(h.object == 198 || h.object == 199);
	assert_true(w->tree->depth < BVH_MAX_DEPTH);
	world_free(w);
	scene_free(s);
}

/* Coordinates far from the origin (float boxes are coarse there, but must
 * still contain their objects). */
static void test_huge_coordinates(void **state)
{
	(void)state;
	static const double offsets[] = {1e6, 2147483648.0, 1e12};
	for (size_t k = 0; k < sizeof offsets / sizeof offsets[0]; k++) {
		double off = offsets[k];
		scene *s = random_scene(7, 0, 1, 1, 0);
		test_rng g = {k + 1};
		for (int i = 0; i < 300; i++) {
			obj_kind kind = (obj_kind)(i % OBJ_KIND_COUNT);
			if (kind == OBJ_PLANE || (obj_kind_flags(kind) & KIND_MODEL))
				kind = OBJ_CUBE;
			object o = random_object(&g, kind, v3_add(v3(off, -off, off), vrand(&g, -50, 50)), 3);
			assert_true(scene_add_object(s, &o, NULL));
		}
		world *w = build(s);
		for (int i = 0; i < 3000; i++) {
			ray r;
			const object *o = &s->objs[(size_t)i % s->nobjs];
			r.o = v3_add(v3(off, -off, off), vrand(&g, -200, 200));
			vec3 to = v3_sub(v3_add(object_center(o), vrand(&g, -1, 1)), r.o);
			r.d = v3_norm(to);
			check_ray(w, &r, 0, INFINITY);
		}
		world_free(w);
		scene_free(s);
	}
}

/* The SAH's half area of a float box, from its definition: xy + yz + zx of
 * the extents, in doubles (so not rounded to float), and 0 for a box empty
 * or NaN on any one axis (each axis alone: the SSE2 version tests z apart
 * from x and y). */
static void test_half_area(void **state)
{
	(void)state;
	bvh_fbox b = {{0, 0, 0, 7}, {1, 2, 3, 0}};
	assert_true(bvh_fbox_half_area(&b) == 11.0); /* 2 + 6 + 3; lane 3 ignored */
	/* extents 2^24 + 1 and 1 + 2^-23: products not representable in float */
	bvh_fbox c = {{-16777216.0f, 0, 0, 1}, {1.0f, 1.0f + 0x1p-23f, 1.0f, 0}};
	double e0 = 16777217.0, e1 = 1.0 + 0x1p-23, e2 = 1.0;
	assert_true(bvh_fbox_half_area(&c) == e0 * e1 + e1 * e2 + e2 * e0);
	bvh_fbox flat = {{1, 1, 1, 1}, {1, 5, 9, 0}};
	assert_true(bvh_fbox_half_area(&flat) == 4.0 * 8.0); /* x extent 0 */
	for (int a = 0; a < 3; a++) {
		bvh_fbox e = b;
		e.lo[a] = 4.0f; /* lo > hi on axis a: empty */
		assert_true(bvh_fbox_half_area(&e) == 0.0);
		e = b;
		e.hi[a] = NAN;
		assert_true(bvh_fbox_half_area(&e) == 0.0);
		e = b;
		e.lo[a] = INFINITY; /* the empty box's corner */
		e.hi[a] = -INFINITY;
		assert_true(bvh_fbox_half_area(&e) == 0.0);
		/* an extent of inf - inf is NaN, not >= 0: empty (the test is
		 * on the extents, not on hi >= lo) */
		e = b;
		e.lo[a] = e.hi[a] = INFINITY;
		assert_true(bvh_fbox_half_area(&e) == 0.0);
		/* hi below lo by the least subnormal: the extent -2^-149 < 0 */
		e = b;
		e.lo[a] = 0x1p-149f;
		e.hi[a] = 0.0f;
		assert_true(bvh_fbox_half_area(&e) == 0.0);
		/* and above it by that much: the extent is 2^-149 > 0, so the
		 * area is the other two axes' product plus two tiny terms */
		e = b;
		e.lo[a] = 0.0f;
		e.hi[a] = 0x1p-149f;
		double ex[3] = {1, 2, 3};
		ex[a] = 0x1p-149;
		assert_true(bvh_fbox_half_area(&e) == ex[0] * ex[1] + ex[1] * ex[2] + ex[2] * ex[0]);
	}
	/* extents 2 FLT_MAX: infinite as a float difference, finite in doubles */
	bvh_fbox big = {{-FLT_MAX, -FLT_MAX, -FLT_MAX, 1}, {FLT_MAX, FLT_MAX, FLT_MAX, 0}};
	double eb = 2.0 * (double)FLT_MAX;
	assert_true(bvh_fbox_half_area(&big) == eb * eb + eb * eb + eb * eb);
	assert_true(isfinite(bvh_fbox_half_area(&big)));
}

/* The largest float <= v (below) or the least float >= v, from the
 * definition: the nearest float stepped until it is on the right side. */
static float float_side(double v, bool below)
{
	float f = (float)v;
	while (below ? (double)f > v : (double)f < v)
		f = nextafterf(f, below ? -INFINITY : INFINITY);
	return f;
}

/* The builder's float boxes hold each double box: the root's bounds of a
 * one-box tree are its corners rounded outward to the nearest floats, at
 * zeros (a tiny negative lower corner: the least negative subnormal), at
 * the top of the float range (past it: infinity, and FLT_MAX below) and for
 * values of each sign that round either way. */
static void test_float_boxes(void **state)
{
	(void)state;
	static const double v[] = {0.1, -0.1, 1.0 / 3.0, -1.0 / 3.0, 3.0, -3.0, 0.0, 1e-50, -1e-50, 1e-40,
	                           -1e-40, 1e39, -1e39, 3.4028235677973366e38, -3.4028235677973366e38,
	                           16777217.0, -16777217.0, 0.7, 2.5e-38};
	size_t nv = sizeof v / sizeof v[0];
	for (size_t i = 0; i < nv; i++)
		for (int a = 0; a < 3; a++) {
			/* axis a gets v[i] on both corners, the others v[i + 1] and v[i + 2] */
			double c[3] = {v[(i + 1) % nv], v[(i + 2) % nv], v[(i + 1) % nv]};
			c[a] = v[i];
			box x = {{c[0], c[1], c[2]}, {c[0], c[1], c[2]}};
			bvh2 t;
			rt_error err;
			assert_true(bvh2_build(&x, 1, &(bvh_build_opts){.trav = 4}, &t, &err));
			for (int k = 0; k < 3; k++) {
				float lo = float_side(c[k], true), hi = float_side(c[k], false);
				assert_true(memcmp(&t.bounds.lo[k], &lo, sizeof lo) == 0);
				assert_true(memcmp(&t.bounds.hi[k], &hi, sizeof hi) == 0);
			}
			bvh2_free(&t);
		}
}

/* Which objects are traced as world-space spheres (world_build works it
 * out once an object): a sphere with a uniform scale and every shear 0 or
 * -0 is; the least positive or negative shear, a checker, a scale not
 * uniform make it a transformed shape. Counted by hand: 2 spheres, 8
 * shapes of which the plane's is one (beside the tree), 1 triangle. */
static void test_fast_spheres(void **state)
{
	(void)state;
	scene *s = random_scene(5, 0, 1, 1, 0);
	object o = object_make(OBJ_SPHERE, v3(200, 10, 10));
	o.scale = v3(2, 2, 2);
	assert_true(scene_add_object(s, &o, NULL)); /* 0: sphere */
	object m = o;
	for (int i = 0; i < 6; i++)
		m.shear[i] = -0.0;
	assert_true(scene_add_object(s, &m, NULL)); /* 1: sphere (-0 shears) */
	for (int i = 0; i < 6; i++) {
		object t = o;
		t.pos = v3(3.0 * (i + 1), 0, 0);
		t.shear[i] = i % 2 ? -0x1p-1074 : 0x1p-1074; /* the least subnormals */
		assert_true(scene_add_object(s, &t, NULL)); /* 2-7: shapes */
	}
	object c = o;
	c.mat.checker = 2;
	assert_true(scene_add_object(s, &c, NULL)); /* 8: shape */
	object e = o;
	e.scale = v3(2, 2, 2.5);
	assert_true(scene_add_object(s, &e, NULL)); /* 9: shape */
	object pl = object_make(OBJ_PLANE, v3(1, 1, 1));
	pl.pos = v3(0, -10, 0);
	assert_true(scene_add_object(s, &pl, NULL)); /* 10: plane */
	object tr = object_make(OBJ_TRIANGLE, v3(1, 1, 1));
	tr.tri[0] = v3(0, 0, 5);
	tr.tri[1] = v3(1, 0, 5);
	tr.tri[2] = v3(0, 1, 5);
	assert_true(scene_add_object(s, &tr, NULL)); /* 11: triangle */
	world *w = build(s);
	assert_int_equal(w->nprims, 11);
	assert_int_equal(w->nplanes, 1);
	assert_int_equal(w->nshapes, 9);
	assert_int_equal(w->ntris, 1);
	for (size_t i = 0; i < w->nprims; i++) {
		uint32_t k = w->prims[i].object;
		uint32_t want = k <= 1 ? PRIM_SPHERE : k == 11 ? PRIM_TRIANGLE : PRIM_SHAPE;
		if (w->prims[i].tag != want)
			fail_msg("object %u: tag %u, expected %u", k, (unsigned)w->prims[i].tag, (unsigned)want);
	}
	/* the materials as mat_lin_make gives them, filled in place */
	for (size_t i = 0; i < s->nobjs; i++) {
		mat_lin ref = mat_lin_make(&s->objs[i].mat);
		assert_true(v3_eq(w->mats[i].albedo, ref.albedo) && w->mats[i].checker == ref.checker &&
		            w->mats[i].diffuse == ref.diffuse && w->mats[i].tx == NULL);
	}
	world_free(w);
	scene_free(s);
}

/* A fast sphere's primitive is made in tree order from its object
 * (world.c reorder), by the map from bounded primitive to object when
 * planes sit between the objects. Spheres on the x axis at x = 10 k, of
 * diameter 1 + k / 8 (radius its half), with a plane first and a plane,
 * a cube and a triangle among them: every primitive's object is a bounded
 * object met once, each sphere's record is its object's centre and half
 * its diameter, and a ray down the y axis onto x = 10 k hits object k's
 * sphere at t = 100 - radius. */
static void test_sphere_prims(void **state)
{
	(void)state;
	scene *s = scene_new();
	camera cam = {v3(0, 0, -50), v3(0, 0, 1), 60, false, 0, 0};
	assert_true(scene_add_camera(s, &cam, NULL));
	enum { N = 40 };
	for (int k = 0; k < N; k++) {
		object o;
		if (k == 0 || k == 17) {
			o = object_make(OBJ_PLANE, v3(1, 1, 1));
			o.pos = v3(0, -1000 - k, 0);
		} else if (k == 23) {
			o = object_make(OBJ_CUBE, v3(1, 1, 1));
			o.pos = v3(10.0 * k, 0, 0);
		} else if (k == 31) {
			o = object_make(OBJ_TRIANGLE, v3(1, 1, 1));
			o.tri[0] = v3(10.0 * k, 0, -1);
			o.tri[1] = v3(10.0 * k + 1, 0, 1);
			o.tri[2] = v3(10.0 * k - 1, 0, 1);
		} else {
			o = object_make(OBJ_SPHERE, v3(1, 1, 1));
			o.pos = v3(10.0 * k, 0, 0);
			double d = 1.0 + k / 8.0;
			o.scale = v3(d, d, d);
		}
		assert_true(scene_add_object(s, &o, NULL));
	}
	world *w = build(s);
	assert_int_equal(w->nprims, N - 2);
	assert_int_equal(w->nplanes, 2);
	int seen[N] = {0};
	for (size_t i = 0; i < w->nprims; i++) {
		const prim *p = &w->prims[i];
		uint32_t k = p->object;
		assert_true(k < N && k != 0 && k != 17);
		seen[k]++;
		bool sphere = k != 23 && k != 31;
		assert_int_equal(p->tag, sphere ? PRIM_SPHERE : k == 23 ? PRIM_SHAPE : PRIM_TRIANGLE);
		if (sphere) {
			assert_true(p->u.sph.c.x == 10.0 * k && p->u.sph.c.y == 0 && p->u.sph.c.z == 0);
			assert_true(p->u.sph.r == (1.0 + k / 8.0) / 2);
		}
	}
	for (int k = 1; k < N; k++)
		assert_int_equal(seen[k], k == 17 ? 0 : 1);
	for (int k = 1; k < N; k++) {
		if (k == 17 || k == 23 || k == 31)
			continue;
		ray r = {v3(10.0 * k, 100, 0), v3(0, -1, 0)};
		hit h;
		assert_true(world_intersect(w, &r, 1e-9, INFINITY, &h));
		assert_int_equal(h.object, k);
		assert_true(fabs(h.t - (100 - (1.0 + k / 8.0) / 2)) < 1e-9);
	}
	world_free(w);
	scene_free(s);
}

/* The tree built by 2, 3 and 4 threads is the 1-thread tree to the byte
 * (bvh.h): 70000 objects of every kind at random (a subtree goes to
 * another thread from 4096 references on both sides, and the primitives'
 * first half in tree order from 65536 on: world.c reorder), the wide
 * nodes, the primitives in tree order and the counts compared; and each
 * fast sphere's record is its object's centre and half its scale. */
static void test_threaded_build(void **state)
{
	(void)state;
	scene *s = random_scene(29, 70000, 100, 1.0, 1);
	rt_error err;
	world *one = world_build_threads(s, 1, NULL, &err);
	assert_non_null(one);
	for (int t = 2; t <= 4; t++) {
		world *w = world_build_threads(s, t, NULL, &err);
		assert_non_null(w);
		assert_int_equal(w->tree->nnodes, one->tree->nnodes);
		assert_int_equal(w->tree->depth, one->tree->depth);
		assert_int_equal(w->tree->leaves, one->tree->leaves);
		assert_int_equal(w->tree->root, one->tree->root);
		assert_memory_equal(w->tree->nodes, one->tree->nodes, one->tree->nnodes * sizeof *one->tree->nodes);
		assert_int_equal(w->nprims, one->nprims);
		for (size_t i = 0; i < w->nprims; i++) {
			const prim *a = &w->prims[i], *b = &one->prims[i];
			assert_true(a->tag == b->tag && a->object == b->object);
			if (a->tag == PRIM_SPHERE) {
				assert_memory_equal(&a->u.sph, &b->u.sph, sizeof a->u.sph);
				const object *o = &s->objs[a->object];
				assert_true(v3_eq(a->u.sph.c, o->pos) && a->u.sph.r == o->scale.x * 0.5);
			} else
				assert_int_equal(a->u.index, b->u.index);
		}
		/* the materials, filled by another thread from 4096 objects on */
		assert_int_equal(w->nmats, one->nmats);
		assert_memory_equal(w->mats, one->mats, one->nmats * sizeof *one->mats);
		world_free(w);
	}
	world_free(one);
	scene_free(s);
}

/* With the materials made by another thread, the textures follow once it
 * is done (world.c mats_textures), in object order: a world of 5000
 * spheres whose objects 3000 and 4000 name missing textures fails at any
 * thread count with the one thread's error, object 3001's; and so does
 * one whose object 4999 cannot be placed (a zero scale) after them. */
static void test_threaded_textures(void **state)
{
	(void)state;
	for (int bad_shape = 0; bad_shape < 2; bad_shape++) {
		scene *s = random_scene(31, 0, 1, 1, 0);
		for (int k = 0; k < 5000; k++) {
			object o = object_make(OBJ_SPHERE, v3(200, 10, 10));
			o.pos = v3(k % 70, k / 70, 0);
			o.mat.texture = k == 3000 ? "no-such-texture-3000.ppm" : k == 4000 ? "no-such-texture-4000.ppm" : NULL;
			if (bad_shape && k == 4999) {
				o.kind = OBJ_CUBE;
				o.scale = v3(1, 0, 1);
			}
			assert_true(scene_add_object(s, &o, NULL));
		}
		rt_error e1, e2;
		assert_null(world_build_threads(s, 1, NULL, &e1));
		assert_non_null(strstr(e1.msg, "no-such-texture-3000"));
		for (int t = 2; t <= 3; t++) {
			assert_null(world_build_threads(s, t, NULL, &e2));
			assert_string_equal(e2.msg, e1.msg);
		}
		/* the texture cleared: the build goes through with the same materials */
		s->objs[3000].mat.texture = NULL;
		s->objs[4000].mat.texture = NULL;
		if (!bad_shape) {
			world *a = world_build_threads(s, 1, NULL, &e1), *b = world_build_threads(s, 2, NULL, &e2);
			assert_non_null(a);
			assert_non_null(b);
			assert_memory_equal(a->mats, b->mats, a->nmats * sizeof *a->mats);
			world_free(a);
			world_free(b);
		}
		scene_free(s);
	}
}

/* The builder's binning of refs ids[0, n) (float boxes fb, unit costs) by
 * its definition (bvh.c): doubled centroids lo + hi, min(n, 16) bins
 * across their bounds per axis, bin (c - lo) * (bins / extent) truncated
 * and clamped. The cheapest split by the SAH, A_left n_left + A_right
 * n_right over every axis with an extent and every bin boundary, the first
 * of equal costs: *axis (-1: none) and the bin each reference falls in. */
static void brute_split(const bvh_fbox *fb, const uint32_t *ids, size_t n, int *axis, int *at, int *bin)
{
	int nbins = n >= 16 ? 16 : (int)n;
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (size_t i = 0; i < n; i++)
		for (int a = 0; a < 3; a++) {
			float c = fb[ids[i]].lo[a] + fb[ids[i]].hi[a];
			lo[a] = c < lo[a] ? c : lo[a];
			hi[a] = c > hi[a] ? c : hi[a];
		}
	double best = INFINITY;
	*axis = -1;
	for (int a = 0; a < 3; a++) {
		float e = hi[a] - lo[a];
		if (!(e > 0.0f))
			continue;
		float scale = (float)nbins / e;
		for (int k = 1; k < nbins; k++) {
			bvh_fbox l = {{INFINITY, INFINITY, INFINITY, 0}, {-INFINITY, -INFINITY, -INFINITY, 0}}, r = l;
			double nl = 0, nr = 0;
			for (size_t i = 0; i < n; i++) {
				const bvh_fbox *x = &fb[ids[i]];
				float v = (x->lo[a] + x->hi[a] - lo[a]) * scale;
				int b = v > 0.0f ? (v < (float)(nbins - 1) ? (int)v : nbins - 1) : 0;
				bvh_fbox *side = b < k ? &l : &r;
				*(b < k ? &nl : &nr) += 1;
				for (int j = 0; j < 3; j++) {
					side->lo[j] = x->lo[j] < side->lo[j] ? x->lo[j] : side->lo[j];
					side->hi[j] = x->hi[j] > side->hi[j] ? x->hi[j] : side->hi[j];
				}
			}
			if (nl == 0 || nr == 0)
				continue;
			double cost = bvh_fbox_half_area(&l) * nl + bvh_fbox_half_area(&r) * nr;
			if (cost < best) {
				best = cost;
				*axis = a;
				*at = k;
			}
		}
	}
	if (*axis < 0)
		return;
	float scale = (float)nbins / (hi[*axis] - lo[*axis]);
	for (size_t i = 0; i < n; i++) {
		const bvh_fbox *x = &fb[ids[i]];
		float v = (x->lo[*axis] + x->hi[*axis] - lo[*axis]) * scale;
		bin[i] = v > 0.0f ? (v < (float)(nbins - 1) ? (int)v : nbins - 1) : 0;
	}
}

/* The references under a child of binary tree t, appended to out. */
static size_t refs_under(const bvh2 *t, uint32_t child, uint32_t meta, uint32_t *out)
{
	if (meta & BVH_LEAF) {
		uint32_t cnt = meta & ~BVH_LEAF;
		memcpy(out, &t->ids[child], cnt * sizeof *out);
		return cnt;
	}
	const bvh2_node *nd = &t->nodes[child];
	size_t k = refs_under(t, nd->child[0], nd->meta[0], out);
	return k + refs_under(t, nd->child[1], nd->meta[1], out + k);
}

static int split_nodes_checked;

/* Each node over more than 8 references (more than a leaf may hold) is
 * split as brute_split says: its left child holds exactly the references
 * of the bins left of the split. */
static void check_splits(const bvh2 *t, uint32_t ni, const bvh_fbox *fb, uint32_t *ids, int *bin)
{
	const bvh2_node *nd = &t->nodes[ni];
	size_t nl = refs_under(t, nd->child[0], nd->meta[0], ids);
	size_t n = nl + refs_under(t, nd->child[1], nd->meta[1], ids + nl);
	if (n > 8) {
		int axis, at;
		brute_split(fb, ids, n, &axis, &at, bin);
		assert_true(axis >= 0);
		for (size_t i = 0; i < n; i++)
			if ((bin[i] < at) != (i < nl))
				fail_msg("node %u (%zu references): reference %u on the %s, expected the %s (axis %d, bin %d of %d)",
				         ni, n, ids[i], i < nl ? "left" : "right", bin[i] < at ? "left" : "right", axis, bin[i], at);
		split_nodes_checked++;
	}
	for (int c = 0; c < 2; c++)
		if (nd->meta[c] == 0)
			check_splits(t, nd->child[c], fb, ids, bin);
}

/* The binned SAH's splits, node by node, against brute force: boxes in
 * clusters, so that many bins are empty (the sweeps skip those), of
 * coordinates in eighths (floats, so the boxes are not rounded). */
static void test_sah_splits(void **state)
{
	(void)state;
	for (uint64_t seed = 1; seed <= 6; seed++) {
		test_rng g = {seed};
		size_t n = seed <= 3 ? 300 : 3000;
		box *bx = malloc(n * sizeof *bx);
		bvh_fbox *fb = malloc(n * sizeof *fb);
		uint32_t *ids = malloc(n * sizeof *ids);
		int *bin = malloc(n * sizeof *bin);
		assert_non_null(bx && fb && ids && bin);
		int nclusters = 2 + (int)seed;
		double cc[12][3];
		for (int c = 0; c < nclusters; c++)
			for (int a = 0; a < 3; a++)
				cc[c][a] = floor(urand(&g, -800, 800));
		for (size_t i = 0; i < n; i++) {
			int c = (int)(trand(&g) * nclusters) % nclusters;
			for (int a = 0; a < 3; a++) {
				double lo = cc[c][a] + floor(urand(&g, -40, 40)) / 8, size = floor(urand(&g, 1, 24)) / 8;
				(&bx[i].lo.x)[a] = lo;
				(&bx[i].hi.x)[a] = lo + size;
				fb[i].lo[a] = (float)lo;
				fb[i].hi[a] = (float)(lo + size);
			}
		}
		bvh2 t;
		rt_error err;
		assert_true(bvh2_build(bx, n, &(bvh_build_opts){.trav = 4}, &t, &err));
		assert_int_equal(t.root_meta, 0);
		split_nodes_checked = 0;
		check_splits(&t, t.root, fb, ids, bin);
		assert_true(split_nodes_checked >= (int)(n / 16)); /* most inner nodes above the leaves */
		bvh2_free(&t);
		free(bx);
		free(fb);
		free(ids);
		free(bin);
	}
}

/* The leaves of binary tree t under child, depth first, left first: each
 * leaf's ids must be in ascending order; the ids of group (ids[i] % 7 == 0
 * below) are appended to seq in tree order. */
static void leaf_walk(const bvh2 *t, uint32_t child, uint32_t meta, uint32_t *seq, size_t *nseq, size_t *leaves)
{
	if (meta & BVH_LEAF) {
		uint32_t cnt = meta & ~BVH_LEAF;
		const uint32_t *id = &t->ids[child];
		for (uint32_t i = 0; i < cnt; i++) {
			if (i > 0 && id[i - 1] >= id[i])
				fail_msg("leaf at %u: ids %u then %u, expected ascending", child, id[i - 1], id[i]);
			if (id[i] % 7 == 0)
				seq[(*nseq)++] = id[i];
		}
		(*leaves)++;
		return;
	}
	const bvh2_node *nd = &t->nodes[child];
	leaf_walk(t, nd->child[0], nd->meta[0], seq, nseq, leaves);
	leaf_walk(t, nd->child[1], nd->meta[1], seq, nseq, leaves);
}

/* The order of references the partitions leave is not the tree's: each
 * leaf holds its primitives in ascending index order, and a node whose
 * centroids are all one point is halved with the lower indices on the
 * left. Boxes at random, and every seventh (0, 7, 14, ...) the same box:
 * that group gathers in one subtree (one centroid: one bin on every axis)
 * that can only be halved, so in tree order its indices ascend. Then the
 * same through world_intersect: of two coincident spheres in one leaf the
 * ray meets the lower index first (the walk keeps the first of equal t). */
static void test_leaf_order(void **state)
{
	(void)state;
	for (uint64_t seed = 1; seed <= 3; seed++) {
		test_rng g = {seed};
		size_t n = 700 * seed;
		box *bx = malloc(n * sizeof *bx);
		uint32_t *seq = malloc(n * sizeof *seq);
		assert_non_null(bx && seq);
		for (size_t i = 0; i < n; i++) {
			vec3 c = i % 7 == 0 ? v3(1.5, -2.25, 3) : vrand(&g, -50, 50);
			double r = i % 7 == 0 ? 0.5 : urand(&g, 0.1, 2);
			bx[i] = (box){v3_sub(c, v3(r, r, r)), v3_add(c, v3(r, r, r))};
		}
		bvh2 t;
		rt_error err;
		assert_true(bvh2_build(bx, n, &(bvh_build_opts){.trav = 4}, &t, &err));
		size_t nseq = 0, leaves = 0;
		leaf_walk(&t, t.root, t.root_meta, seq, &nseq, &leaves);
		assert_int_equal(nseq, (n + 6) / 7);
		for (size_t i = 0; i < nseq; i++)
			if (seq[i] != 7 * i)
				fail_msg("seed %llu: the coincident group's %zu-th id in tree order is %u, expected %zu",
				         (unsigned long long)seed, i, seq[i], 7 * i);
		assert_true(leaves > n / 8);
		bvh2_free(&t);
		free(bx);
		free(seq);
	}
	/* pairs of coincident spheres, the twin of object i at index i + 300,
	 * in another colour; rays at each pair from outside */
	test_rng g = {99};
	scene *s = random_scene(5, 0, 1, 1, 0);
	vec3 at[300];
	for (int i = 0; i < 600; i++) {
		object o = object_make(OBJ_SPHERE, v3(i < 300 ? 200 : 10, 20, 30));
		if (i < 300)
			at[i] = vrand(&g, -40, 40);
		o.pos = at[i % 300];
		o.scale = v3(0.25, 0.25, 0.25);
		assert_true(scene_add_object(s, &o, NULL));
	}
	world *w = build(s);
	int pairs = 0;
	for (int i = 0; i < 300; i++) {
		ray r = {v3_add(at[i], v3(0.01, -0.02, -100)), v3(0, 0, 1)};
		hit h;
		assert_true(world_intersect(w, &r, 0, INFINITY, &h));
		if (h.object != (uint32_t)i && h.object != (uint32_t)i + 300)
			continue; /* another sphere in front */
		if (h.object != (uint32_t)i)
			fail_msg("pair %d: the ray met object %u first, expected %d (the lower index)", i, h.object, i);
		pairs++;
	}
	assert_true(pairs > 250); /* few hidden behind another sphere */
	world_free(w);
	scene_free(s);
}

/* The union of the boxes of the references under a child of binary tree t
 * (float boxes fb by primitive); every inner node's two boxes must be
 * exactly those unions (checked on the way). */
static bvh_fbox box_under(const bvh2 *t, uint32_t child, uint32_t meta, const bvh_fbox *fb)
{
	bvh_fbox u = {{INFINITY, INFINITY, INFINITY, 0}, {-INFINITY, -INFINITY, -INFINITY, 0}};
	if (meta & BVH_LEAF) {
		for (uint32_t i = 0; i < (meta & ~BVH_LEAF); i++)
			for (int a = 0; a < 3; a++) {
				const bvh_fbox *x = &fb[t->ids[child + i]];
				u.lo[a] = x->lo[a] < u.lo[a] ? x->lo[a] : u.lo[a];
				u.hi[a] = x->hi[a] > u.hi[a] ? x->hi[a] : u.hi[a];
			}
		return u;
	}
	const bvh2_node *nd = &t->nodes[child];
	for (int c = 0; c < 2; c++) {
		bvh_fbox x = box_under(t, nd->child[c], nd->meta[c], fb);
		for (int a = 0; a < 3; a++) {
			if (nd->box[c].lo[a] != x.lo[a] || nd->box[c].hi[a] != x.hi[a])
				fail_msg("node %u child %d axis %d: box [%g, %g], its references' [%g, %g]", child, c, a,
				         (double)nd->box[c].lo[a], (double)nd->box[c].hi[a], (double)x.lo[a], (double)x.hi[a]);
			u.lo[a] = x.lo[a] < u.lo[a] ? x.lo[a] : u.lo[a];
			u.hi[a] = x.hi[a] > u.hi[a] ? x.hi[a] : u.hi[a];
		}
	}
	return u;
}

/* A node of 4096 references or more takes the split of a sample: every
 * k-th reference in its order, k = n / 1024. 4096 unit cubes at y = z = 0
 * (only x can split): the sample, references 0, 4, 8, ..., holds cluster A
 * at x = 0 (i % 8 == 0) and C at x = 100 (i % 8 == 4); the other 3072 are
 * cluster B at x = 10. Doubled centroids 1 (A), 21 (B), 201 (C): 16 bins
 * of 12.5, so A is in bin 0, B in bin 1 and C in bin 15. The sample has
 * A and C only: every split between them costs 3 x 512 + 3 x 512, and the
 * first, after bin 0, is taken: A on the left, B and C on the right, whose
 * box is x in [10, 101]. The whole node would put A and B left (after bin
 * 1: 23 x 3584 + 3 x 512 against 3 x 512 + 183 x 3584 after bin 0). Then
 * boxes at random, 20000 and 4095: every node's boxes are the unions of
 * its references' (the sample's bins hold only the sample's). */
static void test_sampled_split(void **state)
{
	(void)state;
	size_t n = 4096;
	box *bx = malloc(n * sizeof *bx);
	bvh_fbox *fb = malloc(20000 * sizeof *fb);
	uint32_t *ids = malloc(n * sizeof *ids);
	assert_non_null(bx && fb && ids);
	for (size_t i = 0; i < n; i++) {
		double x = i % 8 == 0 ? 0 : i % 8 == 4 ? 100 : 10;
		bx[i] = (box){v3(x, 0, 0), v3(x + 1, 1, 1)};
	}
	bvh2 t;
	rt_error err;
	assert_true(bvh2_build(bx, n, &(bvh_build_opts){.trav = 4}, &t, &err));
	assert_int_equal(t.root_meta, 0);
	const bvh2_node *root = &t.nodes[t.root];
	size_t nl = refs_under(&t, root->child[0], root->meta[0], ids);
	assert_int_equal(nl, 512);
	for (size_t i = 0; i < nl; i++)
		if (ids[i] % 8 != 0)
			fail_msg("reference %u on the root's left, expected only cluster A (i %% 8 == 0)", ids[i]);
	const float want[2][2][3] = {{{0, 0, 0}, {1, 1, 1}}, {{10, 0, 0}, {101, 1, 1}}};
	for (int c = 0; c < 2; c++)
		for (int a = 0; a < 3; a++) {
			assert_true(root->box[c].lo[a] == want[c][0][a]);
			assert_true(root->box[c].hi[a] == want[c][1][a]);
		}
	bvh2_free(&t);
	free(bx);
	for (uint64_t seed = 1; seed <= 2; seed++) {
		test_rng g = {seed};
		n = seed == 1 ? 20000 : 4095;
		bx = malloc(n * sizeof *bx);
		assert_non_null(bx);
		for (size_t i = 0; i < n; i++) {
			/* eighths, and every fifth box long: floats, not rounded */
			vec3 lo = v3(floor(urand(&g, -800, 800)) / 8, floor(urand(&g, -800, 800)) / 8,
			             floor(urand(&g, -800, 800)) / 8);
			double len = i % 5 == 0 ? 40 : floor(urand(&g, 1, 16)) / 8;
			bx[i] = (box){lo, v3_add(lo, v3(len, len / 2, len / 4))};
			for (int a = 0; a < 3; a++) {
				fb[i].lo[a] = (float)(&bx[i].lo.x)[a];
				fb[i].hi[a] = (float)(&bx[i].hi.x)[a];
			}
		}
		assert_true(bvh2_build(bx, n, &(bvh_build_opts){.trav = 4}, &t, &err));
		bvh_fbox all = box_under(&t, t.root, t.root_meta, fb);
		for (int a = 0; a < 3; a++)
			assert_true(all.lo[a] == t.bounds.lo[a] && all.hi[a] == t.bounds.hi[a]);
		bvh2_free(&t);
		free(bx);
	}
	free(fb);
	free(ids);
}

/* A sampled node whose sample fills neither end bin: the sweeps run
 * between the sample's first and last bins that hold references. 4096
 * unit cubes [x, x + 1] on the x axis (y and z the same for all: one
 * usable axis); the sample is every 4th (4096 / 1024), ids 0, 4, 8, ...:
 * x = 20 (i % 8 == 0, A) and x = 120 (i % 8 == 4, B); the others x = 0 (i
 * % 4 == 1), x = 150 (i % 4 == 2) and x = 30 (i % 4 == 3). Doubled
 * centroids 2x + 1 from 1 to 301, 16 bins: bin trunc(32x / 300), so x =
 * 0, 20, 30, 120, 150 fall in bins 0, 2, 3, 12, 15. The sample is in bins
 * 2 and 12 only: every split from after bin 2 to after bin 11 has A
 * alone on the left and B on the right, the same cost, and the first
 * (after bin 2) wins. So the root's left child holds x = 0 and A (1024 +
 * 512), box x [0, 21], and the right x = 30, B and x = 150, x [30, 151].
 * A sweep that started one bin late would put x = 30 on the left. */
static void test_sampled_ends(void **state)
{
	(void)state;
	size_t n = 4096;
	box *bx = malloc(n * sizeof *bx);
	uint32_t *ids = malloc(n * sizeof *ids);
	assert_non_null(bx && ids);
	for (size_t i = 0; i < n; i++) {
		double x = i % 8 == 0 ? 20 : i % 8 == 4 ? 120 : i % 4 == 1 ? 0 : i % 4 == 2 ? 150 : 30;
		bx[i] = (box){v3(x, 0, 0), v3(x + 1, 1, 1)};
	}
	bvh2 t;
	rt_error err;
	assert_true(bvh2_build(bx, n, &(bvh_build_opts){.trav = 4}, &t, &err));
	assert_int_equal(t.root_meta, 0);
	const bvh2_node *root = &t.nodes[t.root];
	size_t nl = refs_under(&t, root->child[0], root->meta[0], ids);
	assert_int_equal(nl, 1536);
	for (size_t i = 0; i < nl; i++)
		if (ids[i] % 8 != 0 && ids[i] % 4 != 1)
			fail_msg("reference %u on the root's left, expected only x = 0 and x = 20", ids[i]);
	const float want[2][2][3] = {{{0, 0, 0}, {21, 1, 1}}, {{30, 0, 0}, {151, 1, 1}}};
	for (int c = 0; c < 2; c++)
		for (int a = 0; a < 3; a++) {
			assert_true(root->box[c].lo[a] == want[c][0][a]);
			assert_true(root->box[c].hi[a] == want[c][1][a]);
		}
	bvh2_free(&t);
	free(bx);
	free(ids);
}

/* The materials' colours in linear light (world_build decodes the whole
 * codes from srgb8_table in line): srgb8_table()[k] is the decoding of k /
 * 255 by its definition (IEC 61966-2-1: v / 12.92 up to 0.04045, else
 * ((v + 0.055) / 1.055)^2.4); a world's albedos are srgb255_to_linear's,
 * the same bits, for whole codes, for 127.5 and 254.999 (not whole: the
 * formula, not a table entry), for -0 (whole: code 0) and for a colour
 * whose one channel only is not whole; at 1 and 2 threads (the materials'
 * thread from 4096 objects). */
static void test_material_colours(void **state)
{
	(void)state;
	const double *tab = srgb8_table();
	for (int k = 0; k < 256; k++) {
		double v = k / 255.0;
		double want = v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
		assert_true(tab[k] == want);
	}
	const vec3 cols[] = {v3(0, 128, 255), v3(127.5, 3, 4), v3(-0.0, 254.999, 17), v3(9, 10, 200.25),
	                     v3(1, 2, 3)};
	size_t nc = sizeof cols / sizeof cols[0];
	scene *s = scene_new();
	camera cam = {v3(0, 0, -30), v3(0, 0, 1), 60, false, 0, 0};
	assert_true(scene_add_camera(s, &cam, NULL));
	for (size_t i = 0; i < 5000; i++) {
		object o = object_make(OBJ_SPHERE, cols[i % nc]);
		o.pos = v3((double)(i % 100), (double)(i / 100), 0);
		assert_true(scene_add_object(s, &o, NULL));
	}
	/* 127.5 decodes by the formula: between codes 127 and 128 */
	assert_true(srgb255_to_linear(cols[1]).x > tab[127] && srgb255_to_linear(cols[1]).x < tab[128]);
	for (int t = 1; t <= 2; t++) {
		rt_error err;
		world *w = world_build_threads(s, t, NULL, &err);
		assert_non_null(w);
		for (size_t i = 0; i < s->nobjs; i++) {
			vec3 want = srgb255_to_linear(cols[i % nc]), got = w->mats[i].albedo;
			if (memcmp(&got, &want, sizeof got) != 0)
				fail_msg("object %zu (%d threads): albedo (%.17g, %.17g, %.17g), expected (%.17g, %.17g, %.17g)",
				         i, t, got.x, got.y, got.z, want.x, want.y, want.z);
		}
		assert_true(w->mats[0].albedo.x == tab[0] && w->mats[0].albedo.y == tab[128] &&
		            w->mats[0].albedo.z == tab[255]);
		world_free(w);
	}
	scene_free(s);
}

/* The world's bounds are the union of its bounded primitives' boxes
 * (world.c makes them in line): three spheres by hand, centres and
 * diameters (-7, 2, 1) 2, (5, -4, 20) 4 and (1, 9, -3) 1, give lo (-8, -6,
 * -3.5) and hi (7, 9.5, 22); a plane far out adds nothing; and eps is
 * 1e-9 x the largest coordinate of the camera (-3 x region 1 = -3), the
 * bounds (22) and the plane's point (40): 4e-8. */
static void test_world_bounds(void **state)
{
	(void)state;
	scene *s = random_scene(1, 0, 1, 1, 0);
	const double at[3][4] = {{-7, 2, 1, 2}, {5, -4, 20, 4}, {1, 9, -3, 1}};
	for (int i = 0; i < 3; i++) {
		object o = object_make(OBJ_SPHERE, v3(200, 10, 10));
		o.pos = v3(at[i][0], at[i][1], at[i][2]);
		o.scale = v3(at[i][3], at[i][3], at[i][3]);
		assert_true(scene_add_object(s, &o, NULL));
	}
	object p = object_make(OBJ_PLANE, v3(1, 1, 1));
	p.pos = v3(0, -40, 0);
	p.dir = v3(0, 1, 0);
	assert_true(scene_add_object(s, &p, NULL));
	world *w = build(s);
	assert_true(v3_eq(w->bounds.lo, v3(-8, -6, -3.5)));
	assert_true(v3_eq(w->bounds.hi, v3(7, 9.5, 22)));
	assert_true(w->eps == 1e-9 * 40);
	world_free(w);
	scene_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_random_scenes),
		cmocka_unit_test(test_generated_scenes),
		cmocka_unit_test(test_rays_in_box_planes),
		cmocka_unit_test(test_edit_then_build),
		cmocka_unit_test(test_no_objects),
		cmocka_unit_test(test_one_object),
		cmocka_unit_test(test_same_centroid),
		cmocka_unit_test(test_huge_coordinates),
		cmocka_unit_test(test_half_area),
		cmocka_unit_test(test_float_boxes),
		cmocka_unit_test(test_fast_spheres),
		cmocka_unit_test(test_sphere_prims),
		cmocka_unit_test(test_threaded_build),
		cmocka_unit_test(test_threaded_textures),
		cmocka_unit_test(test_sah_splits),
		cmocka_unit_test(test_leaf_order),
		cmocka_unit_test(test_sampled_split),
		cmocka_unit_test(test_sampled_ends),
		cmocka_unit_test(test_material_colours),
		cmocka_unit_test(test_world_bounds),
	};
	return cmocka_run_group_tests_name("bvh", tests, NULL, NULL);
}
