/* rtsh — tests of the torus against values derived by hand:
 *   - seen along its axis, the silhouette is the annulus R - r < rho < R + r
 *     (area pi((R+r)^2 - (R-r)^2) = 4 pi R r), pixel for pixel away from its
 *     edges (no speckles through the hole), and the disc rho < R + r for a
 *     horn or spindle torus;
 *   - seen side-on, the outline is |y| <= r, |z| <= R + sqrt(r^2 - y^2);
 *   - normals are unit and point away from the nearest point of the tube's
 *     centre line, and the hit point is at distance r from it;
 *   - random rays, grazing ones included, agree with a dense march along the
 *     ray of the distance to the centre circle;
 *   - the .rt short form, the extended form with tube=, and their errors. */
#include "testutil.h"

#include "rtsh/rtfile.h"
#include "rtsh/scene.h"
#include "rtsh/shape.h"
#include "rtsh/world.h"

/* A torus of ring diameter 2R and tube diameter 2r at c with axis a. */
static object torus(vec3 c, vec3 a, double big, double small)
{
	object o = object_make(OBJ_TORUS, v3(200, 100, 50));
	o.pos = c;
	o.dir = a;
	o.scale = v3_splat(2.0 * (big + small));
	o.tube = small / big;
	return o;
}

static world *world_of(const object *o)
{
	scene *s = scene_new();
	assert_non_null(s);
	assert_true(scene_add_object(s, o, NULL));
	camera c = {v3(0, 0, -10), v3(0, 0, 1), 60, false, 0, 0};
	assert_true(scene_add_camera(s, &c, NULL));
	world *w = world_build(s, NULL);
	assert_non_null(w);
	scene_free(s);
	return w;
}

/* A unit basis (u, v) perpendicular to the unit vector a. */
static void perp(vec3 a, vec3 *u, vec3 *v)
{
	vec3 t = fabs(a.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
	*u = v3_norm(v3_cross(a, t));
	*v = v3_cross(a, *u);
}

/* The distance from p to the centre circle of radius R about axis a at c;
 * *foot its nearest point. */
static double circle_dist(vec3 p, vec3 c, vec3 a, double big, vec3 *foot)
{
	vec3 q = v3_sub(p, c);
	double h = v3_dot(q, a);
	vec3 radial = v3_sub(q, v3_scale(a, h));
	double rho = v3_len(radial);
	vec3 dir = rho > 0 ? v3_scale(radial, 1.0 / rho) : v3(0, 0, 0);
	if (foot)
		*foot = v3_add(c, v3_scale(dir, big));
	return sqrt((rho - big) * (rho - big) + h * h);
}

/* Shoots n x n parallel rays along the axis through the square of half
 * side `half` about the centre; counts hits and checks each against the
 * analytic annulus lo < rho < hi, except within `band` of its edges. */
static void axis_view(double big, double small, double *area, double *expected)
{
	vec3 c = v3(0.3, -0.2, 0.5), a = v3_norm(v3(1, 2, 3)), u, v;
	perp(a, &u, &v);
	object o = torus(c, a, big, small);
	world *w = world_of(&o);
	double outer = big + small, inner = big - small; /* inner <= 0: no hole */
	int n = 600;
	double half = 1.05 * outer, px = 2.0 * half / n, band = 1e-6 * outer;
	long hits = 0;
	test_rng g = {7};
	for (int j = 0; j < n; j++)
		for (int i = 0; i < n; i++) {
			/* a random point of the pixel: the count is unbiased */
			double x = -half + (i + trand(&g)) * px, y = -half + (j + trand(&g)) * px;
			vec3 p = v3_add(c, v3_add(v3_scale(u, x), v3_scale(v, y)));
			ray r = {v3_madd(p, a, -5.0 * outer), a};
			hit h;
			bool got = world_intersect(w, &r, 0, INFINITY, &h);
			hits += got;
			double rho = sqrt(x * x + y * y);
			bool in = rho < outer - band && (inner <= 0 || rho > inner + band);
			bool out = rho > outer + band || (inner > 0 && rho < inner - band);
			if ((in && !got) || (out && got))
				fail_msg("axis view R=%g r=%g: pixel (%d,%d) rho=%.9g %s", big, small, i, j, rho,
				         got ? "hit outside the annulus" : "missed inside the annulus");
			assert_int_equal(got, world_occluded(w, &r, 0, INFINITY));
		}
	*area = (double)hits * px * px;
	*expected = inner > 0 ? RT_PI * (outer * outer - inner * inner) : RT_PI * outer * outer;
	world_free(w);
}

static void test_axis_silhouette(void **state)
{
	(void)state;
	/* ring, horn (tube = ring) and spindle tori */
	static const double cases[][2] = {{1.0, 0.25}, {1.0, 0.5}, {0.7, 0.7}, {0.5, 0.8}};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		double area, expected;
		axis_view(cases[k][0], cases[k][1], &area, &expected);
		if (cases[k][0] > cases[k][1])
			assert_near(expected, 4.0 * RT_PI * cases[k][0] * cases[k][1], 1e-12);
		print_message("axis view R=%g r=%g: area %.6f, analytic %.6f (%+.3f%%)\n", cases[k][0],
		              cases[k][1], area, expected, 100.0 * (area / expected - 1.0));
		if (!(fabs(area - expected) <= 0.005 * expected))
			fail_msg("R=%g r=%g: silhouette %.6f, expected %.6f", cases[k][0], cases[k][1], area,
			         expected);
	}
}

/* Seen side-on (rays across the axis), pixel for pixel. */
static void test_side_outline(void **state)
{
	(void)state;
	static const double cases[][2] = {{1.0, 0.25}, {0.7, 0.7}, {0.5, 0.8}};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		double big = cases[k][0], small = cases[k][1];
		vec3 c = v3(-1, 2, 0.25), a = v3_norm(v3(0, 1, 0.2)), u, v;
		perp(a, &u, &v); /* rays along v, the image's axes u and a */
		object o = torus(c, a, big, small);
		world *w = world_of(&o);
		int n = 500;
		double half = 1.05 * (big + small), px = 2.0 * half / n, band = 1e-6;
		long hits = 0;
		test_rng g = {8};
		for (int j = 0; j < n; j++)
			for (int i = 0; i < n; i++) {
				double x = -half + (i + trand(&g)) * px, y = -half + (j + trand(&g)) * px;
				vec3 p = v3_add(c, v3_add(v3_scale(u, x), v3_scale(a, y)));
				ray r = {v3_madd(p, v, -5.0), v};
				hit h;
				bool got = world_intersect(w, &r, 0, INFINITY, &h);
				hits += got;
				/* |y| <= r and |x| <= R + sqrt(r^2 - y^2) */
				double e = small * small - y * y;
				double edge = e > 0 ? big + sqrt(e) : -1;
				bool in = fabs(y) < small - band && fabs(x) < edge - band;
				bool out = fabs(y) > small + band || fabs(x) > edge + band;
				if ((in && !got) || (out && got))
					fail_msg("side view R=%g r=%g: pixel (%d,%d) at (%.9g, %.9g) %s", big, small, i, j,
					         x, y, got ? "hit outside the outline" : "missed inside the outline");
			}
		/* the outline's area: 4 R r + pi r^2 (two half discs and the band
		 * between), for a ring torus; by quadrature of the outline otherwise */
		double expected = 0;
		for (int m = 0; m < 200000; m++) {
			double y = -small + (m + 0.5) * (2.0 * small / 200000);
			expected += 2.0 * (big + sqrt(small * small - y * y)) * (2.0 * small / 200000);
		}
		if (big > small)
			assert_near(expected, 4 * big * small + RT_PI * small * small, 1e-6);
		double area = (double)hits * px * px;
		print_message("side view R=%g r=%g: area %.6f, analytic %.6f (%+.3f%%)\n", big, small, area,
		              expected, 100.0 * (area / expected - 1.0));
		if (!(fabs(area - expected) <= 0.005 * expected))
			fail_msg("side view R=%g r=%g: area %.6f, expected %.6f", big, small, area, expected);
		world_free(w);
	}
}

/* Random rays aimed near the torus, grazing ones among them: a hit is on
 * the surface (distance r from the centre circle), with the unit normal
 * pointing away from it, and no point of the ray before it is inside; a
 * miss has no point inside at all (a march of 10000 steps). */
static void test_random_rays(void **state)
{
	(void)state;
	test_rng g = {16};
	static const double cases[][2] = {{1.0, 0.3}, {1.0, 1.0}, {0.6, 0.9}, {2.0, 0.05}};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		double big = cases[k][0], small = cases[k][1];
		vec3 c = v3(0.5, 0, -0.25), a = tdir(&g);
		object o = torus(c, a, big, small);
		world *w = world_of(&o);
		for (int i = 0; i < 800; i++) {
			/* a point near the surface, and a direction: half of them
			 * nearly tangent there */
			vec3 u, v;
			perp(a, &u, &v);
			double phi = trange(&g, 0, 2 * RT_PI), th = trange(&g, 0, 2 * RT_PI);
			vec3 radial = v3_add(v3_scale(u, cos(phi)), v3_scale(v, sin(phi)));
			vec3 foot = v3_add(c, v3_scale(radial, big));
			vec3 nrm = v3_add(v3_scale(radial, cos(th)), v3_scale(a, sin(th)));
			vec3 target = v3_add(foot, v3_scale(nrm, small * trange(&g, 0.98, 1.02)));
			vec3 d = tdir(&g);
			if (i % 2)
				d = v3_norm(v3_sub(d, v3_scale(nrm, v3_dot(d, nrm) * trange(&g, 0.99, 1.0))));
			ray r = {v3_madd(target, d, -4.0 * (big + small)), d};
			hit h;
			bool got = world_intersect(w, &r, 0, INFINITY, &h);
			double tend = got ? h.t : 8.0 * (big + small);
			double deepest = INFINITY;
			for (int m = 0; m < 10000; m++) {
				double t = tend * (m + 0.5) / 10000;
				double dist = circle_dist(ray_at(r, t), c, a, big, NULL) - small;
				deepest = fmin(deepest, dist);
			}
			if (deepest < -1e-6 * small)
				fail_msg("R=%g r=%g ray %d: a point %.3g inside the tube before %s", big, small, i,
				         -deepest, got ? "the hit" : "nothing (a miss)");
			if (got) {
				vec3 f;
				double dist = circle_dist(h.p, c, a, big, &f);
				assert_near(dist, small, 1e-9 * (big + small));
				assert_near(v3_len(h.n), 1.0, 1e-12);
				vec3 away = v3_norm(v3_sub(h.p, f));
				if (!(v3_dot(away, h.n) > 1.0 - 1e-9))
					fail_msg("R=%g r=%g ray %d: normal (%g,%g,%g), away from the centre line "
					         "(%g,%g,%g)",
					         big, small, i, h.n.x, h.n.y, h.n.z, away.x, away.y, away.z);
				assert_true(world_occluded(w, &r, 0, h.t + 1e-9));
				assert_false(world_occluded(w, &r, 0, h.t * (1 - 1e-9)));
			}
		}
		world_free(w);
	}
}

/* A ray through the middle of the hole along the axis misses a ring torus;
 * one along the ring's plane through the centre hits the near side at
 * distance R + r before the centre. */
static void test_hand_values(void **state)
{
	(void)state;
	object o = torus(v3(1, 2, 3), v3(0, 1, 0), 2.0, 0.5);
	world *w = world_of(&o);
	hit h;
	ray down = {v3(1, 10, 3), v3(0, -1, 0)};
	assert_false(world_intersect(w, &down, 0, INFINITY, &h));
	ray across = {v3(-9, 2, 3), v3(1, 0, 0)};
	assert_true(world_intersect(w, &across, 0, INFINITY, &h));
	assert_near(h.t, 10.0 - 2.5, 1e-9);
	assert_vec_near(h.n, v3(-1, 0, 0), 1e-9);
	/* from inside the tube, the ray leaves it at R - r */
	ray inside = {v3(1 - 2, 2, 3), v3(1, 0, 0)};
	assert_true(world_intersect(w, &inside, 0, INFINITY, &h));
	assert_near(h.t, 0.5, 1e-9);
	assert_vec_near(h.n, v3(1, 0, 0), 1e-9);
	world_free(w);
}

static scene *load(const char *text, rt_error *err)
{
	return rt_load_string(text, strlen(text), "t.rt", NULL, err);
}

/* to CENTER AXIS DIAMETER TUBE_DIAMETER R,G,B [material] [keys]. */
static void test_rt_forms(void **state)
{
	(void)state;
	rt_error err;
	rt_error_clear(&err);
	scene *s = load("to 1,2,3 0,0,2 4 1 10,20,30\n"
	                "to 0,0,0 0,1,0 3 0.5 255,0,0 0.5 0.4 30 0.2 emit=2\n"
	                "to 0,0,0 1,0,0 2,3,2 9,9,9 tube=0.25\n",
	                &err);
	if (!s)
		fail_msg("%s", err.msg);
	assert_int_equal(s->nobjs, 3);
	const object *o = &s->objs[0];
	assert_int_equal(o->kind, OBJ_TORUS);
	assert_vec_near(o->scale, v3_splat(5), 0);
	assert_near(o->tube, 0.25, 0);
	assert_vec_near(o->dir, v3(0, 0, 2), 0);
	assert_near(s->objs[1].mat.shininess, 30, 0);
	assert_near(s->objs[1].mat.emission, 2, 0);
	assert_near(s->objs[1].tube, 0.5 / 3, 1e-15);
	assert_vec_near(s->objs[2].scale, v3(2, 3, 2), 0);
	assert_near(s->objs[2].tube, 0.25, 0);
	/* written back: the short form where it says the object exactly */
	char line[512];
	rt_format_object(&s->objs[0], line, sizeof line);
	assert_string_equal(line, "to 1,2,3 0,0,2 4 1 10,20,30");
	rt_format_object(&s->objs[2], line, sizeof line);
	assert_non_null(strstr(line, "tube=0.25"));
	/* and every one reads back equal */
	char *buf = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&buf, &len);
	assert_true(rt_write(s, f, NULL));
	fclose(f);
	scene *back = load(buf, &err);
	if (!back)
		fail_msg("%s\n%s", err.msg, buf);
	assert_true(scene_equal(s, back));
	free(buf);
	scene_free(back);
	scene_free(s);

	static const struct {
		const char *text, *msg;
	} bad[] = {
		{"to 0,0,0 0,1,0 -1 1 1,1,1\n", "torus diameter \"-1\" is not positive"},
		{"to 0,0,0 0,1,0 1 1,1,1\n", "torus: too few fields"},
		{"to 0,0,0 0,1,0 1,1,1 1,1,1 tube=0\n", "torus key \"tube=0\" is out of range"},
		{"sp 0,0,0 1 1,1,1 tube=0.5\n", "does not apply to spheres"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		rt_error_clear(&err);
		scene *b = load(bad[i].text, &err);
		assert_null(b);
		if (!strstr(err.msg, bad[i].msg))
			fail_msg("%s: got \"%s\", expected \"%s\"", bad[i].text, err.msg, bad[i].msg);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_hand_values),
		cmocka_unit_test(test_axis_silhouette),
		cmocka_unit_test(test_side_outline),
		cmocka_unit_test(test_random_rays),
		cmocka_unit_test(test_rt_forms),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
